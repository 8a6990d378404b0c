"""The grading sandbox's side in ``course/grade.py``: its users, the seal's verdicts, the flags a teacher sees.

``grade.py`` grades each submission in a sandbox
(:mod:`tutorial.tools.grading.sandbox`): :class:`Sandboxes` makes one Unix user
per grading job and removes it afterwards.  After each ``nbgrader autograde``,
:func:`settle` has :func:`judge` read what the kernel's seal
(:mod:`tutorial.tools.grading.seal`) signed, nbgrader's own log and the
autograded notebook, and decide each
exercise: its points stand only if nbgrader *and* the seal say it passed.
Its flags say why not, or what else was seen:

- ``changed cell``: nbgrader put back a read-only cell the learner had changed;
- ``tampering``: the check cell passed in the notebook, but the seal saw no genuine
  passing verdict (a check or the grader replaced, a verdict not the check's,
  a refused operation);
- ``timeout``: a cell of the exercise ran past the cell timeout;
- ``crash``: the kernel died while a cell of the exercise ran (a cell before the first exercise counts with
  the first; or nbgrader failed);
- ``not run``: the kernel had died in an earlier cell, so no cell of the exercise ran;
- ``over a limit``: memory, processes or CPU time ran out (``MemoryError``, ...);
- ``network``, ``processes``, ``outside its folder``: what the seal noted the answer doing;
- ``grader-aware``: the answer looks for nbgrader (``NBGRADER_...``);
- ``the checks' code``: the answer cell names the checks' package (``tutorial.exercises``) other than to import
  its public names, so reaches the rules that compute what the checks expect: an answer that calls them
  copies the answer (its points stand; the teacher reads it);
- ``checked again``: the kernel asked the judge for a judged check that had already run (its first verdict
  stands).

A judged exercise (:data:`tutorial.tools.grading.judge.JUDGED`: its check ran in the judge, a process of the
grader's, which the answer cannot reach) takes its verdict from the judge's lines alone.

The flags go to ``flags.json`` in the course (kept across runs), the
``flags`` column of ``grades.csv``, the learner's feedback (one line under
the check), and ``make grade``'s summary.  Runs in the grader's process, as root.
"""

from __future__ import annotations

import ast
import contextlib
import csv
import hmac
import io
import json
import os
import pwd
import re
import secrets
import shutil
import subprocess
import threading
import tokenize
from dataclasses import dataclass, field
from pathlib import Path

from tutorial.tools.grading import keyrings, sandbox
from tutorial.tools.grading.judge import JUDGED_NAMES, genuine
from tutorial.tools.grading.sandbox import DIED, KERNEL_MARK, NOT_RUN_MARK, OUT_OF_CPU_TIME, Job

ROOT = Path(__file__).resolve().parent.parent
JOBS = Path("/var/lib/rtt-grading")
LIBRARY = Path(sandbox.__file__).resolve().parents[3]  # the clone whose tutorial/ the graded kernels import
TEACHERS_ONLY = ("notebooks", "course", "book", ".git")  # the repository's folders with worked solutions
LIMIT_ERRORS = re.compile(r"MemoryError|BlockingIOError|Resource temporarily unavailable|Cannot allocate memory")
# An import of public names from the checks' package (10.2's stub imports TrackSwitch): what an answer may name
PUBLIC_IMPORT = re.compile(r"^[ \t]*from tutorial\.exercises\.\w+ import (?!_)\w+(?:, *(?!_)\w+)*[ \t]*(?:#.*)?$", re.M)
CPU_SECONDS = "RTT_GRADING_CPU_SECONDS"  # a kernel's CPU time, s (RLIMIT_CPU; default 600)


def hidden_folders(course: Path, library: Path = LIBRARY) -> list[str]:
    """The folders a graded kernel sees empty: the course, the teacher-only folders of this repository and of the
    one the kernel imports ``tutorial`` from (``library``: another clone, when the environment is another's),
    the homes, ``/srv`` and the learners' exchange (``RTT_NBGRADER_EXCHANGE``) wherever the course keeps it."""
    hide = {str(course), *(str(root / f) for root in (ROOT, library) for f in TEACHERS_ONLY), "/home", "/root", "/srv"}
    if os.environ.get("RTT_NBGRADER_EXCHANGE"):
        hide.add(os.environ["RTT_NBGRADER_EXCHANGE"])
    return sorted(hide)


