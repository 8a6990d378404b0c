"""The judge: every exercise's check runs in a process of its own, and only data crosses.

A real judge process (``python -I -m tutorial.tools.grading.judge``) on one end
of a socket pair, the kernel's side (:class:`tutorial.tools.grading.judged.Judge`)
in this process on the other, as while grading:

- a worked solution, and every wrong answer of a judged exercise, get from
  the judge the very line the check gives in-process with the same seed
  (so the judge's checks fail every mistake the tests prove the checks fail);
- each check runs once (asked again: refused, its first verdict stands,
  noted); an interrupted answer leaves no verdict and the next check runs;
- a kernel that sends junk, an unknown check, a value the wire does not
  build, or a float that compares as it likes gets a failing verdict and a
  tampering note, and the judge keeps serving;
- the wire builds only what it lists (:mod:`tutorial.tools.grading.wire`);
- the grader takes a judged exercise's verdict from the judge alone.
"""

from __future__ import annotations

import json
import math
import socket
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from exercise_rules import HIDDEN_MISTAKES
from test_exercises import EXERCISES, MISTAKES, exercise, first_three_of_each, grade, hidden_cases_on, mistake_id

from tutorial.tools.grading import judge, judged, wire

from conftest import ROOT

sys.path.insert(0, str(ROOT / "course"))
import sandboxing  # noqa: E402 - course/ is not a package

SEED = "test"  # the seed tests/test_exercises.py's grading_seed gives the in-process checks
NUMBERS = list(EXERCISES)  # the judged exercises: every one


class JudgeProcess:
    """A judge process and the kernel's end of its socket (``kernel``), with its verdict file."""

    def __init__(self, folder: Path, seed: str = SEED):
        self.verdicts = folder / "verdicts.txt"
        ours, theirs = socket.socketpair()
        self.process = subprocess.Popen(
            [sys.executable, "-I", "-m", "tutorial.tools.grading.judge", str(theirs.fileno()), str(self.verdicts)],
            pass_fds=(theirs.fileno(),),
            stdin=subprocess.PIPE,
            text=True,
        )
        theirs.close()
        self.process.stdin.write(seed + "\n")
        self.process.stdin.close()
        self.sock = ours
        self.kernel = judged.Judge(ours)

    def lines(self) -> list[list[str]]:
        """The verdict file's lines, each split at tabs (the last field of each the judge's signature)."""
        return [line.split("\t") for line in self.verdicts.read_text().splitlines()] if self.verdicts.exists() else []

    def close(self) -> int:
        """The kernel's end closed: the judge ends (its exit status)."""
        self.kernel._reader.close()
        self.sock.close()
        return self.process.wait(timeout=30)


@pytest.fixture
def judge_process(tmp_path):
    made = JudgeProcess(tmp_path)
    yield made
    if made.process.poll() is None:
        assert made.close() == 0


def answer_of(number: str, source: str):
    """The function ``source`` (after the stub) defines for exercise ``number``, as a notebook would."""
    ex = exercise(number)
    names: dict = {}

    def keep(answer):  # the check is not run here: the judge runs it
        names["answer"] = answer

    import importlib

    module = importlib.import_module(f"tutorial.exercises.{ex['checks']}")
    real = getattr(module, ex["check"])
    setattr(module, ex["check"], keep)
    try:
        grade(ex, ex["stub"], source)
    except TypeError:
        pass  # grade() called str() on what keep returned
    finally:
        setattr(module, ex["check"], real)
    return names["answer"]


def test_judged_is_the_judge_modules_table_and_names_every_exercise():
    table = {(module, name) for module, names in judge.JUDGED.items() for name in names}
    exercises = {(f"tutorial.exercises.{exercise(n)['checks']}", exercise(n)["check"]) for n in NUMBERS}
    assert table == exercises and judge.JUDGED_NAMES == {name for _, name in table}


# make test's: a function of lists, one raising the KeyError its statement asks for, and a class run in a simulation
KEPT = {"1.1", "9.1", "2.2"}


