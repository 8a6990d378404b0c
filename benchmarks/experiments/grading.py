"""How long a teacher waits: autograding 30 submissions of one assignment with nbgrader.

    python -m benchmarks.experiments.grading [--submissions 30] [--assignment 01_step1_tank_controller] [--jobs 1 2]
        [--sandbox both|yes|no]

A course is made in a temporary folder (``course/assignments.py``); each
fake submission is the release with the worked solutions pasted in (every
cell of the notebook runs, as in a learner's complete work).
``course/grade.py`` then autogrades them all, writes the feedback and the
CSV, once per ``--jobs`` value (learners graded at once, each job in a ROS
domain of its own), unsandboxed and sandboxed (``--sandbox both``, the
default, as root: each kernel a user of its own, in namespaces, sealed).
Printed: the wall time of each, per submission, and the sandbox's ratio to
the same run's unsandboxed grading (the target: at most 1.5).
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import random
import re
import shutil
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "course"))

import assignments  # noqa: E402 - course/ is not a package
import grade  # noqa: E402


def solved_submission(course: Path, name: str) -> dict:
    """The release of ``name`` with every answer cell the worked solution (the source's, delimiters out)."""
    source = json.loads((course / "source" / name / f"{name}.ipynb").read_text())
    answers = {}
    for cell in source["cells"]:
        gid = cell["metadata"].get("nbgrader", {}).get("grade_id", "")
        if gid.startswith("exercise_"):
            answers[gid] = re.sub(r"^### (BEGIN|END) SOLUTION\n?", "", "".join(cell["source"]), flags=re.M)
    nb = json.loads((course / "release" / name / f"{name}.ipynb").read_text())
    for cell in nb["cells"]:
        gid = cell["metadata"].get("nbgrader", {}).get("grade_id")
        if gid in answers:
            cell["source"] = answers[gid]
    return nb


def grading_time(name: str, submissions: int, jobs: int, domains: list[int], sandboxed: bool) -> dict:
    with tempfile.TemporaryDirectory() as d:
        course = Path(d) / "course"
        assignments.make(course, release=False)
        assignments.nbgrader(course, "generate_assignment", name, "--force")
        nb = json.dumps(solved_submission(course, name))
        for k in range(submissions):
            folder = course / "submitted" / f"learner{k:02d}" / name
            folder.mkdir(parents=True)
            (folder / f"{name}.ipynb").write_text(nb)
        t0 = time.monotonic()
        csv_path = grade.grade(course, [name], collect=False, jobs=jobs, ids=domains[:jobs], sandboxed=sandboxed)
        seconds = time.monotonic() - t0
        full = sum(v for k, v in assignments.POINTS.items() if k.split(".")[0] == str(int(name[:2])))
        with csv_path.open() as f:
            scores = [row["score"] for row in csv.DictReader(f) if row["assignment"] == name]
        shutil.rmtree(course, ignore_errors=True)
    return {
        "submissions": submissions,
        "jobs": jobs,
        "sandboxed": sandboxed,
        "seconds": round(seconds, 1),
        "seconds_per_submission": round(seconds / submissions, 2),
        "all_full_points": all(float(s) == full for s in scores) and len(scores) == submissions,
    }


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--submissions", type=int, default=30)
    p.add_argument("--assignment", default="01_step1_tank_controller")
    p.add_argument("--jobs", type=int, nargs="+", default=[1, 2])
    p.add_argument("--sandbox", choices=("both", "yes", "no"), default="both")
    args = p.parse_args(argv)
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    os.environ.setdefault("RTT_TEST_MODE", "1")  # the notebooks' live sections end by themselves, as in make grade
    base = random.randint(1, 50)
    modes = {"both": [False, True], "yes": [True], "no": [False]}[args.sandbox]
    out = []
    for jobs in args.jobs:
        runs = [grading_time(args.assignment, args.submissions, jobs, [base, base + 50], m) for m in modes]
        if len(runs) == 2:
            runs[1]["ratio_to_unsandboxed"] = round(runs[1]["seconds"] / runs[0]["seconds"], 2)
        out += runs
    print(json.dumps(out, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