class SandboxError(RuntimeError):
    """The sandbox cannot be made here (not root, or no unshare): the message says what to do."""


@dataclass
class Sandboxes:
    """One Unix user per grading job, a folder for their kernels; removed with all they ran on :meth:`close`."""

    course: Path
    jobs: int
    users: list[Job] = field(default_factory=list)

    def __enter__(self) -> Sandboxes:
        try:
            return self._make()
        except BaseException:
            self.close()  # the users made so far, and the folder
            raise

    def _make(self) -> Sandboxes:
        if os.geteuid() != 0 or not shutil.which("unshare") or not shutil.which("setpriv"):
            raise SandboxError(
                "grading runs each submission as a user of its own, in a namespace of its own: "
                "run make grade as root (Linux, util-linux), or pass --unsandboxed to grade with your own "
                "rights (a learner's code then runs as you: not for a real class)"
            )
        if not keyrings.libseccomp_name():  # each kernel's keyrings filter
            raise SandboxError(keyrings.MISSING)
        JOBS.mkdir(parents=True, exist_ok=True)
        os.chmod(JOBS, 0o711)
        remove_stale_users()
        self.folder = JOBS / secrets.token_hex(4)
        self.folder.mkdir(mode=0o711)
        hide = hidden_folders(self.course)
        for k in range(self.jobs):
            name = f"rttgrade{self.folder.name[:5]}{k}"
            subprocess.run(
                ["useradd", "--system", "--no-create-home", "--shell", "/usr/sbin/nologin", name],
                check=True,
                capture_output=True,
                timeout=30,
            )
            entry = pwd.getpwnam(name)
            folder = self.folder / name
            folder.mkdir(mode=0o711)
            self.users.append(
                Job(
                    name,
                    entry.pw_uid,
                    entry.pw_gid,
                    str(folder),
                    str(folder / "verdicts"),
                    hide,
                    test_calls=[],
                    cpu_seconds=int(os.environ.get(CPU_SECONDS, "600")),
                )
            )
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        for job in self.users:
            clear(job)
            subprocess.run(["userdel", job.user], capture_output=True, timeout=30, check=False)
            for controller in ("memory", "pids"):
                with contextlib.suppress(OSError):
                    (Path("/sys/fs/cgroup") / controller / f"rtt-grade-{job.user}").rmdir()
        self.users = []
        shutil.rmtree(getattr(self, "folder", JOBS / "none"), ignore_errors=True)


def remove_stale_users() -> None:
    """Grading users whose run is gone (a grading killed before it removed them): removed, with their processes."""
    alive = {p.name[:5] for p in JOBS.iterdir()} if JOBS.is_dir() else set()
    for entry in pwd.getpwall():
        name = entry.pw_name
        if name.startswith("rttgrade") and name[8:13] not in alive:
            subprocess.run(["pkill", "-KILL", "-u", name], capture_output=True, timeout=30, check=False)
            subprocess.run(["userdel", name], capture_output=True, timeout=30, check=False)


def clear(job: Job) -> None:
    """Everything the job's user still runs, killed (a fork bomb's children, say); its kernels' folders removed."""
    for _ in range(5):  # a fork bomb may fork between two passes; pgrep answers 1 once nothing is left
        subprocess.run(["pkill", "-KILL", "-u", job.user], capture_output=True, timeout=30, check=False)
        if subprocess.run(["pgrep", "-u", job.user], capture_output=True, timeout=30).returncode == 1:
            break
    for group in (Path("/sys/fs/cgroup") / c / f"rtt-grade-{job.user}" for c in ("memory", "pids")):
        with contextlib.suppress(OSError):
            for pid in (group / "cgroup.procs").read_text().split():
                with contextlib.suppress(ProcessLookupError):
                    os.kill(int(pid), 9)
    for kernel in Path(job.folder).iterdir():
        if kernel.is_dir():
            shutil.rmtree(kernel, ignore_errors=True)


def test_calls(course: Path, assignment: str) -> tuple[list[str], list[str]]:
    """The statement each test cell of ``assignment`` ends with (``check_x(answer).require()``), and the modules
    they import their checks from, from the assignment's source (parsed: comments and layout do not count).

    Raises:
        SyntaxError: a test cell of the source is not Python.
    """
    notebook = json.loads((course / "source" / assignment / f"{assignment}.ipynb").read_text())
    calls, modules = [], []
    for cell in notebook["cells"]:
        if cell["metadata"].get("nbgrader", {}).get("grade"):
            tree = ast.parse("".join(cell["source"]))
            calls.append(ast.unparse(tree.body[-1]))
            modules += [n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and n.module]
    return calls, sorted({m for m in modules if m.startswith("tutorial.exercises.")})