@pytest.mark.parametrize(
    "number", [n if n in KEPT else pytest.param(n, marks=pytest.mark.more) for n in sorted(NUMBERS)]
)
def test_the_judge_gives_the_worked_solution_the_line_the_kernel_would(ros, monkeypatch, judge_process, number):
    ex = exercise(number)
    hidden_cases_on(monkeypatch, ex["checks"], seed=SEED)
    in_kernel = grade(ex, ex["stub"], ex["solution"])
    got = judge_process.kernel.run(ex["check"], answer_of(number, ex["solution"]))
    assert got.passed and "hidden ones)" in got.message, str(got)
    assert str(got) == str(in_kernel)
    lines = judge_process.lines()
    assert lines[0][:3] == ["judged", "begin", number] and lines[1][:5] == ["judged", "verdict", number, "1", "1"]


JUDGED_MISTAKES = [m for m in MISTAKES if m[0] in NUMBERS] + [m for m in HIDDEN_MISTAKES if m[0] in NUMBERS]
IN_MAKE_TEST = {  # a function's first wrong answer, and a class's
    mistake_id(m) for n in ("1.1", "1.2") for m in first_three_of_each([m for m in JUDGED_MISTAKES if m[0] == n])[:1]
}


@pytest.mark.parametrize(
    "number, right, wrong, caught_by",
    [m if mistake_id(m) in IN_MAKE_TEST else pytest.param(*m, marks=pytest.mark.more) for m in JUDGED_MISTAKES],
    ids=[mistake_id(m) for m in JUDGED_MISTAKES],
)
def test_the_judge_fails_each_wrong_answer_as_the_kernel_would(
    ros, monkeypatch, tmp_path, number, right, wrong, caught_by
):
    ex = exercise(number)
    source = ex["solution"].replace(right, wrong)
    hidden_cases_on(monkeypatch, ex["checks"], seed=SEED)
    in_kernel = grade(ex, ex["stub"], source)
    process = JudgeProcess(tmp_path)
    try:
        got = process.kernel.run(ex["check"], answer_of(number, source))
    finally:
        assert process.close() == 0
    assert not got.passed and str(got) == str(in_kernel)
    assert process.lines()[-1][:4] == ["judged", "verdict", number, "0"]


def test_a_check_runs_once_and_its_first_verdict_stands(judge_process):
    first = judge_process.kernel.run("check_dpad_steering", lambda axes: (0.0, 0.0))  # a try to learn from
    right = answer_of("1.1", exercise("1.1")["solution"])
    again = judge_process.kernel.run("check_dpad_steering", right)
    assert not first.passed and not again.passed
    assert "its first verdict stands" in again.message
    verdicts = [line for line in judge_process.lines() if line[1] == "verdict"]
    assert [v[3] for v in verdicts] == ["0"]
    assert ["judged", "note", "checked again"] == judge_process.lines()[-1][:3]


def test_an_interrupted_answer_leaves_no_verdict_and_the_next_check_runs(judge_process):
    def interrupted(axes):
        raise KeyboardInterrupt  # what the cell's timeout does to an answer that never returns

    with pytest.raises(KeyboardInterrupt):
        judge_process.kernel.run("check_dpad_steering", interrupted)
    after = judge_process.kernel.run("check_after", answer_of("11.1", exercise("11.1")["solution"]))
    assert after.passed, str(after)
    lines = judge_process.lines()
    assert ["judged", "begin", "1.1"] in [line[:3] for line in lines]
    assert not any(line[1:3] == ["verdict", "1.1"] for line in lines)
    assert any(line[1:5] == ["verdict", "11.1", "1", "1"] for line in lines)


def raw_kernel(process: JudgeProcess, *messages: bytes, run: str = "raw") -> list[dict]:
    """Send ``messages`` as the kernel's raw bytes; the judge's replies until it asks for a call or gives a result
    for ``run`` (an id the kernel's own side never gives)."""
    replies = []
    reader = process.kernel._reader
    for message in messages:
        process.sock.sendall(message)
    while True:
        reply = json.loads(reader.readline())
        replies.append(reply)
        if ("result" in reply or "call" in reply) and reply.get("id") == run:
            return replies


