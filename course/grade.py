"""Grade the class: collect, autograde, feedback and the grades' CSV, with nbgrader's own commands.

    python course/grade.py [ASSIGNMENT ...] [--course DIR] [--no-collect] [--jobs N] [--domains 215-232]
                           [--student NAME ...]
    make grade ARGS="01_step1_tank_controller --jobs 2"
    make grade ARGS="01_step1_tank_controller --student learner1"    # one learner's, again

For each assignment (default: every one released into the exchange; with
``--no-collect``, every one somebody has in ``submitted/``):

1. ``nbgrader collect``: the submissions from the exchange into ``submitted/``, from a copy out of the
   learners' reach, but for those handed in under another learner's name (:func:`stage_submissions`);
2. ``nbgrader autograde``, one learner at a time per job, ``--jobs`` at once.
   Each job's kernel runs in a ROS domain of its own (the discovery range is
   this machine), so submissions graded at once never hear each other's
   nodes; the notebooks' runs end by themselves (``RTT_TEST_MODE=1``).  The
   domains (``--domains``) are by default those the hub's book has given no
   learner, from the top (:func:`free_domains`): a learner's robots running
   during the grading are never heard by it.  A cell that never ends is
   interrupted after the course's cell timeout (``nbgrader_config.py``): its
   exercise gets 0, the rest is graded;
3. ``nbgrader generate_feedback``: each learner's feedback, in ``feedback/``;
   and, from the exchange, ``nbgrader release_feedback``: each learner
   fetches it in the Assignments tab (Fetch Feedback) or with
   ``nbgrader fetch_feedback``;

then ``nbgrader export`` writes the grades of every assignment graded (and,
from the exchange, every one released) to ``grades.csv`` in the course (one not given to the class yet has no
rows: its zeros would read as missed work).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import queue
import re
import secrets
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from assignments import HERE, nbgrader  # noqa: E402 - this folder is not a package
from domains import BOOK_NAME, LEARNER_DOMAINS, DomainBook, DomainError, hub_state  # noqa: E402
from sandboxing import Sandboxes, add_flags_column, clear, course_seed, learner_seed, settle, test_calls  # noqa: E402
from submissions import stage  # noqa: E402

from tutorial.tools.grading.sandbox import UNSANDBOXED  # noqa: E402


def domains(text: str) -> list[int]:
    """``"215-232"`` or ``"5,7,9"`` as a list of ROS domain ids.

    Raises:
        ValueError: not a list or range of the domains a server's learners could have
            (:data:`domains.LEARNER_DOMAINS`: 1 to 101 and 215 to 232; the others are not usable on Linux,
            or everyone's default).
    """
    ids = []
    for part in text.split(","):
        low, _, high = part.partition("-")
        ids.extend(range(int(low), int(high or low) + 1))
    if not ids or not all(i in LEARNER_DOMAINS for i in ids):
        raise ValueError(f"domains {text!r}: grade in ROS domains 1 to 101 or 215 to 232 (see course/domains.py)")
    return ids


def free_domains(book: Path | None = None) -> list[int]:
    """The server's ROS domains the hub's book has given no learner, highest first (the hub gives the lowest).

    ``book``: the hub's book of domains (default: the hub's state folder's, ``RTT_HUB_STATE``); none
    there yet: every domain is free.

    Raises:
        ValueError: every domain is a learner's, or the book cannot be read (the message says what to do).
    """
    try:
        taken = set(DomainBook(book or hub_state() / BOOK_NAME).read().values())
    except DomainError as error:
        raise ValueError(f"{error}; name the domains to grade in with --domains") from None
    free = [d for d in reversed(LEARNER_DOMAINS) if d not in taken]
    if not free:
        raise ValueError(
            "every ROS domain of this server is a learner's, and graded notebooks would hear a learner's robots: "
            "grade on another machine, or name domains no learner runs in now with --domains"
        )
    return free


def released(course: Path) -> list[str]:
    """The assignments released into the course's exchange (nbgrader's own ``list``)."""
    said = nbgrader(course, "list").splitlines()
    start = next((i for i, line in enumerate(said) if line.endswith("Released assignments:")), len(said))
    return sorted(m.group(1) for line in said[start + 1 :] if (m := re.search(r"\] \S+ (\S+)$", line)))


def stage_submissions(course: Path) -> tuple[Path, list[str], list[str]]:
    """The exchange's submissions, copied where only the teacher can write, each checked for who handed it in
    (``course/submissions.py``).

    Returns:
        (the staged exchange's root, which ``nbgrader collect`` reads; one line per refused submission; the
        names whose author cannot be told)
    """
    from nbgrader.coursedir import CourseDirectory

    config = course_config(course)
    limit = 1000 * CourseDirectory(config=config).max_dir_size  # as nbgrader's collect computes it
    return stage(Path(config.Exchange.root) / config.CourseDirectory.course_id, course, limit)


def course_config(course: Path):
    """The course's nbgrader configuration (its ``nbgrader_config.py``), as nbgrader reads it."""
    from traitlets.config.loader import PyFileConfigLoader

    return PyFileConfigLoader("nbgrader_config.py", path=str(course)).load_config()