def course_seed(course: Path) -> bytes:
    """The course's own seed of hidden cases, ``.grading_seed`` (made once, 0600 from the start: the teacher's
    alone).  Call it before grading's threads start: two makers at once would draw two seeds."""
    path = course / ".grading_seed"
    with contextlib.suppress(FileExistsError):
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        with os.fdopen(fd, "w") as out:
            out.write(secrets.token_hex(16) + "\n")
    return path.read_text().strip().encode()


def learner_seed(course: Path, assignment: str, learner: str) -> str:
    """The seed of ``learner``'s hidden cases of ``assignment``, from :func:`course_seed`: a regrade draws
    the same cases, another learner others."""
    key = course_seed(course)
    return hmac.new(key, f"{assignment}/{learner}".encode(), "sha256").hexdigest()[:16]


def grade_id(cell: dict) -> str:
    """The nbgrader grade id of a notebook cell, or ""."""
    return cell["metadata"].get("nbgrader", {}).get("grade_id") or ""


def number(grade_id: str) -> str:
    """``check_1_2`` or ``exercise_1_2`` as ``1.2``."""
    return grade_id.split("_", 1)[1].replace("_", ".")


def names_the_checks(source: str) -> bool:
    """Whether an answer's code names the checks' package (``tutorial.exercises``) other than to import a public
    name from it: as a name, or as a module or file path in a string.  Comments and prose do not count (an
    honest answer may say "like the other exercises").  A hint for the teacher, not a proof: code can spell the
    name in pieces, and the judge and the seal decide the points."""
    code = PUBLIC_IMPORT.sub("", source)
    try:
        tokens = [
            t
            for t in tokenize.generate_tokens(io.StringIO(code).readline)
            if t.type in (tokenize.NAME, tokenize.STRING)
        ]
    except (tokenize.TokenError, SyntaxError):  # not Python (a cell cut short): its lines less their comments
        return bool(re.search(r"\bexercises\b", re.sub(r"#.*", "", code)))
    return any(
        t.string == "exercises" if t.type == tokenize.NAME else re.search(r"[./]exercises\b|\bexercises[./]", t.string)
        for t in tokens
    )