def test_a_kernel_that_sends_junk_or_asks_for_no_check_is_noted_and_the_judge_goes_on(judge_process):
    replies = raw_kernel(judge_process, b"not json\n", b'{"check": ["x"]}\n', b'{"check": "os.system", "id": "raw"}\n')
    assert replies[-1]["result"]["passed"] is False
    notes = [line for line in judge_process.lines() if line[1] == "note"]
    assert [n[2] for n in notes] == ["tampering"] * 3
    right = answer_of("1.1", exercise("1.1")["solution"])
    assert judge_process.kernel.run("check_dpad_steering", right).passed


@pytest.mark.parametrize(
    "returned, said",
    [
        ({"object": ["os:system", {}]}, "no such class on the wire"),
        ({"message": ["std_msgs/msg/String", {"data": "x"}]}, "no such message on the wire"),
        ({"raw": ["|O", [2], "AAAAAAAAAAAAAAAAAAAAAA=="]}, "only booleans and numbers cross"),
        ({"opaque": ["Anything", "0.0", True]}, "compares as it likes"),
        ({"file": ["x.mcap", ""]}, "a file goes only to the kernel"),
    ],
    ids=[
        "a class not listed",
        "a message not listed",
        "an array of objects",
        "a float that says it is equal",
        "a file",
    ],
)
def test_a_value_the_wire_does_not_build_fails_the_case_and_is_noted(judge_process, returned, said):
    raw_kernel(judge_process, b'{"check": "check_dpad_steering", "id": "raw"}\n')
    replies = raw_kernel(judge_process, wire.dumps({"id": "raw", "return": {"tuple": [returned, 0.0]}}))
    assert replies[-1]["result"]["passed"] is False
    notes = [line for line in judge_process.lines() if line[1] == "note"]
    assert notes and notes[0][2] == "tampering" and said in notes[0][3], judge_process.lines()
    verdict = next(line for line in judge_process.lines() if line[1] == "verdict")
    assert verdict[3:5] == ["0", "0"]  # failed, and not intact


def test_an_answers_own_float_class_arrives_as_a_value_equal_to_nothing(judge_process):
    class Anything(float):
        def __eq__(self, other):
            return True

        __hash__ = float.__hash__

    got = judge_process.kernel.run("check_dpad_steering", lambda axes: (Anything(0), Anything(0)))
    assert not got.passed and "returned (0.0, 0.0)" in got.message
    assert any(line[1:3] == ["note", "tampering"] and "a Anything" in line[3] for line in judge_process.lines())


def test_an_exception_arrives_by_its_name_and_a_keyerror_as_itself(ros, judge_process):
    def lookup(transforms, frame):
        raise KeyError(frame)

    got = judge_process.kernel.run("check_lookup", lookup)  # a KeyError for a frame that is not there passes
    assert not got.passed and "raised KeyError" in got.message and "expected a KeyError" not in got.message


WIRED = [
    None,
    True,
    3,
    2.5,
    math.inf,
    "text",
    [1, (2.0, "x")],
    {"a": [1.0]},
    np.arange(6.0).reshape(2, 3),
    np.float32(1.5),
    np.int64(7),
]


@pytest.mark.parametrize("value", WIRED, ids=[type(v).__name__ for v in WIRED])
def test_the_wire_builds_back_what_it_carries(value):
    got = wire.decode(wire.loads(wire.dumps({"v": wire.encode(value)}))["v"])
    assert type(got) is type(value)
    if isinstance(value, np.ndarray):
        assert got.dtype == value.dtype and (got == value).all()
    else:
        assert got == value


def test_the_wire_carries_the_checks_data_classes_messages_parameters_and_qos(ros):
    from rcl_interfaces.msg import SetParametersResult
    from rclpy.parameter import Parameter
    from rclpy.qos import QoSProfile, ReliabilityPolicy

    from tutorial.interfaces.tf import Transform

    values = [
        Transform((1, 2), "world", "CHASSIS", (1.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)),
        SetParametersResult(successful=False, reason="no"),
        Parameter("rate", Parameter.Type.DOUBLE, 50.0),
        QoSProfile(depth=3, reliability=ReliabilityPolicy.BEST_EFFORT),
    ]
    for value in values:
        got = wire.decode(wire.loads(wire.dumps({"v": wire.encode(value)}))["v"])
        assert type(got) is type(value)
    assert got.depth == 3 and got.reliability == ReliabilityPolicy.BEST_EFFORT