def enrol(course: Path, names) -> None:
    """The learners ``names`` in the course's gradebook, so that each has a row in the grades' CSV, with zeros
    for an assignment they never submitted (nbgrader lists only the learners its gradebook knows)."""
    from nbgrader.api import Gradebook

    if names:
        with Gradebook(f"sqlite:///{course / 'gradebook.db'}") as gb:
            for name in names:
                gb.update_or_create_student(name)


def the_class(book: Path) -> list[str]:
    """The learners the hub's book of domains has (each who ever started a server), or none (no hub, no book)."""
    try:
        return sorted(json.loads(book.read_text()))
    except (OSError, ValueError, TypeError):  # no book here, or one that free_domains() names
        return []


def learners(course: Path, assignment: str) -> list[str]:
    """Who submitted ``assignment`` (the folders of ``submitted/``)."""
    folder = course / "submitted"
    return sorted(p.name for p in folder.iterdir() if (p / assignment).is_dir()) if folder.is_dir() else []


def grade(
    course: Path,
    assignments: list[str],
    collect: bool = True,
    jobs: int = 1,
    ids=(232,),
    sandboxed: bool = True,
    students: tuple[str, ...] = (),
    class_list: tuple[str, ...] = (),
) -> Path:
    """Grade ``assignments`` in ``course``; the grades' CSV (with its ``flags`` column).

    ``collect``: from the exchange (then each learner's feedback is released into it).  ``sandboxed``: each
    submission runs as a user of its own, without network, limited and sealed (``sandboxing.py``); its
    exercises' points stand only where the seal saw the teacher's check pass them.  ``students``: these
    learners' submissions alone (default: every learner's); one named with no submission is a failure.
    ``class_list``: learners who get a row in the CSV whether or not they submitted anything (:func:`enrol`).

    Raises:
        ValueError: more ``jobs`` than domains in ``ids`` (checked before anything is graded).
        SandboxError: ``sandboxed`` and the sandbox cannot be made here (not root).
        GradingError: some submissions could not be graded; the others were, and the CSV was written.
        RuntimeError: another nbgrader command failed (its output is in the message).
    """
    ids = list(ids)
    if jobs > len(ids):
        raise ValueError(f"{jobs} jobs need {jobs} ROS domains, {len(ids)} given")
    with Sandboxes(course, jobs) if sandboxed else contextlib.nullcontext() as boxes:
        return _grade(course, assignments, collect, jobs, ids, boxes, students, class_list)