def judge(
    autograded: Path, verdicts: Path, log: str, died: bool = False, judge_key: str = ""
) -> dict[str, tuple[bool, list[str]]]:
    """Each exercise of one graded notebook: (whether the seal let its points stand, its flags).

    ``autograded``: the notebook nbgrader executed (none: nbgrader removed it, every exercise 0); ``verdicts``:
    the seal's checked lines; ``log``: what nbgrader autograde printed; ``died``: the kernel died (nbgrader
    could not finish the notebook).  An exercise's points stand only if the last check of it that began
    ended with a signed pass, intact.  Any thread (it reads files and changes none).

    Raises:
        ValueError: ``autograded`` is not a notebook (JSON).
    """
    notebook = json.loads(autograded.read_text()) if autograded.is_file() else {"cells": []}
    exercises: dict[str, dict] = {}
    current = None
    before: list[dict] = []  # the code cells before the first exercise: a death there counts with the first
    of_cell: dict[str, str] = {}  # a cell's index (the grader's marks on the seal's pipe): its exercise
    for index, cell in enumerate(notebook["cells"]):
        gid = grade_id(cell)
        if gid.startswith(("exercise_", "check_")):
            current = number(gid)
            exercises.setdefault(current, {"cells": [*before] if not exercises else [], "source": "", "check": ""})
            if gid.startswith("exercise_"):
                exercises[current]["source"] = "".join(cell["source"])
            else:  # the test cell, nbgrader's read-only one: which check it calls
                exercises[current]["check"] = "".join(cell["source"])
        if cell["cell_type"] == "code":
            (exercises[current]["cells"] if current else before).append(cell)
        if current:
            of_cell[str(index)] = current
    passed: dict[str, bool] = {}
    flags: dict[str, list[str]] = {n: [] for n in exercises}
    called = {n: set(re.findall(r"\b(check_\w+)\(", found["check"])) for n, found in exercises.items()}
    judged = {n for n, names in called.items() if JUDGED_NAMES & names}
    by_check = {name: n for n, names in called.items() for name in names}  # a note of the seal's names the check
    pending: list[str] = []  # notes of no exercise's cell (none marked yet, or a cell before the first exercise)
    in_cell = None  # the exercise of the cell the grader last marked as starting
    # lines split at "\n" alone, as the seal's pipe reader and the judge write them (str.splitlines() would also
    # split at "\r", "\x1c" or U+2028, which a body the kernel signed may hold)
    lines = verdicts.read_text().split("\n") if verdicts.is_file() else []
    key = bytes.fromhex(judge_key)
    for line in lines:
        kind, *rest = line.split("\t")
        by_judge = kind == "judged"  # the judge's own line, signed with its key (the seal's reader refuses one)
        if by_judge:
            body = genuine(key, line)
            if body is None:  # cut short and finished by another writer's bytes, or forged
                pending.append("tampering")
                continue
            kind, *rest = body.split("\t")[1:] or [""]
        if kind in ("begin", "verdict") and rest and (rest[0] in judged) != by_judge:
            if not by_judge:  # the seal saw a judged check run in the kernel: the teacher's, reloaded by the answer
                flags.setdefault(rest[0], []).append("tampering")
            continue  # a judged exercise's verdict is the judge's alone
        if kind == "note" and rest:
            flag = {"refused": "tampering", "outside": "outside its folder"}.get(rest[0], rest[0])
            ex = by_check.get(rest[2], rest[2]) if len(rest) > 2 else None
            if ex in flags:  # a note that names its exercise, or the judged check it ran in the kernel for
                flags[ex].append(flag)
            elif in_cell:  # made while a cell of an exercise ran (its answer cell: before any check of it began)
                flags[in_cell].append(flag)
            else:
                pending.append(flag)
        elif kind == "cell" and rest and not by_judge:
            in_cell = of_cell.get(rest[0])
        elif kind == "begin" and rest:
            passed[rest[0]] = False  # the last begin of an exercise must be followed by its verdict
            flags.setdefault(rest[0], []).extend(pending)
            pending = []
        elif kind == "verdict" and len(rest) >= 3:
            ex, ok, intact = rest[0], rest[1] == "1", rest[2] == "1"
            passed[ex] = ok and intact
            flags.setdefault(ex, []).extend(pending + ([] if intact else ["tampering"]))
            pending = []
    if pending and exercises:  # a note of no exercise's cell, none begun after it: the last exercise's, not lost
        flags.setdefault(list(exercises)[-1], []).extend(pending)
    for match in re.finditer(r"Attribute '\w+' for cell (\w+) has changed", log):
        flags.setdefault(number(match.group(1)), []).append("changed cell")
    out = {}
    for ex, found in exercises.items():
        errors = [o for c in found["cells"] for o in c.get("outputs", []) if o.get("output_type") == "error"]
        text = " ".join(f"{o.get('ename')}: {o.get('evalue')}" for o in errors)
        check_ok = any(
            c["metadata"].get("nbgrader", {}).get("grade")
            and not any(o.get("output_type") == "error" for o in c.get("outputs", []))
            for c in found["cells"]
        )
        mine = flags.setdefault(ex, [])
        if "CellTimeoutError" in text or "KeyboardInterrupt" in text:
            mine.append("timeout")
        # what became of the kernel, from the cells' metadata, which only the sandbox's executor writes (an
        # answer can raise an error of any name and text)
        kernel = {c["metadata"].get(KERNEL_MARK) for c in found["cells"]}
        if LIMIT_ERRORS.search(text) or OUT_OF_CPU_TIME in kernel:
            mine.append("over a limit")
        if died or DIED in kernel:  # nbgrader failed, or the kernel died while a cell of this exercise ran
            mine.append("crash")
        elif kernel == {NOT_RUN_MARK}:  # it had died before
            mine.append("not run")
        if "showtraceback was disabled" in json.dumps(found["cells"]):  # nbgrader's words for a hidden error
            mine.append("tampering")
        if "NBGRADER" in found["source"]:
            mine.append("grader-aware")
        if names_the_checks(found["source"]):
            mine.append("the checks' code")
        if check_ok and not passed.get(ex, False):  # the notebook passed what the seal did not see pass
            mine.append("tampering")
        # tampering costs the exercise its points: a judged check's experiments, replaced in the kernel, could
        # have sent the judge what a right answer would
        out[ex] = (passed.get(ex, False) and "tampering" not in mine, sorted(set(mine)))
    return out


