"""Grading a class with nbgrader: assignments made from the notebooks, fake submissions graded as a teacher would.

``course/assignments.py`` makes a course in a temporary folder (the
teacher's ``course/`` is never touched); the fake submissions start from
the release, as a learner's would:

- the stubs as released: 0 points (``make test-grade``; ``make test`` has
  them only with the checks edited, below);
- the worked solutions pasted in: full points (in ``make test``, handed in
  through the exchange by the learner below);
- each wrong answer of tests/test_exercises.py ``MISTAKES`` (the solution
  with one mistake): it loses exactly its own exercise's points, no other
  (``make test-grade``; in ``make test`` a cheat stands for it);
- a check cell edited to pass always: graded with the original check
  (nbgrader restores read-only test cells), so the stubs still get 0;
- an answer that never returns: interrupted by the cell timeout, 0 for that
  exercise, the others graded.

``course/grade.py`` grades them two at a time, each job in a ROS domain of
its own, writes feedback and the CSV.  One more learner goes the whole way
with nbgrader's own commands: release, fetch and submit through the
exchange, then collect, autograde, feedback, export (their fetched feedback
is the one grading wrote for them, byte for byte); and a submission that
is not a notebook is named as ungradable while the others are graded.

``make test`` grades notebook 01's assignment (one cheat among them), and checks its release;
``make test-grade`` all nine, with every wrong answer.
"""

from __future__ import annotations

import contextlib
import copy
import csv
import io
import json
import os
import re
import shutil
import sys
import types
from pathlib import Path

import pytest
from test_exercises import MISTAKES, VISIBLE_ONLY

from conftest import ROOT

sys.path.insert(0, str(ROOT / "course"))

import assignments  # noqa: E402 - course/ is not a package
import grade  # noqa: E402
import sandboxing  # noqa: E402

pytestmark = pytest.mark.cross_process