@pytest.mark.parametrize(
    "line",
    [b'{"v": NaN}', b"[1]", b'{"v": ' * 2000 + b"1" + b"}" * 2000, b" " * (wire.MAX_LINE + 1)],
    ids=["an untagged NaN", "not an object", "nested too deep", "too long"],
)
def test_the_wire_refuses_a_line_it_does_not_read(line):
    with pytest.raises(wire.WireError):
        wire.loads(line)


def by_judge(body: str, key: bytes = b"") -> str:
    """A line of the judge's (``judged`` and ``body``), signed with ``key``, as a judge given that key writes it."""
    return judge.signed(key, "judged\t" + body) + "\n"


def cell(gid, source, grade=False):
    """An autograded notebook's code cell, as nbgrader leaves it."""
    meta = {"nbgrader": {"grade_id": gid, "grade": grade, "solution": not grade}}
    return {"cell_type": "code", "metadata": meta, "source": source, "outputs": []}


def two_exercises(check_1_2: str) -> list[dict]:
    """Assignment 01's answer and check cells as nbgrader leaves them, 1.2's test cell calling ``check_1_2``."""
    return [
        cell("exercise_1_1", "def dpad_track_velocities(axes): ..."),
        cell("check_1_1", "check_dpad_steering(dpad_track_velocities).require()", True),
        cell("exercise_1_2", "class ShotCountingTankController: ..."),
        cell("check_1_2", f"{check_1_2}(ShotCountingTankController).require()", True),
    ]


@pytest.mark.parametrize(
    "answer, flagged",
    [
        ("from tutorial.exercises.step1_tank_controller import _dpad\n", True),
        ("import tutorial.exercises.step1_tank_controller as m\n", True),
        ("from tutorial.exercises.parameters_and_services import TrackSwitch  # .enabled, .lock\n", False),
        ("import math\n", False),
        ("import importlib\nm = importlib.import_module('tutorial.exercises.grader')\n", True),
        ("print(open('/work/tutorial/exercises/grader.py').read())\n", True),
        ("# Like the other exercises of this notebook, the D-pad\n", False),
        ("print('all exercises done')\n", False),
    ],
    ids=[
        "a private rule imported",
        "the module imported",
        "a public name, as 10.2's stub",
        "no checks",
        "imported by its name in a string",
        "its file read",
        "the word in a comment",
        "the word in prose",
    ],
)
def test_an_answer_naming_the_checks_package_is_flagged_unless_it_imports_public_names(tmp_path, answer, flagged):
    graded = tmp_path / "graded.ipynb"
    source = answer + "def dpad_track_velocities(axes): ..."
    checked = "check_dpad_steering(dpad_track_velocities).require()"
    graded.write_text(json.dumps({"cells": [cell("exercise_1_1", source), cell("check_1_1", checked, True)]}))
    verdicts = tmp_path / "verdicts.txt"
    verdicts.write_text(by_judge("begin\t1.1") + by_judge("verdict\t1.1\t1\t1\t"))
    assert sandboxing.judge(graded, verdicts, "")["1.1"] == (True, ["the checks' code"] if flagged else [])


def test_the_grader_takes_a_judged_exercises_verdict_from_the_judge_alone(tmp_path):
    # 1.2: a check the judge does not run (none of the course's): its verdict is the sealed kernel's
    notebook = {"cells": two_exercises("check_in_the_kernel")}
    graded = tmp_path / "graded.ipynb"
    graded.write_text(json.dumps(notebook))
    verdicts = tmp_path / "verdicts.txt"
    # the seal's lines (signed, so from the kernel) pass 1.1 too: the kernel's word for a judged check counts not
    verdicts.write_text(
        "begin\t1.1\nverdict\t1.1\t1\t1\t\n" + by_judge("begin\t1.1") + by_judge("verdict\t1.1\t0\t1\t")
    )
    verdicts.write_text(verdicts.read_text() + "begin\t1.2\nverdict\t1.2\t1\t1\t\n")
    judged_ = sandboxing.judge(graded, verdicts, "")
    assert judged_["1.1"] == (False, ["tampering"]) and judged_["1.2"] == (True, [])
    verdicts.write_text(
        by_judge("begin\t1.1") + by_judge("verdict\t1.1\t1\t1\t") + "begin\t1.2\nverdict\t1.2\t1\t1\t\n"
    )
    assert sandboxing.judge(graded, verdicts, "") == {"1.1": (True, []), "1.2": (True, [])}
    verdicts.write_text("begin\t1.2\n" + by_judge("verdict\t1.2\t1\t1\t"))  # the judge's word for a sealed check: none
    assert sandboxing.judge(graded, verdicts, "")["1.2"][0] is False