def _grade(
    course: Path,
    assignments: list[str],
    collect: bool,
    jobs: int,
    ids: list[int],
    boxes,
    students: tuple[str, ...],
    class_list: tuple[str, ...],
) -> Path:
    failed: list[str] = []  # submissions nbgrader could not grade (the worker threads append)
    keep_private(course)
    staged = None
    if collect:
        staged, refused, unchecked = stage_submissions(course)
        failed.extend(f"{line} (not graded)" for line in refused)
        if unchecked:
            print(f"graded as handed in, unchecked: {', '.join(unchecked)} (no Unix user of this machine has their "
                  "name, as on the trial's spawner, so whether another learner handed one in under that name "
                  "cannot be told)", file=sys.stderr)  # fmt: skip
    if boxes:
        course_seed(course)  # made once, before the worker threads read it
    # feedback goes back into the exchange when one is there: collected now, or before (a --no-collect regrade)
    exchange = collect or Path(course_config(course).Exchange.root).is_dir()
    for assignment in assignments:
        if collect:
            # the staged copies are the teacher's: nbgrader's owner check would warn of every one
            nbgrader(course, "collect", assignment, "--update", f"--Exchange.root={staged}",
                     "--ExchangeCollect.check_owner=False")  # fmt: skip
        who = learners(course, assignment)
        if students:  # a regrade of some: those named, and a name with no submission said
            failed.extend(f"{assignment}, {name}: no submission" for name in students if name not in who)
            who = [w for w in who if w in students]
        calls, checks = test_calls(course, assignment) if boxes else ([], [])  # the seal's, for every learner

        todo: queue.SimpleQueue = queue.SimpleQueue()  # the learners left: each worker takes the next when free
        for learner in who:
            todo.put(learner)

        def worker(k: int, todo=todo, assignment=assignment, calls=calls, checks=checks) -> None:
            """The next learner of ``todo``, until none is left, in domain ids[k]: never two kernels in one domain.

            A submission nbgrader cannot grade (its kernel died, say) is named, and the others are graded.  A
            submission that runs to its timeout holds up this worker alone: the other takes the next ones.
            """
            env = dict(
                os.environ, ROS_DOMAIN_ID=str(ids[k]), ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST", RTT_TEST_MODE="1"
            )
            job = boxes.users[k] if boxes else None
            while True:
                try:
                    learner = todo.get_nowait()
                except queue.Empty:
                    return
                log, died = "", False
                if job:
                    job.test_calls, job.checks = calls, checks
                    job.seed = learner_seed(course, assignment, learner)
                    job.judge_key = secrets.token_hex(32)  # the judge's lines', which no kernel holds
                    Path(job.verdicts).unlink(missing_ok=True)
                    env["RTT_SANDBOX"] = job.to_env()
                else:
                    env[UNSANDBOXED] = "1"  # the teacher's --unsandboxed (nbgrader_config.py refuses otherwise)
                try:
                    log = nbgrader(course, "autograde", assignment, "--student", learner, "--force", env=env)
                except RuntimeError as error:
                    log, died = str(error), True
                    failed.append(f"{assignment}, {learner}: {str(error).splitlines()[0]}")
                finally:
                    if job:
                        clear(job)
                try:
                    problem = settle(course, assignment, learner, job, log, died) if job else None
                except Exception as error:  # noqa: BLE001 - one submission's, named: the others are graded
                    problem = f"not settled ({type(error).__name__}: {error})"
                if problem:
                    failed.append(f"{assignment}, {learner}: {problem}")

        with ThreadPoolExecutor(max_workers=jobs) as pool:
            list(pool.map(worker, range(jobs)))  # list(): a worker's exception is raised here
        if who:
            nbgrader(course, "generate_feedback", assignment, "--force")
            # Into the exchange, for the learners whose submission came through it (nbgrader submit's timestamp
            # and secret, which release_feedback needs): one put into submitted/ by hand is handed back by hand.
            came = ("timestamp.txt", "submission_secret.txt")
            by_hand = [w for w in who if not all((course / "feedback" / w / assignment / f).is_file() for f in came)]
            if exchange and len(by_hand) < len(who):
                exclude = [f"--CourseDirectory.student_id_exclude={','.join(by_hand)}"] if by_hand else []
                nbgrader(course, "release_feedback", assignment, *exclude)
    csv = course / "grades.csv"
    enrol(course, class_list)
    given = sorted(set(assignments) | set(released(course) if collect else ()))
    nbgrader(course, "export", "--to", str(csv), *(f"--assignment={name}" for name in given))
    flagged = add_flags_column(course, csv)
    keep_private(course)  # what grading made, too (autograded/, feedback/, grades.csv)
    if flagged:
        print(f"{len(flagged)} flagged submission(s) (the flags column of {csv.name}):", *flagged, sep="\n  ")
    if failed:
        raise GradingError(csv, failed)
    return csv


