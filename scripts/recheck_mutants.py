"""Run today's tests against survivors of an earlier mutmut run, one mutant at a time.

    python scripts/recheck_mutants.py MUTMUT_DIR NAME[,NAME...] -- PYTEST_ARGS...
    python scripts/recheck_mutants.py /tmp/mut "$(paste -sd, survivors.txt)" -- tests/test_exercises.py -k 5.2

A mutation run takes hours on two cores; the tests written for its survivors
are written while it runs.  This asks the finished part of that run
(``MUTMUT_DIR``, a tree where ``mutmut run`` ran) for each named mutant's
change (``mutmut show``), puts that change into a copy of this tree's
``tutorial/`` (the mutated function's text replaced, nothing else), and runs
pytest with ``PYTEST_ARGS`` there.  It prints one line per mutant: ``caught``
(with the first failing test), ``SURVIVED``, or ``cannot apply`` when the
function has changed here since the run (then ``make mutate`` must run it
again).  Runs one mutant at a time, in a temporary folder it removes.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import textwrap
from pathlib import Path

import mutation_report  # this folder's: how make mutate's report names a mutant's module

ROOT = Path(__file__).resolve().parent.parent


def mutant_change(mutmut_dir: Path, name: str) -> tuple[str, str] | None:
    """The mutated function's text before and after, from ``mutmut show``; None when it shows no diff."""
    shown = subprocess.run(
        [str(mutmut_dir / ".venv" / "bin" / "mutmut"), "show", name],
        cwd=mutmut_dir,
        capture_output=True,
        text=True,
        timeout=120,
    ).stdout.splitlines()
    start = next((i for i, line in enumerate(shown) if line.startswith("@@")), None)
    if start is None:
        return None
    body = shown[start + 1 :]
    before = "\n".join(line[1:] for line in body if line[:1] in (" ", "-"))
    after = "\n".join(line[1:] for line in body if line[:1] in (" ", "+"))
    return before, after


def module_path(name: str) -> str:
    """``tutorial/exercises/step5_imu_viewer.py`` for ``tutorial.exercises.step5_imu_viewer.x_f__mutmut_3``."""
    return mutation_report.module(name).replace(".", "/") + ".py"


def recheck(mutmut_dir: Path, name: str, pytest_args: list[str], work: Path) -> str:
    change = mutant_change(mutmut_dir, name)
    if change is None:
        return "cannot apply (mutmut shows no change)"
    before, after = change
    shutil.rmtree(work, ignore_errors=True)
    shutil.copytree(ROOT / "tutorial", work / "tutorial", ignore=shutil.ignore_patterns("__pycache__"))
    for folder in ("project", "model", "notebooks", "launch_py", "course"):  # what the checks load
        os.symlink(ROOT / folder, work / folder)
    path = work / module_path(name)
    source = path.read_text(encoding="utf-8")
    # mutmut shows a method dedented: as in its class, one level in
    before, after = next(
        (
            (textwrap.indent(before, i), textwrap.indent(after, i))
            for i in ("", "    ")
            if textwrap.indent(before, i) in source
        ),
        (before, after),
    )
    if source.count(before) != 1:
        return "cannot apply (the function has changed here since the run)"
    path.write_text(source.replace(before, after), encoding="utf-8")
    # run from the copy: its tutorial/ comes first on the path; the tests stay this tree's
    args = [str(ROOT / a) if a.startswith("tests/") else a for a in pytest_args]
    run = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-x", "-p", "no:cacheprovider", *args],
        cwd=work,
        env={**os.environ, "RTT_TEST_MODE": "1"},
        capture_output=True,
        text=True,
        timeout=1800,
    )
    if run.returncode == 0:
        return "SURVIVED"
    failed = next((line for line in run.stdout.splitlines() if line.startswith("FAILED")), "(no FAILED line)")
    return f"caught by {failed.removeprefix('FAILED ').split(' - ')[0]}"


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if "--" not in argv or argv.index("--") != 2:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    mutmut_dir, names, pytest_args = Path(argv[0]), argv[1].split(","), argv[3:]
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    if "ROS_DOMAIN_ID" not in os.environ:
        print("set ROS_DOMAIN_ID to a domain of this run's own", file=sys.stderr)
        return 2
    with tempfile.TemporaryDirectory(prefix="recheck-") as tmp:
        for name in names:
            print(f"{recheck(mutmut_dir, name, pytest_args, Path(tmp) / 'tree')}  {name}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