IN_MAKE_TEST = ["01_step1_tank_controller"]
ALL = sorted(p.stem for p in (ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb") if not p.stem.startswith("00"))
DOMAINS = [int(os.environ["ROS_DOMAIN_ID"]), int(os.environ["ROS_DOMAIN_ID"]) + 101]  # this session's own
# An endless answer is interrupted after this: notebook 01's cells take under 4 s here, graded two at once;
# all nine notebooks' under 10 s alone, more with two graded at once (CELL_TIMEOUT_ALL_S).
CELL_TIMEOUT_S = 9
ROOT_USER = os.geteuid() == 0  # grading in the sandbox needs root; elsewhere the tests grade unsandboxed
CELL_TIMEOUT_ALL_S = 40


def cells_of(course: Path, name: str, folder: str = "release") -> list[dict]:
    return json.loads((course / folder / name / f"{name}.ipynb").read_text())["cells"]


def grade_id(cell: dict) -> str | None:
    return cell["metadata"].get("nbgrader", {}).get("grade_id")


def solution_of(course: Path, name: str) -> dict[str, str]:
    """Each answer cell's worked solution (the source's, delimiters taken out), by grade id."""
    out = {}
    for cell in cells_of(course, name, "source"):
        gid = grade_id(cell)
        if gid and gid.startswith("exercise_"):
            text = "".join(cell["source"])
            out[gid] = re.sub(r"^### (BEGIN|END) SOLUTION\n?", "", text, flags=re.M)
    return out


def submission(course: Path, name: str, answers: dict[str, str], checks: dict[str, str] | None = None) -> dict:
    """The release of ``name`` with the answer cells ``answers`` (by grade id) and check cells ``checks`` put in."""
    nb = json.loads((course / "release" / name / f"{name}.ipynb").read_text())
    for cell in nb["cells"]:
        gid = grade_id(cell)
        if gid in answers:
            cell["source"] = answers[gid]
        if checks and gid in checks:
            cell["source"] = checks[gid]
    return nb


def exercises_of(name: str) -> list[str]:
    number = str(int(name[:2]))
    return sorted(k for k in assignments.POINTS if k.split(".")[0] == number)


def submissions(course: Path, name: str, every_mistake: bool = True) -> dict[str, tuple[dict, dict[str, float]]]:
    """The fake submissions of ``name``: each one's notebook and the points each exercise must get.

    ``every_mistake``: every wrong answer of ``MISTAKES``, and the stubs alone; else neither.
    """
    solved = solution_of(course, name)
    numbers = exercises_of(name)
    full = {n: float(assignments.POINTS[n]) for n in numbers}
    zero = dict.fromkeys(numbers, 0.0)
    out = {
        "solutions": (submission(course, name, solved), full),
        # the stubs with every check edited to pass: 0 only if nbgrader put the checks back and the stubs fail them
        "check-edited": (
            submission(course, name, {}, {f"check_{n.replace('.', '_')}": "pass  # always passes" for n in numbers}),
            zero,
        ),
    }
    if every_mistake:  # the stubs alone as well (make test-grade); make test's check-edited already holds them to 0
        out["stubs"] = (submission(course, name, {}), zero)
    first = numbers[0]
    gid = f"exercise_{first.replace('.', '_')}"
    # the answer never returns: every function and method it defines starts with an endless loop
    loop = r"\1def \2(\3)\4:\n\1    while True:\n\1        pass\n"
    endless = re.sub(r"^(\s*)def (\w+)\((.*)\)(.*):\n", loop, solved[gid], flags=re.M)
    out["endless"] = (submission(course, name, dict(solved, **{gid: endless})), dict(full, **{first: 0.0}))
    for k, (number, right, wrong, _) in enumerate(MISTAKES):
        if number not in numbers or not every_mistake:  # make test: its cheat stands for a wrong answer
            continue
        key = f"exercise_{number.replace('.', '_')}"
        assert right in solved[key], f"the solution of {number} no longer has {right!r}"
        answers = dict(solved, **{key: solved[key].replace(right, wrong)})
        out[f"mistake-{number}-{k}"] = (submission(course, name, answers), dict(full, **{number: 0.0}))
    return out


@pytest.fixture(scope="module")
def generated_01(tmp_path_factory) -> Path:
    """Assignment 01 made and generated once for this module's tests (its source, release and gradebook)."""
    course = tmp_path_factory.mktemp("generated") / "course"
    assignments.make(course, release=False)
    assignments.nbgrader(course, "generate_assignment", IN_MAKE_TEST[0], "--force")
    return course


@pytest.fixture
def course_01(generated_01, tmp_path) -> Path:
    """A copy of :func:`generated_01`, this test's own to change."""
    course = tmp_path / "course"
    shutil.copytree(generated_01, course, symlinks=True)
    return course


def grade_all(
    tmp: Path, names: list[str], every_mistake: bool = True, exchange: bool = False, cheats: tuple[str, ...] = ()
) -> None:
    """Make the course, put every fake submission in, grade, and hold each exercise's points to the expected.

    ``exchange``: one more learner (this Unix user) fetches the first assignment from nbgrader's exchange,
    solves it and submits it, with nbgrader's own commands; grading then collects it (in place of the
    worked solutions put in by hand: the other submissions put in by hand stay).
    """
    import getpass

    course, home, exchange_dir = tmp / "course", tmp / "learner", tmp / "exchange"
    if cheats and not ROOT_USER:  # said, not silently left out
        import warnings

        warnings.warn("the grading sandbox needs root: graded unsandboxed, without the cheats", stacklevel=2)
        cheats = ()
    assignments.make(course, release=False)
    for name in names:
        assignments.nbgrader(course, "generate_assignment", name, "--force")
        release_shows_the_notebooks_stubs_and_no_solution(course, name)
    if exchange:  # made and not given to the class yet: the grades' CSV must have no rows for it (read as zeros)
        from nbgrader.api import Gradebook

        with Gradebook(f"sqlite:///{course / 'gradebook.db'}") as gb:
            gb.update_or_create_assignment(next(n for n in ALL if n not in names))
    expected = {}
    if exchange:
        name, me = names[0], getpass.getuser()
        exchange_dir.mkdir()
        home.mkdir()
        assignments.nbgrader(course, "release_assignment", name, "--force")
        # the learner, in their own folder: no course configuration there, as on a learner's server
        where = ["--course", "ros-tank-tutorial", f"--Exchange.root={exchange_dir}"]
        assert name in assignments.nbgrader(home, "list", *where)
        assignments.nbgrader(home, "fetch_assignment", name, *where)
        fetched = home / name / f"{name}.ipynb"
        nb = json.loads(fetched.read_text())
        solved = solution_of(course, name)
        for cell in nb["cells"]:  # every exercise solved: this learner's are the full points of the "solutions"
            if grade_id(cell) in solved:
                cell["source"] = solved[grade_id(cell)]
        fetched.write_text(json.dumps(nb))
        assignments.nbgrader(home, "submit", name, *where)
        assert grade.released(course) == [name]  # what make grade collects by default
        expected[(name, me)] = {n: float(assignments.POINTS[n]) for n in exercises_of(name)}
    for name in names:
        made = submissions(course, name, every_mistake)
        if exchange and name == names[0]:  # the learner of the exchange handed in the worked solutions
            del made["solutions"]
        for learner, nb in cheating_submissions(course, name, list(cheats), CHEAT_FILL).items():
            target = CHEATS[learner.removeprefix("cheat-")][0]
            made[learner] = (nb, {n: 0.0 if n == target else float(assignments.POINTS[n]) for n in exercises_of(name)})
        for learner, (nb, points) in made.items():
            folder = course / "submitted" / learner / name
            folder.mkdir(parents=True)
            (folder / f"{name}.ipynb").write_text(json.dumps(nb))
            expected[(name, learner)] = points
    if exchange:  # and a submission nbgrader cannot read: named, and the others graded all the same
        broken = course / "submitted" / "broken" / names[0]
        broken.mkdir(parents=True)
        (broken / f"{names[0]}.ipynb").write_text("{ not a notebook")
        with pytest.raises(grade.GradingError) as caught:
            grade.grade(course, names, collect=exchange, jobs=2, ids=DOMAINS, sandboxed=ROOT_USER)
        assert [line.split(":")[0] for line in caught.value.failed] == [f"{names[0]}, broken"], caught.value.failed
        csv_path = caught.value.csv
    else:
        csv_path = grade.grade(course, names, collect=exchange, jobs=2, ids=DOMAINS, sandboxed=ROOT_USER)

    from nbgrader.api import Gradebook

    wrong = []
    with Gradebook(f"sqlite:///{course / 'gradebook.db'}") as gb:
        for (name, learner), points in sorted(expected.items()):
            for number, want in points.items():
                got = gb.find_grade(f"check_{number.replace('.', '_')}", name, name, learner).score
                if got != want:
                    wrong.append(f"{name} {learner}: exercise {number} got {got}, expected {want}")
    assert not wrong, "\n".join(wrong)
    rows = {(r["assignment"], r["student_id"]): float(r["score"]) for r in csv.DictReader(csv_path.open())}
    for (name, learner), points in expected.items():
        assert rows[(name, learner)] == sum(points.values()), (name, learner, rows[(name, learner)])
        assert (course / "feedback" / learner / name / f"{name}.html").is_file(), f"no feedback for {learner}"
        # the seal's notes are the teacher's, never in the learner's feedback (nbgrader copies what is beside
        # the autograded notebook there)
        assert not list((course / "feedback" / learner).rglob("seal*")), f"the seal's notes went to {learner}"
    honest = getpass.getuser() if exchange else "solutions"  # graded in the sandbox: the seal's notes are kept
    assert not ROOT_USER or (course / "seal" / honest / f"{names[0]}.txt").is_file(), "no seal notes kept"
    assert {name for name, _ in rows} == set(names), "the CSV has rows for an assignment not given to the class"
    flags = {(r["assignment"], r["student_id"]): r["flags"] for r in csv.DictReader(csv_path.open())}
    for cheat in cheats:  # its target flagged; the honest submissions not at all
        target, _, flag = CHEATS[cheat]
        assert f"{target}: {flag}" in flags[(names[0], f"cheat-{cheat}")], flags
    for (name, learner), said in flags.items():  # what nbgrader and the seal saw, nothing more
        if learner == "check-edited" and ROOT_USER:
            assert "changed cell" in said, (name, said)
        elif learner == "endless" and ROOT_USER and not name.startswith("06"):  # 06's loops on its render thread
            assert said == f"{exercises_of(name)[0]}: timeout", (name, said)
        elif not learner.startswith("cheat-"):
            assert said == "", (name, learner, said)  # the solutions, the wrong answers, the stubs: no flag
    if exchange:  # the learner fetches their feedback from the exchange, as from the Assignments tab
        assignments.nbgrader(home, "fetch_feedback", names[0], *where)
        fetched = list((home / names[0] / "feedback").glob(f"*/{names[0]}.html"))
        assert len(fetched) == 1, f"the learner got no feedback: {list(home.rglob('*.html'))}"
        graded = course / "feedback" / me / names[0] / f"{names[0]}.html"
        assert fetched[0].read_bytes() == graded.read_bytes(), "the fetched feedback is not the learner's"


def release_shows_the_notebooks_stubs_and_no_solution(course: Path, name: str) -> None:
    """The release of ``name`` (made in ``course``): the notebook's own stubs, read-only checks, no solution."""
    teacher = json.loads((ROOT / "notebooks" / f"{name}.ipynb").read_text())["cells"]
    release = cells_of(course, name)
    stubs = [c for c in release if (grade_id(c) or "").startswith("exercise_")]
    found = assignments.exercises(teacher)
    assert ["".join(c["source"]) for c in stubs] == ["".join(teacher[e["stub"]]["source"]) for e in found]
    text = json.dumps(release)
    assert "Worked solution" not in text and "BEGIN SOLUTION" not in text
    checks = [c for c in release if (grade_id(c) or "").startswith("check_")]
    assert [c["metadata"]["nbgrader"]["points"] for c in checks] == [assignments.POINTS[e["number"]] for e in found]
    assert all(c["metadata"]["nbgrader"]["locked"] for c in checks)
    assert all("".join(c["source"]).rstrip().endswith(".require()") for c in checks)


def test_grading_takes_only_domains_no_learner_was_given(tmp_path):
    """make grade's default domains: none the hub's book gave a learner, so a graded notebook never hears one."""
    import domains as hub_domains

    book = tmp_path / "ros_domains.json"
    assert grade.free_domains(book)[:2] == [232, 231]  # no hub yet: every domain, from the top
    book.write_text(json.dumps({"learner1": 1, "learner2": 2, "late": 232}))
    free = grade.free_domains(book)
    assert free[0] == 231 and not {1, 2, 232} & set(free) and len(free) == len(hub_domains.LEARNER_DOMAINS) - 3
    book.write_text(json.dumps({f"l{d}": d for d in hub_domains.LEARNER_DOMAINS}))
    with pytest.raises(ValueError, match="every ROS domain of this server is a learner's"):
        grade.free_domains(book)
    book.write_text("{ not a book")
    with pytest.raises(ValueError, match="name the domains to grade in with --domains"):
        grade.free_domains(book)
    # The hub (root, with learners as Unix users) writes the book; the teacher's make grade must read it.
    kept = hub_domains.DomainBook(tmp_path / "kept.json")
    kept.domain_for("learner1")
    assert (tmp_path / "kept.json").stat().st_mode & 0o777 == 0o644


def test_the_hidden_cases_seed_is_the_teachers_alone_and_the_same_on_a_regrade(tmp_path):
    """course/.grading_seed: made once, 0600; each learner's seed of an assignment the same every time it is
    asked, another for another learner, another assignment or another course."""
    import stat

    (tmp_path / "a").mkdir()
    first = sandboxing.learner_seed(tmp_path / "a", "01", "ada")
    assert stat.S_IMODE((tmp_path / "a" / ".grading_seed").stat().st_mode) == 0o600
    assert sandboxing.learner_seed(tmp_path / "a", "01", "ada") == first  # a regrade draws the same cases
    assert sandboxing.learner_seed(tmp_path / "a", "01", "bob") != first
    assert sandboxing.learner_seed(tmp_path / "a", "02", "ada") != first
    (tmp_path / "b").mkdir()
    assert sandboxing.learner_seed(tmp_path / "b", "01", "ada") != first  # another course, another seed
    assert len(first) == 16 and int(first, 16) >= 0


def test_grading_domains_named_by_hand_are_ones_fast_dds_can_use():
    """--domains: 1 to 101 and 215 to 232; 0 is everyone's default, 102 to 214 have no ports on Linux."""
    assert grade.domains("215-217,5") == [215, 216, 217, 5]
    for text in ("0", "101-102", "150", "233", "", "7,x"):
        with pytest.raises(ValueError):
            grade.domains(text)


def test_grading_what_was_submitted_says_when_nothing_was(tmp_path, capsys):
    """make grade ARGS=--no-collect grades what is in submitted/, and says so when nothing is."""
    (tmp_path / "submitted").mkdir()
    assert grade.main(["--course", str(tmp_path), "--no-collect", "--domains", "232"]) == 1
    assert "nothing in" in capsys.readouterr().err


def test_grading_before_there_is_an_exchange_says_where_it_comes_from(tmp_path, capsys):
    """make grade before make hub made the exchange: not nbgrader's "please contact your instructor"."""
    from hub import teacher_course

    course = teacher_course(tmp_path / "course", tmp_path / "no-exchange")
    assert grade.main(["--course", str(course), "--domains", "232"]) == 1
    said = capsys.readouterr().err
    assert f"no exchange at {tmp_path / 'no-exchange'} yet: `make hub` makes it" in said, said


def test_grading_an_assignment_the_course_does_not_have_says_so_before_anything_is_graded(tmp_path, capsys):
    """make grade ARGS=01_step1_tank_controler (a typo), or before make assignments: which ones there are."""
    (tmp_path / "source" / "01_step1_tank_controller").mkdir(parents=True)
    (tmp_path / "source" / "01_step1_tank_controller" / "01_step1_tank_controller.ipynb").write_text("{}")
    args = ["--course", str(tmp_path), "--domains", "232", "01_step1_tank_controler"]
    assert grade.main(args) == 2
    said = capsys.readouterr().err
    assert "no assignment 01_step1_tank_controler" in said and "there: 01_step1_tank_controller" in said, said
    assert not (tmp_path / "staged-exchange").exists() and not (tmp_path / "submitted").exists()


def test_grading_one_learner_grades_theirs_alone_and_names_one_who_submitted_nothing(tmp_path, capsys, course_01):
    """make grade ARGS="--student NAME": a regrade of one learner; a name with no submission is said."""
    name = IN_MAKE_TEST[0]
    course = course_01
    folder = course / "submitted" / "someone" / name
    folder.mkdir(parents=True)
    (folder / f"{name}.ipynb").write_text(json.dumps(submission(course, name, {})))
    args = ["--course", str(course), "--no-collect", "--domains", "232", "--unsandboxed", "--student", "nobody", name]
    assert grade.main(args) == 1
    assert f"{name}, nobody: no submission" in capsys.readouterr().err
    assert not (course / "autograded" / "someone").exists(), "another learner's submission was graded"


def submitted_with_a_mark(course: Path, tmp_path: Path) -> Path:
    """Learner ``learner``'s submission of assignment 01 in ``course``: the worked solutions, the first answer
    cell leaving a file when it runs; that file (which must not exist after a run that runs no answer)."""
    name = IN_MAKE_TEST[0]
    ran = tmp_path / "the-answer-ran"
    solved = solution_of(course, name)
    first = sorted(solved)[0]
    answers = dict(solved, **{first: f"open({str(ran)!r}, 'w').close()\n" + solved[first]})
    folder = course / "submitted" / "learner" / name
    folder.mkdir(parents=True)
    (folder / f"{name}.ipynb").write_text(json.dumps(submission(course, name, answers)))
    return ran


@pytest.mark.more  # make test keeps the command's refusal (test_nbgrader_autograde_by_hand_runs_no_answer_...)
def test_the_formgraders_autograde_runs_no_answer_either(course_01, tmp_path, monkeypatch):
    """The formgrader's Autograde button (nbgrader's API, in the Jupyter server's process): refused the same way,
    by the executor the course's configuration puts in nbgrader's place."""
    from nbgrader.apps import NbGraderAPI
    from nbgrader.coursedir import CourseDirectory

    name = IN_MAKE_TEST[0]
    ran = submitted_with_a_mark(course_01, tmp_path)
    for variable in ("RTT_SANDBOX", "RTT_UNSANDBOXED"):
        monkeypatch.delenv(variable, raising=False)
    monkeypatch.chdir(course_01)
    config = grade.course_config(course_01)
    api = NbGraderAPI(coursedir=CourseDirectory(config=config, root=str(course_01)), config=config)
    result = api.autograde(name, "learner")
    assert not result["success"] and "make grade" in result["error"] + result.get("log", ""), result
    assert not ran.exists(), "the answer ran"


def test_the_teachers_exchange_is_the_hubs_wherever_its_state_folder_is(tmp_path, monkeypatch):
    """RTT_HUB_STATE moves the hub's exchange: the teacher's nbgrader (the course's configuration) follows it."""
    monkeypatch.delenv("RTT_NBGRADER_EXCHANGE", raising=False)
    monkeypatch.setenv("RTT_HUB_STATE", str(tmp_path / "state"))
    assert grade.course_config(ROOT / "course").Exchange.root == str(tmp_path / "state" / "exchange")
    monkeypatch.setenv("RTT_NBGRADER_EXCHANGE", str(tmp_path / "srv"))
    assert grade.course_config(ROOT / "course").Exchange.root == str(tmp_path / "srv")


def test_every_learner_of_the_hubs_book_has_a_row_also_without_a_submission(tmp_path, course_01):
    """grades.csv: a row per learner the hub knows, zeros for an assignment they never handed in."""
    name = IN_MAKE_TEST[0]
    course = course_01
    book = tmp_path / "ros_domains.json"
    book.write_text(json.dumps({"learner1": 3, "late": 4}))
    assert grade.the_class(book) == ["late", "learner1"] and grade.the_class(tmp_path / "none.json") == []
    grade.enrol(course, grade.the_class(book))
    out = tmp_path / "grades.csv"
    assignments.nbgrader(course, "export", "--to", str(out), f"--assignment={name}")
    rows = {r["student_id"]: r for r in csv.DictReader(out.open())}
    assert set(rows) == {"late", "learner1"} and all(float(r["score"]) == 0 for r in rows.values()), rows


@pytest.mark.more  # make test grades through the exchange in test_grading_notebook_01s_assignment
def test_a_regrade_of_what_was_collected_releases_its_new_feedback(tmp_path, monkeypatch, course_01):
    """make grade ARGS=--no-collect after a collect: the learner fetches the regrade's feedback, not the old one."""
    import getpass

    name, me = IN_MAKE_TEST[0], getpass.getuser()
    exchange, home = tmp_path / "exchange", tmp_path / "learner"
    exchange.mkdir()
    home.mkdir()
    monkeypatch.setenv("RTT_NBGRADER_EXCHANGE", str(exchange))
    course = course_01
    assignments.nbgrader(course, "release_assignment", name, "--force")
    where = ["--course", "ros-tank-tutorial", f"--Exchange.root={exchange}"]
    assignments.nbgrader(home, "fetch_assignment", name, *where)
    assignments.nbgrader(home, "submit", name, *where)
    released = exchange / "ros-tank-tutorial" / "feedback"
    grade.grade(course, [name], collect=True, ids=DOMAINS[:1], sandboxed=False)
    assert list(released.iterdir()), "the first grading released no feedback"
    shutil.rmtree(released)
    grade.grade(course, [name], collect=False, ids=DOMAINS[:1], sandboxed=False, students=(me,))
    assert released.is_dir() and list(released.iterdir()), "the regrade's feedback was not released"


def exchange_and_course(tmp_path: Path) -> tuple[Path, Path]:
    """An exchange with this course's folder (the teacher's, as nbgrader's release makes it) and a course
    whose nbgrader configuration names it."""
    from hub import teacher_course

    exchange = tmp_path / "exchange"
    (exchange / "ros-tank-tutorial").mkdir(parents=True, mode=0o755)
    return exchange / "ros-tank-tutorial", teacher_course(tmp_path / "course", exchange)


def staged_names(root: Path) -> list[str]:
    return sorted(p.name for p in (root / "ros-tank-tutorial" / "inbound").iterdir())


STAMP = "2026-11-26 10:00:00.000000 UTC"


@pytest.mark.skipif(not ROOT_USER, reason="handing a folder to another user needs root")
def test_a_submission_handed_in_under_another_learners_name_is_refused(tmp_path):
    """A learner can name anyone in ``nbgrader submit --student``: where learners are Unix users, a submission
    not owned by the user of the name it bears is left out of what grading collects."""
    import pwd

    exchange, course = exchange_and_course(tmp_path)
    inbound = exchange / "inbound"
    inbound.mkdir()
    me = pwd.getpwnam("nobody")  # uid 65534: an account above the system ones, standing in for a learner
    handed = {  # the name it bears -> who handed it in
        f"nobody+hello+{STAMP}+abc": me.pw_uid,  # their own
        "nobody+hello+2026-11-26 11:00:00.000000 UTC+def": 0,  # root's, under nobody's name, newer
        f"learner-x+hello+{STAMP}+ghi": me.pw_uid,  # no account of that name
        f"daemon+hello+{STAMP}+jkl": me.pw_uid,  # a system account's name: no learner, so not checked
        f"nobody+hello+{STAMP}+mno": me.pw_uid,  # their folder, with root's file in it (a hard link, say)
    }
    for name, uid in handed.items():
        (inbound / name).mkdir()
        (inbound / name / "hello.ipynb").write_text(name)
        os.chown(inbound / name, uid, uid)
        os.chown(inbound / name / "hello.ipynb", uid, uid)
    os.chown(inbound / f"nobody+hello+{STAMP}+mno" / "hello.ipynb", 0, 0)
    root, refused, unchecked = grade.stage_submissions(course)
    forged = "nobody+hello+2026-11-26 11:00:00.000000 UTC+def"
    assert refused == [
        f"nobody+hello+{STAMP}+mno: holds 'hello.ipynb', which is root's",
        f"{forged}: handed in by root, not nobody",
    ], refused
    assert unchecked == ["daemon", "learner-x"]
    assert staged_names(root) == sorted(set(handed) - {forged, f"nobody+hello+{STAMP}+mno"})
    staged = root / "ros-tank-tutorial" / "inbound" / f"nobody+hello+{STAMP}+abc"
    assert (staged / "hello.ipynb").read_text() == f"nobody+hello+{STAMP}+abc" and staged.stat().st_uid == 0
    assert root.stat().st_mode & 0o077 == 0  # out of the learners' reach
    assert sorted(p.name for p in inbound.iterdir()) == sorted(handed)  # the exchange is left as it was


def test_a_submission_holding_a_link_a_special_file_or_an_unreadable_time_is_refused(tmp_path):
    """Grading copies a submission without following any link: one that holds a link (to another learner's
    work, the teacher's solutions), a hard link or a special file is refused whole, as is one whose time nbgrader cannot
    read (which would stop the collection of the whole class)."""
    exchange, course = exchange_and_course(tmp_path)
    inbound = exchange / "inbound"
    inbound.mkdir()
    secret = tmp_path / "solutions"
    secret.mkdir()
    (secret / "hello.ipynb").write_text("the teacher's")
    good = f"learner-a+hello+{STAMP}+a"
    (inbound / good / "sub").mkdir(parents=True)
    (inbound / good / "sub" / "hello.ipynb").write_text("mine")
    (inbound / f"learner-b+hello+{STAMP}+b").symlink_to(secret)  # the submission itself a link
    (inbound / f"learner-c+hello+{STAMP}+c").mkdir()
    (inbound / f"learner-c+hello+{STAMP}+c" / "hello.ipynb").symlink_to(secret / "hello.ipynb")  # a link in it
    (inbound / f"learner-d+hello+{STAMP}+d").mkdir()
    os.mkfifo(inbound / f"learner-d+hello+{STAMP}+d" / "hello.ipynb")  # a pipe: reading it would never end
    (inbound / f"learner-i+hello+{STAMP}+i").mkdir()
    os.link(secret / "hello.ipynb", inbound / f"learner-i+hello+{STAMP}+i" / "hello.ipynb")  # a second name
    (inbound / "learner-e+hello+yesterday+e").mkdir()
    (inbound / "learner-f").mkdir()
    (inbound / f"learner-g+hello+{STAMP}+x+y").mkdir()  # nbgrader would read its time as "x": collect would stop
    deep = inbound / f"learner-h+hello+{STAMP}+h"
    deep.mkdir()
    fd = os.open(deep, os.O_RDONLY)
    for _ in range(17):  # a copy path past the 4096 bytes a path may have (made a folder at a time)
        os.mkdir("d" * 250, dir_fd=fd)
        fd, parent = os.open("d" * 250, os.O_RDONLY, dir_fd=fd), fd
        os.close(parent)
    os.close(fd)
    (inbound / good / "timestamp.txt").write_text("soon")  # would stop every later collection
    root, refused, _ = grade.stage_submissions(course)
    assert staged_names(root) == [good]
    copied = root / "ros-tank-tutorial" / "inbound" / good
    assert (copied / "sub" / "hello.ipynb").read_text() == "mine"
    assert (copied / "timestamp.txt").read_text() == STAMP  # the time in its name
    assert refused == [
        f"learner-b+hello+{STAMP}+b: not a folder",
        f"learner-c+hello+{STAMP}+c: holds 'hello.ipynb', a link or a special file",
        f"learner-d+hello+{STAMP}+d: holds 'hello.ipynb', a link or a special file",
        "learner-e+hello+yesterday+e: its time cannot be read",
        "learner-f: not a submission's name",
        f"learner-g+hello+{STAMP}+x+y: not a submission's name",
        f"learner-h+hello+{STAMP}+h: could not be copied (OSError)",
        f"learner-i+hello+{STAMP}+i: holds 'hello.ipynb', a file with another name too (a hard link)",
    ], refused
    assert list((root / "ros-tank-tutorial" / "inbound").glob("learner-h*")) == []  # no part of it left


def test_a_submission_larger_than_the_course_allows_is_refused(tmp_path):
    """nbgrader's collect stops for the whole class on a submission over its limit: staging refuses it alone."""
    exchange, course = exchange_and_course(tmp_path)
    with open(course / "nbgrader_config.py", "a") as config:
        config.write("c.CourseDirectory.max_dir_size = 1  # kB\n")
    (exchange / "inbound" / f"learner-a+hello+{STAMP}+a").mkdir(parents=True)
    (exchange / "inbound" / f"learner-a+hello+{STAMP}+a" / "big.bin").write_bytes(b"x" * 1001)
    (exchange / "inbound" / f"learner-b+hello+{STAMP}+b").mkdir()
    (exchange / "inbound" / f"learner-b+hello+{STAMP}+b" / "small.bin").write_bytes(b"x" * 900)
    root, refused, _ = grade.stage_submissions(course)
    assert refused == [f"learner-a+hello+{STAMP}+a: larger than the course allows (nbgrader's max_dir_size)"]
    assert staged_names(root) == [f"learner-b+hello+{STAMP}+b"]


def test_a_submission_handed_in_from_a_container_under_another_name_is_refused(tmp_path):
    """Learners in containers hand in to folders of their own, named by the hub (course/container_exchange.py):
    grading stages each one's own and refuses one bearing another learner's name."""
    exchange, course = exchange_and_course(tmp_path)
    by_learner = exchange / "inbound-by-learner"
    by_learner.mkdir(mode=0o711)
    handed = {  # folder (the hub's name) -> the submissions in it, by the names they bear
        "learner-a": [f"learner-a+hello+{STAMP}+abc", "learner-b+hello+2026-11-26 11:00:00.000000 UTC+x"],
        "learner-b": [f"learner-b+hello+{STAMP}+def"],
    }
    for folder, names in handed.items():
        for name in names:
            (by_learner / folder / name).mkdir(parents=True)
            (by_learner / folder / name / "hello.ipynb").write_text(folder)
    root, refused, unchecked = grade.stage_submissions(course)
    forged = handed["learner-a"][1]
    assert refused == [f"{forged}: handed in by learner-a, not learner-b"], refused
    assert unchecked == []  # the folders said who handed each in
    assert staged_names(root) == [handed["learner-a"][0], handed["learner-b"][0]]
    # a course folder a learner could have put in place of the teacher's is not graded at all
    os.chmod(exchange, 0o777)
    with pytest.raises(RuntimeError, match="is not the teacher's"):
        grade.stage_submissions(course)


def test_a_class_hub_gives_learners_the_notebooks_without_the_worked_solutions():
    """Each notebook as the hub copies it to a learner: every cell but the folded solutions, outputs and all."""
    for name in ALL:
        teacher = json.loads((ROOT / "notebooks" / f"{name}.ipynb").read_text())
        found = assignments.exercises(teacher["cells"])
        given = assignments.learner_notebook(teacher)
        assert "Worked solution to Exercise" not in json.dumps(given), name
        solutions = {ex["solution"] for ex in found}
        kept = [c for i, c in enumerate(teacher["cells"]) if i not in solutions]
        assert len(given["cells"]) == len(kept) == len(teacher["cells"]) - len(found) > 0, name
        for mine, theirs in zip(given["cells"], kept):
            assert mine.get("outputs") == theirs.get("outputs") and mine["cell_type"] == theirs["cell_type"], name
            if mine["cell_type"] == "code":  # the stubs and checks as the teacher's: the learner's to solve
                assert mine["source"] == theirs["source"], name
        assert teacher == json.loads((ROOT / "notebooks" / f"{name}.ipynb").read_text()), "the teacher's changed"
    text = json.dumps(assignments.learner_notebook(json.loads((ROOT / "notebooks" / f"{ALL[0]}.ipynb").read_text())))
    assert "A worked solution follows" not in text and "the worked solutions are held back" in text


def test_a_notebook_without_points_for_an_exercise_is_refused():
    nb = json.loads((ROOT / "notebooks" / f"{IN_MAKE_TEST[0]}.ipynb").read_text())
    saved = copy.deepcopy(assignments.POINTS)
    try:
        del assignments.POINTS["1.2"]
        with pytest.raises(ValueError, match="exercise 1.2 has no points"):
            assignments.source_notebook(nb)
    finally:
        assignments.POINTS.clear()
        assignments.POINTS.update(saved)


def test_a_dead_kernel_is_flagged_where_it_died_and_an_answer_cannot_say_so_itself(tmp_path, monkeypatch):
    """What the sandbox's executor marks in a cell's metadata, and what judge reads from it: a crash on the exercise
    whose cell was running, `not run` on the ones after it, `over a limit` (and no crash) for the CPU time; an
    answer's own error named DeadKernelError, or a mark the submission brought, flags nothing."""
    from nbclient.exceptions import DeadKernelError
    from nbformat.v4 import new_code_cell, new_notebook, new_output
    from nbgrader.preprocessors import Execute

    from tutorial.tools.grading import sandbox

    def cells(number, marks, check_error=None):  # an exercise's answer and check cells, each with its mark
        out = []
        for kind, mark in zip(("exercise", "check"), marks):
            cell = new_code_cell("", metadata={"nbgrader": {"grade_id": f"{kind}_{number}", "grade": kind == "check"}})
            if mark:  # as the executor leaves it
                cell.metadata[sandbox.KERNEL_MARK] = mark
                cell.outputs = [new_output("error", ename="DeadKernelError", evalue=mark, traceback=[])]
            out.append(cell)
        if check_error:
            out[1].outputs = [new_output("error", ename=check_error[0], evalue=check_error[1], traceback=[])]
        return out

    nb = new_notebook(
        cells=[
            *cells("1_1", (None, None), ("DeadKernelError", "the kernel died while this cell ran")),  # the answer's
            *cells("1_2", (None, None), ("SystemExit", "its CPU time ran out")),  # the answer's words, no limit
            *cells("1_3", (None, sandbox.DIED)),
            *cells("1_4", (sandbox.NOT_RUN_MARK, sandbox.NOT_RUN_MARK)),
        ]
    )
    path = tmp_path / "graded.ipynb"
    path.write_text(json.dumps(nb))
    judged = sandboxing.judge(path, tmp_path / "no-verdicts", "")
    assert {ex: flags for ex, (_, flags) in judged.items()} == {
        "1.1": [],
        "1.2": [],
        "1.3": ["crash"],
        "1.4": ["not run"],
    }
    nb.cells[4].metadata[sandbox.KERNEL_MARK] = nb.cells[5].metadata[sandbox.KERNEL_MARK] = sandbox.OUT_OF_CPU_TIME
    path.write_text(json.dumps(nb))
    assert sandboxing.judge(path, tmp_path / "no-verdicts", "")["1.3"] == (False, ["over a limit"])
    # died in a cell before the first exercise (the set-up, or one the learner added at the top): that one's crash
    setup = new_code_cell("", metadata={sandbox.KERNEL_MARK: sandbox.DIED})
    setup.outputs = [new_output("error", ename="DeadKernelError", evalue=sandbox.KERNEL_DIED, traceback=[])]
    for cell in nb.cells:
        cell.metadata[sandbox.KERNEL_MARK] = sandbox.NOT_RUN_MARK
        cell.outputs = [new_output("error", ename="DeadKernelError", evalue=sandbox.NOT_RUN, traceback=[])]
    nb.cells.insert(0, setup)
    path.write_text(json.dumps(nb))
    judged = sandboxing.judge(path, tmp_path / "no-verdicts", "")
    assert {ex: flags for ex, (_, flags) in judged.items()} == {
        "1.1": ["crash"],
        "1.2": ["not run"],
        "1.3": ["not run"],
        "1.4": ["not run"],
    }
    del nb.cells[0]

    # the executor: a submission's own marks taken off before the run, its marks written as the kernel fares
    ran = []
    monkeypatch.setattr(Execute, "preprocess", lambda self, nb, resources=None, km=None: (nb, resources))

    def run(self, cell, resources, index):
        ran.append(index)
        if index == 1:
            raise DeadKernelError("died")
        return cell, resources

    monkeypatch.setattr(Execute, "preprocess_cell", run)
    executor = sandbox.SandboxedExecute()
    executor.preprocess(nb, {})
    assert not any(sandbox.KERNEL_MARK in c.metadata for c in nb.cells)
    marked = []  # each cell's start, said on the seal's pipe (the manager's mark_cell) before it runs
    executor.km = types.SimpleNamespace(mark_cell=marked.append)
    for index, cell in enumerate(nb.cells):
        executor.preprocess_cell(cell, {}, index)
    assert ran == [0, 1] and marked == [0, 1]  # none after the kernel died
    marks = [c.metadata.get(sandbox.KERNEL_MARK) for c in nb.cells]
    assert marks == [None, sandbox.DIED] + [sandbox.NOT_RUN_MARK] * 6
    assert nb.cells[1].outputs[-1]["evalue"] == sandbox.KERNEL_DIED
    not_run = dict(output_type="error", ename="DeadKernelError", evalue=sandbox.NOT_RUN, traceback=[sandbox.NOT_RUN])
    assert all(c.outputs == [not_run] for c in nb.cells[2:])
    executor.preprocess(nb, {})  # the next notebook: a kernel of its own
    assert not executor._died and not any(sandbox.KERNEL_MARK in c.metadata for c in nb.cells)


def test_the_seals_lines_are_all_read_before_nbgrader_goes_on_after_a_kernel_died():
    """nbclient only cleans up after a dead kernel (it shuts down a live one): that, too, waits for the verdict
    reader, which ends when the pipe's last writer is gone."""
    import asyncio
    import threading

    from tutorial.tools.grading import sandbox

    manager = sandbox.SandboxedKernelManager()
    drained = threading.Event()
    # a reader that drains for 2 s, far longer than the clean-up itself takes
    manager._reader = threading.Thread(target=lambda: drained.wait(2.0) or drained.set(), daemon=True)
    manager._reader.start()
    asyncio.run(manager.cleanup_resources())  # what nbclient's _async_cleanup_kernel calls for a dead kernel
    assert drained.is_set() and not manager._reader.is_alive()


def test_grading_notebook_01s_assignment(tmp_path, monkeypatch):
    """Graded sandboxed (as root), with one cheat among the submissions: 0 for its target, flagged."""
    monkeypatch.setenv("RTT_GRADING_CELL_TIMEOUT", str(CELL_TIMEOUT_S))  # read by the course's nbgrader_config.py
    monkeypatch.setenv("RTT_NBGRADER_EXCHANGE", str(tmp_path / "exchange"))
    grade_all(tmp_path, IN_MAKE_TEST, every_mistake=False, exchange=True, cheats=tuple(IN_MAKE_TEST_CHEATS))


@pytest.mark.slow
@pytest.mark.timeout(2400)  # about 150 notebooks run, two at a time
def test_grading_every_assignment(tmp_path, monkeypatch):
    monkeypatch.setenv("RTT_GRADING_CELL_TIMEOUT", str(CELL_TIMEOUT_ALL_S))
    monkeypatch.setenv("RTT_NBGRADER_EXCHANGE", str(tmp_path / "exchange"))
    grade_all(tmp_path, ALL)


# ---- submissions that cheat (the sandbox and seal: tutorial/tools/grading/, course/sandboxing.py) ----

STUB_1_1 = "def dpad_track_velocities(axes):\n    raise NotImplementedError\n"
GRADER = "import tutorial.exercises.grader as grader\n"
# Python that finds a key named rtt-cheat in its user's keyring, user-session keyring or persistent keyring
# (keyctl(2) through ctypes, x86_64's numbers: the kernel's seal refuses ctypes to an answer, not to a process it
# starts), in a session keyring of its own; and what it puts there, and how it empties them.  Linux keeps them by
# user ID, past the processes that wrote them.
KEYRINGS = (
    "import ctypes\n"
    "libc = ctypes.CDLL(None, use_errno=True)\n"
    "def keyctl(*a):\n"
    "    return libc.syscall(250, *(ctypes.c_long(x) if isinstance(x, int) else x for x in a))\n"
    "keyctl(1, 0)\n"
    "rings = (-4, -5, keyctl(22, -1, -3))\n"
    "found = [r for r in rings if keyctl(10, r, b'user', b'rtt-cheat', 0) >= 0]\n"
)
LEAVE_A_KEY = "for r in rings:\n    libc.syscall(248, b'user', b'rtt-cheat', b'answers', 7, ctypes.c_long(r))\n"
SAY_AND_LEAVE = "print('yes' if found else 'no')\n" + LEAVE_A_KEY
EMPTY_THEM = "for r in rings:\n    keyctl(7, r)\n"
# Each cheat: (the exercise it targets, the code put in that exercise's answer cell after its stub, the flag
# it must get, or "": none).  The other exercise keeps its worked solution and its points.  A cheat on a
# global (the grader, IPython) targets 1.2, the later check: a change cannot reach a check that ran before it.
CHEATS = {
    "rebind-check": (
        "1.1",
        GRADER + "import tutorial.exercises.step1_tank_controller as m\n"
        "m.check_dpad_steering = lambda f: grader.Result('Exercise 1.1, steer with the D-pad', True, 'passed')\n",
        "tampering",
    ),
    "patch-grader": ("1.2", GRADER + "grader.Result.require = lambda self: self\n", "tampering"),
    # a file read in an answer whose check then never begins (rebound): flagged on that exercise, not the next
    "read-and-rebind": (
        "1.1",
        "try:\n    open('{root}/course/grade.py').read()\nexcept OSError:\n    pass\n"
        + GRADER
        + "import tutorial.exercises.step1_tank_controller as m\n"
        "m.check_dpad_steering = lambda f: grader.Result('Exercise 1.1, steer with the D-pad', True, 'passed')\n",
        "outside its folder",
    ),
    # ... and in the last exercise's answer, nothing beginning after it: flagged all the same, not lost
    "read-and-rebind-last": (
        "1.2",
        "try:\n    open('{root}/course/grade.py').read()\nexcept OSError:\n    pass\n"
        + GRADER
        + "import tutorial.exercises.step1_tank_controller as m\n"
        "m.check_shot_counter = lambda c: grader.Result('Exercise 1.2, count the shots', True, 'passed')\n",
        "outside its folder",
    ),
    "always-equal": (
        "1.1",
        "class Anything(float):\n    def __eq__(self, other):\n        return True\n"
        "    def __sub__(self, other):\n        return 0.0\n"
        "def dpad_track_velocities(axes):\n    return (Anything(0), Anything(0))\n",
        "tampering",
    ),
    "showtraceback": (
        "1.2",
        "shell = get_ipython()\nshell.showtraceback = lambda *a, **k: None\n"
        "shell._showtraceback = lambda *a, **k: None\n",
        "tampering",
    ),
    "read-solutions": (
        "1.1",
        "found = 0\n"
        "for path in ('{root}/notebooks/01_step1_tank_controller.ipynb',\n"
        "             '{course}/source/01_step1_tank_controller/01_step1_tank_controller.ipynb'):\n"
        "    try:\n        exec(open(path).read().split('Worked solution to Exercise 1.1.')[1].split('check_')[0])\n"
        "        found += 1\n"
        "    except (OSError, IndexError, SyntaxError):\n        pass\n"
        "print('solutions found:', found)\n",
        "outside its folder",
    ),
    "read-another-learner": (
        "1.1",
        "try:\n    open('{course}/submitted/cheat-endless/01_step1_tank_controller/01_step1_tank_controller.ipynb')\n"
        "    print('read another learner: yes')\n"
        "except OSError:\n    print('read another learner: no')\n" + STUB_1_1,
        "outside its folder",
    ),
    "write-home-and-gradebook": (  # and a note for the next submission, where anyone may write on this machine
        "1.1",
        "for path in ('{home}/rtt-cheat', '{course}/gradebook.db', '/run/lock/rtt-cheat', '/var/lock/rtt-cheat'):\n"
        "    try:\n        open(path, 'a').write('rtt-cheat-mark')\n    except OSError:\n        pass\n" + STUB_1_1,
        "outside its folder",
    ),
    "network": (
        "1.1",
        "import socket\ntry:\n    socket.create_connection(('127.0.0.1', {port}), timeout=2).sendall(b'answers?')\n"
        "except OSError:\n    pass\n" + STUB_1_1,
        "network",
    ),
    "fork-bomb": (
        "1.2",
        "import os, time\nborn = 0\nwhile born < 2000:\n    if os.fork() == 0:\n        time.sleep(120)\n"
        "        os._exit(0)\n    born += 1\n",
        "over a limit",
    ),
    "memory-hog": (
        "1.2",
        "hog = []\nwhile len(hog) < 16:  # 4 GiB, every page touched\n"
        "    hog.append(bytearray(256 << 20))\n    hog[-1][::4096] = b'x' * (256 << 8)\n",
        "over a limit",
    ),
    "endless": ("1.1", "while True:\n    pass\n", "timeout"),
    "crash": ("1.2", "import os\nos.kill(os.getpid(), 9)\n", "crash"),  # 1.1, before it, keeps its points
    # graded alone, with the CPU time limit below the cell timeout (test_a_kernel_over_its_cpu_time_...)
    "cpu-time": ("1.2", "while True:\n    pass\n", "over a limit"),
    "stack-walk": (  # the check's expected values down the stack: the judge runs every check, nothing to read
        "1.2",
        "import traceback\n"
        "class ShotCountingTankController(RttTankController):\n"
        "    def summary(self):\n"
        "        try:\n            1 / 0\n        except ZeroDivisionError as e:\n"
        "            frame = next(traceback.walk_tb(e.__traceback__))[0]\n"
        "        while frame is not None and 'expected' not in frame.f_locals:\n"
        "            frame = frame.f_back\n"
        "        print('an expected value on the stack:', 'yes' if frame is not None else 'no')\n"
        "        return {**super().summary(), 'shots': frame.f_locals['expected'] if frame is not None else 0}\n",
        "",
    ),
    "replace-the-experiments": (  # what the judge asks the kernel to run on the class, replaced by the rules
        "1.2",
        GRADER + "import tutorial.exercises.step1_tank_controller as m\n"
        "said = {'_shots_counted': lambda cls, presses: m._shots(presses),\n"
        "        '_input_after_one_joy': lambda cls, buttons, axes: (1, axes),\n"
        "        '_summary_after_one_joy': lambda cls, buttons: {'joy_received': 1},\n"
        "        '_state_touched': lambda cls, presses: ([], [])}\n"
        "for name, fake in said.items():\n"
        "    grader.EXPERIMENTS[f'{m.__name__}:{name}'] = fake\n",
        "tampering",
    ),
    "copy-the-rule": (  # the check module's own rule, called: full points, which the teacher must see
        "1.1",
        "import math\nfrom tutorial.exercises.step1_tank_controller import _dpad\n"
        "def dpad_track_velocities(axes):\n"
        "    a = [x if math.isfinite(x) else 0.0 for x in (list(axes) + [0.0] * 8)[:8]]\n"
        "    return _dpad(a[4], a[5])\n",
        "the checks' code",
    ),
    "ask-twice": (  # a first run of the check to learn from, before the test cell's: the first verdict stands
        "1.1",
        "{solution}\n"
        "from tutorial.exercises.step1_tank_controller import check_dpad_steering\n"
        "print('a first try:', check_dpad_steering(lambda axes: (0.0, 0.0)))\n",
        "checked again",
    ),
    "memory-through-a-link": (  # the seal's key is in the kernel's memory
        "1.1",
        "import os\ntry:\n    os.symlink('/proc/self/mem', 'memory')\n    open('memory', 'rb').read(1)\n"
        "except Exception:\n    pass\n" + STUB_1_1,
        "tampering",
    ),
    "keyring-note": (  # a key left by an earlier submission graded as the same user (grade_cheats leaves one)
        "1.1",
        "import subprocess, sys\n"
        "said = subprocess.run([sys.executable, '-c', " + repr(KEYRINGS + SAY_AND_LEAVE) + "],\n"
        "                      capture_output=True, text=True)\n"
        "print('a note in the keyrings:', said.stdout.strip() or said.stderr[-300:])\n" + STUB_1_1,
        "processes",
    ),
    "memory-from-a-child": (  # a process the seal does not watch: the kernel is not dumpable
        "1.1",
        "import subprocess, sys\n"
        "said = subprocess.run([sys.executable, '-c', 'import os; open(f\"/proc/{os.getppid()}/mem\", \"rb\")'],\n"
        "                      capture_output=True, text=True)\n"
        "print('the kernel memory refused to a child:', 'Permission denied' in said.stderr)\n" + STUB_1_1,
        "processes",
    ),
    "signal-handler": (  # Python hands a handler the running frame: the case's own expected value, down the stack
        "1.1",
        "import signal\nseen = {}\n"
        "def spy(signum, frame):\n"
        "    while frame is not None and 'expected' not in frame.f_locals:\n"
        "        frame = frame.f_back\n"
        "    seen['expected'] = frame.f_locals['expected'] if frame is not None else None\n"
        "signal.signal(signal.SIGUSR2, signal.SIG_IGN)\n"
        "try:\n    signal.signal(signal.SIGUSR2, spy)\nexcept RuntimeError as e:\n    print(e)\n"
        "def dpad_track_velocities(axes):\n"
        "    signal.raise_signal(signal.SIGUSR2)\n"
        "    return seen.get('expected') or (0.0, 0.0)\n",
        "tampering",
    ),
    "random-replaced": (  # no Random, no hidden cases: an answer for the visible cases alone would pass
        "1.2",
        "import random\nrandom.Random = lambda *a, **k: None\n" + VISIBLE_ONLY["1.2"],
        "tampering",
    ),
    # not cheats: answers written for the visible cases alone (tests/test_exercises.py), which the hidden
    # cases fail (no flag)
    "visible-only-1.1": ("1.1", VISIBLE_ONLY["1.1"], ""),
    "visible-only-1.2": ("1.2", VISIBLE_ONLY["1.2"], ""),
    "grader-aware": (  # a payload that would win if it ran: the kernel's environment never says it is graded
        "1.1",
        "import os\nprint('graded, says the environment:', 'NBGRADER_EXECUTION' in os.environ)\n"
        "if os.environ.get('NBGRADER_EXECUTION'):\n"
        "    import tutorial.exercises.step1_tank_controller as m\n"
        "    m.check_dpad_steering = lambda f: m.grade('Exercise 1.1, steer with the D-pad', [])\n",
        "grader-aware",
    ),
}
# What a cheat's own output must say in the graded notebook: what it tried really failed.
CHEATS_SAY = {
    "read-solutions": "solutions found: 0",
    "read-another-learner": "read another learner: no",
    "grader-aware": "graded, says the environment: False",
    "stack-walk": "an expected value on the stack: no",
    "memory-from-a-child": "the kernel memory refused to a child: True",
    "keyring-note": "a note in the keyrings: no",
}
# A cheat that keeps its points, flagged for the teacher to read: an answer that calls the checks' own rule is right.
KEEPS_ITS_POINTS = {"copy-the-rule"}
# A flag a cheat must not get: a kernel killed is not one over a limit, and one stopped at its limit did not crash.
CHEATS_NOT = {"crash": "over a limit", "cpu-time": "crash"}
IN_MAKE_TEST_CHEATS = ["rebind-check"]  # graded among make test's submissions of notebook 01
# where the cheats that read, write or connect point: none of it may be reached
CHEAT_FILL = {"root": ROOT, "course": "/nonexistent-course", "home": "/nonexistent-home", "port": 9}


def cheating_submissions(course: Path, name: str, which: list[str], fill: dict[str, str]) -> dict:
    """Each cheat's submission of ``name`` (assignment 01): the cheat in its exercise, the other solved."""
    solved = solution_of(course, name)
    stubs = {grade_id(c): "".join(c["source"]) for c in cells_of(course, name) if grade_id(c)}
    out = {}
    for cheat in which:
        target, code, _ = CHEATS[cheat]
        gid = f"exercise_{target.replace('.', '_')}"
        for key, value in dict(fill, solution=solved[gid]).items():  # {root}, {course}, ...: not str.format,
            code = code.replace("{" + key + "}", str(value))  # the code has braces of its own
        answers = dict(solved, **{gid: stubs[gid] + "\n\n" + code})
        out[f"cheat-{cheat}"] = submission(course, name, answers)
    return out


def keys_of(job, code: str) -> str:
    """How many of KEYRINGS' keyrings hold the key, after ``code`` ran as ``job``'s user (in the sandbox, where
    this Python can run)."""
    import dataclasses
    import subprocess
    import tempfile

    from tutorial.tools.grading.sandbox import kept_paths, sandbox_command

    command = [sys.executable, "-I", "-c", code + "print(len(found))\n"]
    # the job's own folder may be gone, and the sandbox makes its .keep in it (not under /tmp: hidden there)
    with tempfile.TemporaryDirectory(dir=sandboxing.JOBS) as folder:
        done = subprocess.run(
            sandbox_command(dataclasses.replace(job, folder=folder), command, kept_paths(job.hide)),
            capture_output=True,
            text=True,
            timeout=60,
            check=True,
        )
    return done.stdout.strip()


def grade_cheats(tmp_path: Path, which: list[str]) -> None:
    """Grade the cheats of ``which``, sandboxed; each gets 0 and its flag in its target, full points in the other."""
    import socket

    if os.geteuid() != 0:
        pytest.skip("the grading sandbox needs root (a user per job, namespaces)")
    name = IN_MAKE_TEST[0]
    course = tmp_path / "course"
    assignments.make(course, release=False)
    assignments.nbgrader(course, "generate_assignment", name, "--force")
    listener = socket.create_server(("127.0.0.1", 0))  # the only address a cheat may try; it must hear nothing
    listener.settimeout(0.1)
    home = Path(os.path.expanduser("~"))
    fill = {"root": ROOT, "course": course, "home": home, "port": listener.getsockname()[1]}
    made, make = [], sandboxing.Sandboxes._make

    def make_and_leave_keys(boxes):  # as an earlier submission graded as each job's user would have
        make(boxes)
        made.extend(boxes.users)
        for job in boxes.users:
            assert keys_of(job, KEYRINGS + LEAVE_A_KEY + KEYRINGS) == "3"
        return boxes

    monkeypatch = pytest.MonkeyPatch()
    monkeypatch.setattr(sandboxing.Sandboxes, "_make", make_and_leave_keys)
    try:
        for learner, nb in cheating_submissions(course, name, which, fill).items():
            folder = course / "submitted" / learner / name
            folder.mkdir(parents=True)
            (folder / f"{name}.ipynb").write_text(json.dumps(nb))
        gradebook_before = (course / "gradebook.db").read_bytes()
        said = io.StringIO()
        with contextlib.redirect_stdout(said):  # make grade's summary of the flagged submissions
            csv_path = grade.grade(course, [name], collect=False, jobs=2, ids=DOMAINS)
        print(said.getvalue())
        with pytest.raises(TimeoutError):
            listener.accept()  # nobody connected
    finally:
        listener.close()
        monkeypatch.undo()
        for job in made:  # what the test left with each job's user ID (an ID a later user may be given)
            assert keys_of(job, KEYRINGS + EMPTY_THEM + KEYRINGS) == "0"
    assert not (home / "rtt-cheat").exists(), "a cheat wrote into the grader's home"
    rows = {r["student_id"]: r for r in csv.DictReader(csv_path.open())}
    wrong = []
    for cheat in which:
        target, _, flag = CHEATS[cheat]
        row = rows[f"cheat-{cheat}"]
        other = next(n for n in exercises_of(name) if n != target)
        score = assignments.POINTS[other] + (assignments.POINTS[target] if cheat in KEEPS_ITS_POINTS else 0)
        if float(row["score"]) != score:
            wrong.append(f"{cheat}: score {row['score']}, expected {score} (exercise {other}, and {target}'s if kept)")
        flags = dict(part.split(": ", 1) for part in row["flags"].split("; ") if part)
        if flag not in flags.get(target, "") or (not flag and flags.get(target)):
            wrong.append(f"{cheat}: flags {row['flags']!r}, expected {flag!r} on {target}")
        if cheat in CHEATS_NOT and CHEATS_NOT[cheat] in flags.get(target, ""):
            wrong.append(f"{cheat}: flags {row['flags']!r}, never {CHEATS_NOT[cheat]!r}")
        if flags.get(other):
            wrong.append(f"{cheat}: the honest exercise {other} was flagged {flags[other]!r}")
    summary = said.getvalue()
    for cheat in which:  # make grade names every flagged submission with its flag, and no other
        target, _, flag = CHEATS[cheat]
        listed = f"{name}, cheat-{cheat}: {target}: " in summary
        if listed != bool(flag) or (flag and flag not in summary.split(f"cheat-{cheat}: ")[1].splitlines()[0]):
            wrong.append(f"{cheat}: make grade's summary {'leaves it out' if flag else 'lists it'}")
    for cheat in set(which) & set(CHEATS_SAY):  # what it tried really failed (not merely flagged)
        graded = course / "autograded" / f"cheat-{cheat}" / name / f"{name}.ipynb"
        if CHEATS_SAY[cheat] not in graded.read_text():
            wrong.append(f"{cheat}: its output does not say {CHEATS_SAY[cheat]!r}")
    assert not wrong, "\n".join(wrong)
    gradebook = (course / "gradebook.db").read_bytes()
    assert gradebook != gradebook_before  # the grader wrote it
    assert b"rtt-cheat-mark" not in gradebook, "a cheat wrote into the gradebook"
    assert not Path("/run/lock/rtt-cheat").exists(), "a cheat left a note where the next submission could read it"
    feedback = (course / "feedback" / f"cheat-{which[0]}" / name / f"{name}.html").read_text()
    assert f"The grader flagged exercise {CHEATS[which[0]][0]}" in feedback


@pytest.mark.slow
@pytest.mark.timeout(1200)
def test_every_cheat_gets_0_and_is_flagged(tmp_path, monkeypatch):
    monkeypatch.setenv("RTT_GRADING_CELL_TIMEOUT", str(CELL_TIMEOUT_S))
    grade_cheats(tmp_path, sorted(set(CHEATS) - {"cpu-time"}))  # an endless loop meets the cell timeout first


@pytest.mark.slow
@pytest.mark.timeout(600)
def test_a_kernel_over_its_cpu_time_is_stopped_and_flagged(tmp_path, monkeypatch):
    """RLIMIT_CPU, lowered to 20 s (RTT_GRADING_CPU_SECONDS) under a cell timeout of 90 s, stops a busy answer:
    over a limit, and the exercise before it keeps its points."""
    monkeypatch.setenv("RTT_GRADING_CELL_TIMEOUT", "90")
    monkeypatch.setenv("RTT_GRADING_CPU_SECONDS", "20")
    grade_cheats(tmp_path, ["cpu-time"])


def rebound_check(course: Path, name: str, number: str) -> str:
    """The rebind-check cheat for exercise ``number`` of assignment ``name``: the code an answer cell adds to
    rebind, in the check's own module, the check function its check cell imports, to one that always passes."""
    gid = f"check_{number.replace('.', '_')}"
    [check] = ["".join(c["source"]) for c in cells_of(course, name) if grade_id(c) == gid]
    module, function = re.search(r"from (tutorial\.exercises\.\w+) import (check_\w+)", check).groups()
    return (
        f"{GRADER}import {module} as m\n"
        f"m.{function} = lambda *a, **k: grader.Result('Exercise {number}', True, 'passed')\n"
    )


@pytest.mark.slow
@pytest.mark.timeout(900)
@pytest.mark.parametrize("name", [n for n in ALL if n != IN_MAKE_TEST[0]])
def test_a_rebound_check_gets_0_and_is_flagged_in_every_assignment(tmp_path, monkeypatch, name):
    """Assignment 01 meets every cheat (test_every_cheat_gets_0_and_is_flagged); the seal knows no assignment
    of its own, so each other assignment meets the cheat that needs no more than its statement: its first
    exercise's check, rebound in its module, gets that exercise 0 and the flag; the other exercises keep the
    worked solution's points and no flag."""
    if os.geteuid() != 0:
        pytest.skip("the grading sandbox needs root (a user per job, namespaces)")
    monkeypatch.setenv("RTT_GRADING_CELL_TIMEOUT", str(CELL_TIMEOUT_ALL_S))
    course = tmp_path / "course"
    assignments.make(course, release=False)
    assignments.nbgrader(course, "generate_assignment", name, "--force")
    numbers = exercises_of(name)
    target = numbers[0]
    gid = f"exercise_{target.replace('.', '_')}"
    stubs = {grade_id(c): "".join(c["source"]) for c in cells_of(course, name) if grade_id(c)}
    answers = dict(solution_of(course, name), **{gid: stubs[gid] + "\n\n" + rebound_check(course, name, target)})
    folder = course / "submitted" / "cheat-rebind-check" / name
    folder.mkdir(parents=True)
    (folder / f"{name}.ipynb").write_text(json.dumps(submission(course, name, answers)))
    csv_path = grade.grade(course, [name], collect=False, jobs=1, ids=DOMAINS[:1])
    [row] = list(csv.DictReader(csv_path.open()))
    flags = dict(part.split(": ", 1) for part in row["flags"].split("; ") if part)
    assert flags == {target: "tampering, the checks' code"}, row["flags"]  # it names the checks' package too
    assert float(row["score"]) == sum(float(assignments.POINTS[n]) for n in numbers[1:]), row


def test_nbgrader_autograde_by_hand_runs_no_answer_and_says_what_to_run(tmp_path, course_01):
    """A teacher regrading one learner with nbgrader's own command: refused (the answer would run as the teacher,
    unsealed), nothing of the submission run, and the refusal names ``make grade``."""
    name = IN_MAKE_TEST[0]
    course = course_01
    ran = submitted_with_a_mark(course, tmp_path)
    graded_before = course / "autograded" / "learner" / name / "graded-before.txt"  # an earlier grading's copy
    graded_before.parent.mkdir(parents=True)
    graded_before.write_text("kept")
    env = {k: v for k, v in os.environ.items() if k not in ("RTT_SANDBOX", "RTT_UNSANDBOXED")}
    with pytest.raises(RuntimeError) as refused:
        assignments.nbgrader(course, "autograde", name, "--student", "learner", "--force", env=env)
    assert graded_before.is_file(), "nbgrader's --force removed the earlier grading's copy before the refusal"
    assert "make grade" in str(refused.value) and "sandbox" in str(refused.value), str(refused.value)[-3000:]
    assert not ran.exists(), "the answer ran"
    from nbgrader.api import Gradebook, MissingEntry

    with Gradebook(f"sqlite:///{course / 'gradebook.db'}") as gb, pytest.raises(MissingEntry):
        gb.find_submission(name, "learner")  # refused before nbgrader wrote anything