def test_a_file_a_check_made_crosses_into_a_folder_of_the_kernels_own_and_is_gone_after_the_call(tmp_path):
    bag = tmp_path / "check.mcap"
    bag.write_bytes(b"\x89MCAP0\r\n bytes")
    seen = {}

    def answer(path):
        seen["path"], seen["bytes"] = path, path.read_bytes()
        return []

    reply = judged._called(answer, wire.loads(wire.dumps({"call": [wire.encode(bag)]}))["call"])
    assert reply == {"return": []}
    assert seen["bytes"] == bag.read_bytes() and seen["path"] != bag and not seen["path"].exists()
    with pytest.raises(wire.WireError):
        wire.decode({"file": ["../up", ""]}, folder=str(tmp_path))


def test_a_signed_line_that_another_reader_would_split_is_never_the_judges(tmp_path):
    """The seal's pipe reader refuses a signed body with a line break of any kind (U+2028 among them) or naming
    the judge; the grader splits the file at "\\n" alone."""
    import hmac
    import os
    import threading
    import types

    from tutorial.tools.grading.sandbox import MAX_REFUSED_LINES, SandboxedKernelManager

    key = b"k" * 32
    read, write = os.pipe()
    verdicts = tmp_path / "verdicts.txt"

    def signed(body: str) -> bytes:
        return (body + "\t" + hmac.new(key, body.encode(), "sha256").hexdigest() + "\n").encode()

    forged = "\u2028judged\tverdict\t1.1\t1\t1"
    reader = types.SimpleNamespace(_key=key, _verdict_read=read, _job=types.SimpleNamespace(verdicts=str(verdicts)))
    thread = threading.Thread(target=SandboxedKernelManager._read_verdicts, args=(reader,))  # as the grader's
    thread.start()
    with os.fdopen(write, "wb") as pipe:  # a line of 100 kB, more than the pipe holds
        pipe.write(signed("begin\t1.2") + signed(forged) + signed("note\tx\tjudged\t1.1") + b"y" * 100_000)
        pipe.write(b"\n" + b"junk\n" * 100)
    thread.join(timeout=30)
    assert not thread.is_alive()
    lines = verdicts.read_text().split("\n")
    assert lines[0] == "begin\t1.2" and "\u2028" not in verdicts.read_text()
    assert lines[1:-1] == ["note\ttampering\tan unsigned line on the seal's pipe\t"] * MAX_REFUSED_LINES
    notebook = {"cells": [cell("exercise_1_1", "..."), cell("check_1_1", "check_dpad_steering(f).require()", True)]}
    graded = tmp_path / "graded.ipynb"
    graded.write_text(json.dumps(notebook))
    verdicts.write_text(by_judge("begin\t1.1") + by_judge("verdict\t1.1\t0\t1\t") + forged + "\n")  # had it got through
    assert sandboxing.judge(graded, verdicts, "")["1.1"][0] is False


def test_the_kernel_holds_a_seed_from_which_the_judges_draws_cannot_be_had():
    from tutorial.tools.grading.sandbox import sealed_seed

    assert sealed_seed("0123456789abcdef") == sealed_seed("0123456789abcdef") != "0123456789abcdef"
    assert len(sealed_seed("0123456789abcdef")) == 16 and sealed_seed("") == ""


