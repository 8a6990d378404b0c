"""The class's nbgrader assignments, made from the notebooks: ``make assignments``.

    python course/assignments.py [--course DIR] [--no-release]

The notebooks in ``notebooks/`` are the teacher's version (the book and
nbval use them); an assignment is made from each notebook that has
exercises, never edited by hand.  For each exercise (a statement, the
learner's code cell, its check cell, and its folded worked solution):

- the learner's code cell becomes an **autograded answer** cell: the worked
  solution (after the stub, as the teacher's notebook runs them) sits between
  nbgrader's ``### BEGIN SOLUTION`` and ``### END SOLUTION``, and the release shows the notebook's own stub instead
  (``tutorial.tools.grading.release.ReleaseStubs``, which runs inside ``nbgrader generate_assignment``
  right after nbgrader's own ``ClearSolutions``);
- the check cell becomes a **read-only autograder test** cell worth the
  exercise's :data:`POINTS`; its call ends in ``.require()``, which raises
  with the same one line a learner sees (``tutorial.exercises.grader``);
- the folded solution cell is left out.

Everything else (the lesson) is the notebook's, outputs cleared.  The
course is ``course/`` by default: ``nbgrader_config.py`` beside this file,
``source/<assignment>/<assignment>.ipynb``, and ``release/`` from
``nbgrader generate_assignment`` (both generated; git ignores them).
"""

from __future__ import annotations

import argparse
import copy
import json
import os
import re
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent

# Points per exercise: the one place they are written.  Each exercise's check holds every case of it.
POINTS = {
    "1.1": 2, "1.2": 3,
    "2.1": 3, "2.2": 4,
    "3.1": 3, "3.2": 4,
    "4.1": 4, "4.2": 3,
    "5.1": 3, "5.2": 3,
    "6.1": 3, "6.2": 4,
    "7.1": 3, "7.2": 3,
    "8.1": 2, "8.2": 3,
    "9.1": 4,
    "10.1": 3, "10.2": 3,
    "11.1": 3,
}  # fmt: skip

SOLUTION_HEADER = re.compile(r"^# Worked solution to Exercise (\d+\.\d+)\..*\n")
CHECK_CALL = re.compile(r"^(check_\w+)\((\w+)\)\s*$", re.M)
NBGRADER = {"schema_version": 3}


def exercises(cells: list[dict]) -> list[dict]:
    """The exercises of a notebook's cells: ``{"number", "stub", "check", "solution"}`` cell indices."""
    found = []
    for i, cell in enumerate(cells):
        match = SOLUTION_HEADER.match("".join(cell["source"])) if cell["cell_type"] == "code" else None
        if match:
            number = match.group(1)
            check, stub = i - 1, i - 2
            if not CHECK_CALL.search("".join(cells[check]["source"])):
                raise ValueError(f"exercise {number}: the cell before its solution is not a check cell")
            if "raise NotImplementedError" not in "".join(cells[stub]["source"]):
                raise ValueError(f"exercise {number}: the cell before its check is not a stub")
            found.append({"number": number, "stub": stub, "check": check, "solution": i})
    return found


def source_notebook(notebook: dict) -> dict:
    """The nbgrader source notebook of a teacher's notebook (a new dict; the notebook is not changed).

    Raises:
        ValueError: an exercise without its stub or check cell, or with no entry in :data:`POINTS`.
    """
    nb = copy.deepcopy(notebook)
    cells = nb["cells"]
    found = exercises(cells)
    drop = set()
    for ex in found:
        number, tag = ex["number"], ex["number"].replace(".", "_")
        if number not in POINTS:
            raise ValueError(f"exercise {number} has no points in course/assignments.py POINTS")
        solution = SOLUTION_HEADER.sub("", "".join(cells[ex["solution"]]["source"]), count=1)
        solution = CHECK_CALL.sub("", solution).rstrip() + "\n"  # its check call is the test cell's
        stub = cells[ex["stub"]]
        stub_text = "".join(stub["source"])
        # The solution as the teacher's notebook runs it: the stub's cell, then the solution's, which
        # replaces what the stub left undone and uses what it defines (constants, imports).
        stub["source"] = f"### BEGIN SOLUTION\n{stub_text.rstrip()}\n\n\n{solution}### END SOLUTION"
        stub["metadata"] = {
            "nbgrader": dict(NBGRADER, grade=False, solution=True, locked=False, grade_id=f"exercise_{tag}"),
            "rtt_stub": stub_text,  # what the release shows in its place (tutorial.tools.grading.release)
        }
        check = cells[ex["check"]]
        check["source"] = CHECK_CALL.sub(r"\1(\2).require()", "".join(check["source"]))
        check["metadata"] = {
            "nbgrader": dict(
                NBGRADER, grade=True, solution=False, locked=True, grade_id=f"check_{tag}", points=POINTS[number]
            )
        }
        drop.add(ex["solution"])
    for cell in cells:
        if cell["cell_type"] == "code":
            cell["outputs"], cell["execution_count"] = [], None
        cell["metadata"].pop("execution", None)
    _say_solutions_held_back(
        cells, "In this assignment the worked solutions are held back: your check cells are graded."
    )
    nb["cells"] = [c for i, c in enumerate(cells) if i not in drop]
    nb["metadata"].pop("widgets", None)
    return nb