def settle(course: Path, assignment: str, learner: str, job: Job, log: str, died: bool) -> str | None:
    """After ``nbgrader autograde`` of one submission in ``job``'s sandbox: its exercises judged
    (:func:`judge`), the points the seal did not let stand taken back, its flags in the feedback and in
    ``flags.json``, and the seal's lines kept for the teacher, why, in ``seal/<learner>/<assignment>.txt`` (not
    beside the autograded notebook: ``nbgrader generate_feedback`` copies every other file there into the
    learner's feedback).

    Returns:
        None, or why the submission was not graded in the sandbox (no kernel of the sandbox ever ran).
    Any thread (one per job).
    """
    verdicts = Path(job.verdicts)
    if not died and not verdicts.exists():
        return f"not graded in the sandbox (nbgrader's log: {log[-500:]})"
    notebook = course / "autograded" / learner / assignment / f"{assignment}.ipynb"
    judged = judge(notebook, verdicts, log, died, job.judge_key)
    if verdicts.exists():  # what the seal said, and why, for the teacher alone
        notes = course / "seal" / learner
        notes.mkdir(parents=True, exist_ok=True)
        (course / "seal").chmod(0o700)
        shutil.copyfile(verdicts, notes / f"{assignment}.txt")
    if notebook.is_file():
        apply(f"sqlite:///{course / 'gradebook.db'}", assignment, learner, judged)
        say_in_feedback(notebook, judged)
    record_flags(course, assignment, learner, judged)
    return None


def apply(gradebook_url: str, assignment: str, learner: str, judged: dict[str, tuple[bool, list[str]]]) -> None:
    """nbgrader's automatic score of each check the seal did not let stand, set to 0 (a manual score stays)."""
    from nbgrader.api import Gradebook

    with Gradebook(gradebook_url) as gb:
        for ex, (ok, _) in judged.items():
            if not ok:
                grade = gb.find_grade(f"check_{ex.replace('.', '_')}", assignment, assignment, learner)
                grade.auto_score = 0.0
        gb.db.commit()


def say_in_feedback(autograded: Path, judged: dict[str, tuple[bool, list[str]]]) -> None:
    """One line under each flagged check, in the autograded notebook the feedback is made from."""
    notebook = json.loads(autograded.read_text())
    for cell in notebook["cells"]:
        gid = grade_id(cell)
        if gid.startswith("check_") and judged.get(number(gid), (True, []))[1]:
            ok, mine = judged[number(gid)]
            points = "" if ok else " It gets 0 points."
            line = f"The grader flagged exercise {number(gid)}: {', '.join(mine)}.{points}\n"
            cell.setdefault("outputs", []).append({"output_type": "stream", "name": "stdout", "text": line})
    autograded.write_text(json.dumps(notebook))


_FLAGS_LOCK = threading.Lock()  # grading's worker threads each record their learners' flags in one file


def record_flags(course: Path, assignment: str, learner: str, judged: dict[str, tuple[bool, list[str]]]) -> None:
    """``flags.json`` in the course: each (assignment, learner)'s flags, as ``1.1: tampering; 1.2: timeout``.

    Any thread (the file is read, changed and written under a lock).
    """
    path = course / "flags.json"
    said = "; ".join(f"{ex}: {', '.join(f)}" for ex, (_, f) in sorted(judged.items()) if f)
    with _FLAGS_LOCK:
        kept = json.loads(path.read_text()) if path.is_file() else {}
        kept[f"{assignment}/{learner}"] = said
        path.write_text(json.dumps(kept, indent=1, sort_keys=True) + "\n")
        os.chmod(path, 0o600)


def add_flags_column(course: Path, csv_path: Path) -> list[str]:
    """``grades.csv`` with a ``flags`` column (from ``flags.json``); the flagged rows, one line each."""
    kept = json.loads((course / "flags.json").read_text()) if (course / "flags.json").is_file() else {}
    with csv_path.open(newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        return []
    for row in rows:
        row["flags"] = kept.get(f"{row['assignment']}/{row['student_id']}", "")
    with csv_path.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=[*rows[0].keys()])
        writer.writeheader()
        writer.writerows(rows)
    return [f"{r['assignment']}, {r['student_id']}: {r['flags']}" for r in rows if r["flags"]]