def test_the_judges_notes_are_bounded_and_an_odd_character_does_not_stop_it(judge_process):
    judge_process.sock.sendall(b"x\n" * 500)  # junk between checks: notes counted, not written without end
    raw_kernel(judge_process, b'{"check": "check_dpad_steering", "id": "raw"}\n')
    replies = raw_kernel(judge_process, b'{"id": "raw", "return": {"opaque": ["X\\ud800", "r", true]}}\n')
    assert replies[-1]["result"]["passed"] is False
    lines = judge_process.lines()
    assert sum(line[1] == "note" for line in lines) <= judge.MAX_NOTES_IN_ALL
    assert any(line[1:3] == ["verdict", "1.1"] for line in lines)  # written, the lone surrogate replaced
    right = answer_of("11.1", exercise("11.1")["solution"])
    assert judge_process.kernel.run("check_after", right).passed  # the judge goes on


def test_a_judge_line_cut_short_and_finished_by_the_kernel_or_signed_otherwise_is_no_verdict(tmp_path):
    """The seal's reader appends the kernel's lines to the judge's file: a judge line the disk cut short, then
    finished by a line the kernel signed, carries no signature of the judge's key."""
    key = bytes(range(32))
    graded = tmp_path / "graded.ipynb"
    checked = "check_dpad_steering(dpad_track_velocities).require()"
    graded.write_text(json.dumps({"cells": [cell("exercise_1_1", "..."), cell("check_1_1", checked, True)]}))
    verdicts = tmp_path / "verdicts.txt"
    cut = by_judge("verdict\t1.1\t0\t1\t", key)[: len("judged\tverdict\t1.1\t")]
    verdicts.write_text(by_judge("begin\t1.1", key) + cut + "1\t1\t\n")
    assert sandboxing.judge(graded, verdicts, "", judge_key=key.hex())["1.1"] == (False, ["tampering"])
    verdicts.write_text(by_judge("begin\t1.1", b"other") + by_judge("verdict\t1.1\t1\t1\t", b"other"))
    assert sandboxing.judge(graded, verdicts, "", judge_key=key.hex())["1.1"][0] is False
    verdicts.write_text(by_judge("begin\t1.1", key) + by_judge("verdict\t1.1\t1\t1\t", key) + "note\n")
    assert sandboxing.judge(graded, verdicts, "", judge_key=key.hex())["1.1"] == (True, [])  # a bare note: nothing


SEALED_KERNEL = """
import socket, subprocess, sys
from tutorial.tools.grading import judged, seal
MODULES = ["tutorial.exercises.step1_tank_controller"]
ours, theirs = socket.socketpair()
judge = subprocess.Popen(
    [sys.executable, "-I", "-m", "tutorial.tools.grading.judge", str(theirs.fileno()), {verdicts!r}, *MODULES],
    pass_fds=(theirs.fileno(),), stdin=subprocess.PIPE, text=True,
)
theirs.close()
judge.stdin.write("seed\\n" + "00" * 32 + "\\n")
judge.stdin.close()
judged.install(ours.detach(), MODULES)
seal.install(b"k" * 32, 1, ["check_shot_counter(ShotCountingTankController).require()"], checks=MODULES, seed="x")
from tutorial.app.reference.tank_controller import RttTankController
from tutorial.exercises.step1_tank_controller import check_shot_counter
from tutorial.interfaces import joy
{answer}
{before}
print(check_shot_counter(ShotCountingTankController), file=sys.stderr)
"""
REPLACE_THE_EXPERIMENTS = """
import tutorial.exercises.grader as grader
import tutorial.exercises.step1_tank_controller as m
said = {"_shots_counted": lambda cls, presses: m._shots(presses),
        "_input_after_one_joy": lambda cls, buttons, axes: (1, axes),
        "_summary_after_one_joy": lambda cls, buttons: {"joy_received": 1},
        "_state_touched": lambda cls, presses: ([], [])}
for name, fake in said.items():
    grader.EXPERIMENTS[f"{m.__name__}:{name}"] = fake
"""


# Code an answer runs before its test cell that leaves what the experiments report right, but changes the kernel's
# side of the judge (each is what a cheat would wrap); the seal notes it for the check that runs next.
JUDGES_END_WRAPPED = """
judge = next(c.cell_contents for c in check_shot_counter.__closure__ if type(c.cell_contents).__name__ == "Judge")
judge._send = judge._send  # an attribute of the object's own now, in front of the method
"""
PARTIAL_WRAPPED = """
import functools
real = functools.partial
functools.partial = lambda *a, **k: real(*a, **k)
"""


