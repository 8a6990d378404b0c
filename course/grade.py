"""Grade the class: collect, autograde, feedback and the grades' CSV, with nbgrader's own commands.

    python course/grade.py [ASSIGNMENT ...] [--course DIR] [--no-collect] [--jobs N] [--domains 90-101]

For each assignment (default: every one in the course's ``release/``):

1. ``nbgrader collect``: the submissions from the exchange into ``submitted/``;
2. ``nbgrader autograde``, one learner at a time per job, ``--jobs`` at once.
   Each job's kernel runs in a ROS domain of its own (``--domains``; the
   discovery range is this machine), so submissions graded at once never
   hear each other's nodes; the notebooks' runs end by themselves
   (``RTT_TEST_MODE=1``).  A cell that never ends is interrupted after the
   course's cell timeout (``nbgrader_config.py``): its exercise gets 0, the
   rest is graded;
3. ``nbgrader generate_feedback``: each learner's feedback, in ``feedback/``;

then ``nbgrader export`` writes every grade to ``grades.csv`` in the course.
"""

from __future__ import annotations

import argparse
import os
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from assignments import HERE, nbgrader  # noqa: E402 - this folder is not a package


def domains(text: str) -> list[int]:
    """``"90-101"`` or ``"5,7,9"`` as a list of ROS domain ids.

    Raises:
        ValueError: not a list or range of ids from 0 to 232.
    """
    ids = []
    for part in text.split(","):
        low, _, high = part.partition("-")
        ids.extend(range(int(low), int(high or low) + 1))
    if not ids or not all(0 <= i <= 232 for i in ids):
        raise ValueError(f"domains {text!r}: ROS domain ids are 0 to 232")
    return ids


def learners(course: Path, assignment: str) -> list[str]:
    """Who submitted ``assignment`` (the folders of ``submitted/``)."""
    folder = course / "submitted"
    return sorted(p.name for p in folder.iterdir() if (p / assignment).is_dir()) if folder.is_dir() else []


def grade(course: Path, assignments: list[str], collect: bool = True, jobs: int = 1, ids=(90,)) -> Path:
    """Grade ``assignments`` in ``course``; the grades' CSV.

    Raises:
        GradingError: some submissions could not be graded; the others were, and the CSV was written.
        RuntimeError: another nbgrader command failed (its output is in the message).
    """
    ids = list(ids)
    failed: list[str] = []  # submissions nbgrader could not grade (the worker threads append)
    if jobs > len(ids):
        raise ValueError(f"{jobs} jobs need {jobs} ROS domains, {len(ids)} given")
    for assignment in assignments:
        if collect:
            nbgrader(course, "collect", assignment, "--update")
        who = learners(course, assignment)

        def worker(k: int, who=who, assignment=assignment) -> None:
            """Learners k, k + jobs, ... one after another, in domain ids[k]: never two kernels in one domain.

            A submission nbgrader cannot grade (its kernel died, say) is named, and the others are graded.
            """
            env = dict(
                os.environ, ROS_DOMAIN_ID=str(ids[k]), ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST", RTT_TEST_MODE="1"
            )
            for learner in who[k::jobs]:
                try:
                    nbgrader(course, "autograde", assignment, "--student", learner, "--force", env=env)
                except RuntimeError as error:
                    failed.append(f"{assignment}, {learner}: {str(error).splitlines()[0]}")

        with ThreadPoolExecutor(max_workers=jobs) as pool:
            list(pool.map(worker, range(jobs)))  # list(): a worker's exception is raised here
        if who:
            nbgrader(course, "generate_feedback", assignment, "--force")
    csv = course / "grades.csv"
    nbgrader(course, "export", "--to", str(csv))
    if failed:
        raise GradingError(csv, failed)
    return csv


class GradingError(RuntimeError):
    """Some submissions could not be graded (the others were, and the CSV was written).

    Attributes:
        csv: the grades' CSV (an ungraded submission has no score in it).
        failed: one line per submission: assignment, learner, what nbgrader said.
    """

    def __init__(self, csv: Path, failed: list[str]):
        super().__init__(f"{len(failed)} submission(s) could not be graded:\n" + "\n".join(failed))
        self.csv, self.failed = csv, failed


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("assignments", nargs="*", help="default: every assignment in the course's release/")
    p.add_argument("--course", type=Path, default=HERE)
    p.add_argument("--no-collect", action="store_true", help="grade what is in submitted/ already")
    p.add_argument("--jobs", type=int, default=1, help="learners graded at once (default 1)")
    p.add_argument("--domains", default="90-101", help="ROS domains for the jobs (default 90-101)")
    args = p.parse_args(argv)
    course = args.course.resolve()
    names = args.assignments or sorted(p.name for p in (course / "release").iterdir() if p.is_dir())
    try:
        csv = grade(course, names, collect=not args.no_collect, jobs=args.jobs, ids=domains(args.domains))
    except GradingError as error:
        print(f"graded {', '.join(names)}: {error.csv}, but {error}", file=sys.stderr)
        return 1
    print(f"graded {', '.join(names)}: {csv}; feedback in {course / 'feedback'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