def learner_notebook(notebook: dict) -> dict:
    """A teacher's notebook as a class's hub gives it to a learner: the folded worked solutions left out.

    Everything else is the notebook's, outputs included (the lessons' recorded
    views and figures); the stubs and checks stay, so each exercise is the
    learner's to solve and check, as in the assignment.  A new dict; the
    notebook is not changed.

    Raises:
        ValueError: an exercise without its stub or check cell.
    """
    nb = copy.deepcopy(notebook)
    drop = {ex["solution"] for ex in exercises(nb["cells"])}
    _say_solutions_held_back(
        nb["cells"],
        "On this class's server the worked solutions are held back. What your teacher grades is the "
        "assignment you fetch and submit in the Assignments tab (Nbgrader > Assignment List), not this copy.",
    )
    nb["cells"] = [c for i, c in enumerate(nb["cells"]) if i not in drop]
    return nb


def _say_solutions_held_back(cells: list[dict], sentence: str) -> None:
    """Put ``sentence`` where a statement says a worked solution follows (the cells are changed in place)."""
    for cell in cells:
        if cell["cell_type"] == "markdown":
            text = "".join(cell["source"])
            cell["source"] = re.sub(
                r"A worked solution follows, folded\s+away:.*?checks it\.", sentence, text, flags=re.S
            )


def make(course: Path, release: bool = True) -> list[str]:
    """Write every assignment's source into ``course``, then (``release``) nbgrader's release; their names.

    A course folder other than ``course/`` gets a copy of ``nbgrader_config.py``.
    """
    course.mkdir(parents=True, exist_ok=True)
    if course != HERE:
        (course / "nbgrader_config.py").write_text((HERE / "nbgrader_config.py").read_text())
    names = []
    for path in sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb")):
        notebook = json.loads(path.read_text(encoding="utf-8"))
        if not exercises(notebook["cells"]):
            continue
        folder = course / "source" / path.stem
        folder.mkdir(parents=True, exist_ok=True)
        (folder / path.name).write_text(json.dumps(source_notebook(notebook), indent=1) + "\n", encoding="utf-8")
        names.append(path.stem)
    if release:
        for name in names:
            nbgrader(course, "generate_assignment", name, "--force")
    return names


def nbgrader(course: Path, *args: str, env: dict | None = None, timeout: float = 1800) -> str:
    """Run ``nbgrader args`` in ``course`` (its nbgrader_config.py); its output.

    Raises:
        RuntimeError: nbgrader failed (its output is in the message).
    """
    bin_dir = str(Path(sys.executable).parent)  # nbgrader runs alembic, its database's tool, from the PATH
    env = dict(os.environ if env is None else env)
    env["PATH"] = bin_dir + os.pathsep + env.get("PATH", "")
    done = subprocess.run(
        [os.path.join(bin_dir, "nbgrader"), *args],
        cwd=course,
        env=env,
        capture_output=True,
        text=True,
        timeout=timeout,
    )
    if done.returncode != 0:
        raise RuntimeError(f"nbgrader {' '.join(args)} failed:\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}")
    return done.stdout + done.stderr


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--course", type=Path, default=HERE, help="the nbgrader course folder (default: course/)")
    p.add_argument("--no-release", action="store_true", help="write the sources only")
    args = p.parse_args(argv)
    names = make(args.course.resolve(), release=not args.no_release)
    print(f"assignments: {', '.join(names)}; sources in {args.course / 'source'}, release in {args.course / 'release'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