@pytest.mark.parametrize(
    "answer, before, noted",
    [
        ("solution", "", None),
        ("stub", REPLACE_THE_EXPERIMENTS, "the experiment tutorial.exercises.step1_tank_controller:_shots_counted was"),
        pytest.param(
            "solution", JUDGES_END_WRAPPED, "the kernel's end of the judge was changed", marks=pytest.mark.more
        ),
        pytest.param("solution", PARTIAL_WRAPPED, "functools.partial was replaced", marks=pytest.mark.more),
    ],
    ids=["honest", "experiments replaced", "the judge's end wrapped", "functools.partial wrapped"],
)
def test_a_class_checks_experiments_run_in_the_kernel_and_replacing_them_is_tampering(tmp_path, answer, before, noted):
    """The judge has the kernel run 1.2's experiments on the learner's class; the seal compares what they use (their
    module's names, the experiments by name, the standard modules the kernel's side of the judge calls, and that
    side's own object) with its snapshot as the judged check begins and ends: an answer that replaced one passes the
    judge, and is noted as tampering for that check (the grader then gives it no points)."""
    from test_seal import sealed, signed_lines

    ex = exercise("1.2")
    code = ex[answer].replace(ex["check"], "")  # the test cell's call is below
    done = sealed(SEALED_KERNEL.format(verdicts=str(tmp_path / "verdicts.txt"), answer=code, before=before))
    assert "passed (" in done.stderr, done.stderr  # the judge's line: the experiments said what the rule says
    # (its temporary folders, outside the sandbox's /tmp here, are noted "outside"; no flag of this test's)
    notes = [line for line in signed_lines(done.stdout) if line[0] == "note" and line[1] == "tampering"]
    if noted:
        assert notes and notes[0][3] == "check_shot_counter" and noted in notes[0][2], notes
    else:
        assert notes == []


def test_a_standard_library_class_is_not_taken_for_an_answers_own():
    """An honest summary may hold a deque or a namespace: it crosses as a value equal to nothing, never flagged."""
    import collections
    import types

    for value in (collections.deque([1]), collections.OrderedDict(a=1), types.SimpleNamespace(a=1)):
        kind, _, own_eq = wire.encode(value)["opaque"]
        assert not own_eq, kind
    assert wire.encode(type("Mine", (), {"__eq__": lambda self, other: True})())["opaque"][2]


STILL_HEADING = """
from geometry_msgs.msg import PoseStamped
from tutorial.core.controller import SimpleController
from tutorial.core.period import PeriodAccumulator
from tutorial.interfaces.joint_state import joint_state_qos
from tutorial.interfaces.timing import stamp_parts


class RttPosePublisher(SimpleController):  # publishes honestly, and holds the tank's heading still
    PARAMETERS = {"rate": (float, 10.0, "publish rate, Hz of simulated time")}

    def configure(self, config):
        self.node, self.rate = config.node, config.parameters["rate"]
        self.publisher = config.node.create_publisher(PoseStamped, f"/{config.body_name}/pose", joint_state_qos())
        return True

    def unconfigure(self):
        self.node.destroy_publisher(self.publisher)

    def initialize(self, io):
        self.io, self.accumulator = io, PeriodAccumulator(io.time_step, self.rate)
        joint = io.body.model.body_jntadr[io.body.root_id]
        self.q, self.v = int(io.body.model.jnt_qposadr[joint]), int(io.body.model.jnt_dofadr[joint])
        return True

    def control(self):
        self.io.data.qpos[self.q + 3 : self.q + 7] = [1.0, 0.0, 0.0, 0.0]
        self.io.data.qvel[self.v + 3 : self.v + 6] = 0.0
        if self.accumulator.tick():
            msg = PoseStamped()
            msg.header.frame_id = "world"
            msg.header.stamp.sec, msg.header.stamp.nanosec = stamp_parts(self.io.current_time)
            (x, y, z), (w, qx, qy, qz) = self.io.body.root_pose()
            msg.pose.position.x, msg.pose.position.y, msg.pose.position.z = float(x), float(y), float(z)
            o = msg.pose.orientation
            o.x, o.y, o.z, o.w = float(qx), float(qy), float(qz), float(w)
            self.publisher.publish(msg)
        return True
"""