def keep_private(course: Path) -> None:
    """The course's folders and files of solutions, submissions and grades: the teacher's alone (0700, 0600).

    A learner's server on the same machine, or a graded kernel, never reads them; the exchange and the
    release, which learners read, are left as they are.
    """
    for name in (
        "source",
        "submitted",
        "staged-exchange",
        "autograded",
        "feedback",
        "gradebook.db",
        "grades.csv",
        "flags.json",
    ):
        path = course / name
        if path.exists():
            os.chmod(path, 0o700 if path.is_dir() else 0o600)


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
    p.add_argument(
        "assignments", nargs="*", help="default: every one released (with --no-collect: every one in submitted/)"
    )
    p.add_argument("--course", type=Path, default=HERE)
    p.add_argument("--no-collect", action="store_true", help="grade what is in submitted/ already")
    p.add_argument("--jobs", type=int, default=1, help="learners graded at once (default 1)")
    p.add_argument(
        "--domains", help="ROS domains for the jobs, as 215-232 or 5,7,9 (default: those the hub gave no learner)"
    )
    p.add_argument(
        "--student", action="append", default=[], help="grade this learner's submission alone (again for more)"
    )
    p.add_argument(
        "--unsandboxed", action="store_true", help="run submissions with your own rights, unsealed (not for a class)"
    )
    args = p.parse_args(argv)
    course = args.course.resolve()
    names: list[str] = []
    try:
        if args.assignments:
            names = args.assignments
        elif args.no_collect:  # what someone submitted: an assignment nobody was given has no rows
            names = sorted({p.name for p in (course / "submitted").glob("*/*") if p.is_dir()})
            if not names:
                print(f"nothing in {course / 'submitted'} to grade", file=sys.stderr)
                return 1
        else:
            exchange = Path(course_config(course).Exchange.root)
            if not exchange.is_dir():  # nbgrader would say "Unwritable directory, please contact your instructor"
                said = f"no exchange at {exchange} yet: `make hub` makes it, and a release puts an assignment in it"
                print(said + " (book/course.md); to grade what is in submitted/, ARGS=--no-collect", file=sys.stderr)
                return 1
            names = released(course)
            if not names:
                print("no assignment is released into the exchange yet: nothing to collect", file=sys.stderr)
                return 1
        unknown = [n for n in names if not (course / "source" / n / f"{n}.ipynb").is_file()]
        if unknown:  # a typo, or make assignments not run yet: said before anything is collected or graded
            made = sorted(p.name for p in (course / "source").glob("*") if p.is_dir())
            print(f"not graded: no assignment {', '.join(unknown)} in {course / 'source'} (`make assignments` "
                  f"makes them; there: {', '.join(made) or 'none'})", file=sys.stderr)  # fmt: skip
            return 2
        ids = domains(args.domains) if args.domains else free_domains()
        csv = grade(
            course,
            names,
            collect=not args.no_collect,
            jobs=args.jobs,
            ids=ids,
            sandboxed=not args.unsandboxed,
            students=tuple(args.student),
            class_list=tuple(n for n in the_class(hub_state() / BOOK_NAME) if n != os.environ.get("RTT_HUB_TEACHER")),
        )
    except GradingError as error:
        print(f"graded {', '.join(names)}: {error.csv}, but {error}", file=sys.stderr)
        return 1
    except (ValueError, RuntimeError) as error:  # DomainError and nbgrader's failures are RuntimeErrors
        print(f"not graded: {error}", file=sys.stderr)
        return 2
    print(f"graded {', '.join(names)}: {csv}; feedback in {course / 'feedback'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