@pytest.mark.more
def test_a_check_that_raises_outside_its_cases_fails_the_exercise_and_the_judge_goes_on(ros, judge_process):
    """2.2's check raises when its own drive did not turn the tank (a class that held the heading still): the
    exercise fails with the check's words, and the judge still serves the next check."""
    import tutorial.exercises.step2_joint_state_publisher  # noqa: F401 - its experiments, as install imports them

    names: dict = {}
    exec(STILL_HEADING, names)
    got = judge_process.kernel.run("check_pose_publisher", names["RttPosePublisher"])
    assert not got.passed and "the check could not judge this answer (RuntimeError" in got.message, str(got)
    assert judge_process.lines()[-1][:4] == ["judged", "verdict", "2.2", "0"]
    again = judge_process.kernel.run("check_dpad_steering", lambda axes: (0.0, 0.0))
    assert not again.passed and "Exercise 1.1" in str(again)  # judged, not "the judge is gone"


def test_a_note_of_the_seal_counts_for_the_exercise_whose_cell_made_it_and_is_never_lost(tmp_path):
    """The grader marks each cell's start on the seal's pipe (``SandboxedExecute``): a note made in an exercise's
    answer cell is that exercise's, also when its check never began (rebound in the answer) or when it is the
    last exercise; a note of no marked cell goes to the next exercise that begins, else to the last one."""
    setup = {"cell_type": "code", "metadata": {}, "source": "import math", "outputs": []}
    notebook = {"cells": [setup, *two_exercises("check_shot_counter")]}
    graded = tmp_path / "graded.ipynb"
    graded.write_text(json.dumps(notebook))
    verdicts = tmp_path / "verdicts.txt"
    outside = "note\toutside\topened /course/grade.py\t\n"
    passes_1_2 = by_judge("begin\t1.2") + by_judge("verdict\t1.2\t1\t1\t")
    # 1.1's answer reads a file and rebinds its check (no begin of 1.1); 1.2 is graded
    verdicts.write_text("cell\t0\ncell\t1\n" + outside + "cell\t2\ncell\t3\ncell\t4\n" + passes_1_2)
    flags = sandboxing.judge(graded, verdicts, "")
    assert "outside its folder" in flags["1.1"][1] and flags["1.2"] == (True, []), flags
    # the last exercise's answer reads a file and its check is rebound: nothing begins after it
    verdicts.write_text("cell\t0\ncell\t1\ncell\t2\n" + "cell\t3\n" + outside + "cell\t4\n")
    flags = sandboxing.judge(graded, verdicts, "")
    assert "outside its folder" in flags["1.2"][1] and "outside its folder" not in flags["1.1"][1], flags
    # a note made before any exercise's cell: the next exercise to begin's; with none after it, the last one's
    verdicts.write_text("cell\t0\n" + outside + "cell\t3\n" + passes_1_2)
    assert sandboxing.judge(graded, verdicts, "")["1.2"] == (True, ["outside its folder"])
    verdicts.write_text(outside)
    assert "outside its folder" in sandboxing.judge(graded, verdicts, "")["1.2"][1]
    # a mark in a line the judge signed is not the grader's: it moves no note
    verdicts.write_text("cell\t1\n" + by_judge("cell\t3") + outside)
    assert "outside its folder" in sandboxing.judge(graded, verdicts, "")["1.1"][1]


def test_a_graded_kernel_sees_the_teachers_folders_empty_in_this_clone_and_in_its_librarys(tmp_path, monkeypatch):
    """A teacher's environment may come from another clone: its notebooks (the worked solutions) are hidden too."""
    monkeypatch.setenv("RTT_NBGRADER_EXCHANGE", str(tmp_path / "exchange"))
    hidden = sandboxing.hidden_folders(tmp_path / "course", library=tmp_path / "other-clone")
    for folder in ("notebooks", "course", "book", ".git"):
        assert str(tmp_path / "other-clone" / folder) in hidden and str(ROOT / folder) in hidden
    assert {str(tmp_path / "course"), str(tmp_path / "exchange"), "/home", "/root", "/srv"} <= set(hidden)
