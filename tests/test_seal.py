"""The grading kernel's seal (tutorial/exercises/seal.py), in a process of its own (a sealed process stays sealed).

A genuine check signs a verdict that passes; the same check after the grader
was patched, or a Result made by hand, does not; a patched function's code is
refused; the signature holds only with the key.  The sandbox around it
(users, namespaces, limits) is tested by grading: tests/test_grading.py.
"""

from __future__ import annotations

import hashlib
import hmac
import os
import subprocess
import sys
import textwrap

import pytest

pytestmark = pytest.mark.cross_process

KEY = b"k" * 32
SCRIPT = textwrap.dedent(
    """
    import os, sys
    from tutorial.exercises import seal
    seal.install(b"k" * 32, 1, ["check_dpad_steering(dpad_track_velocities).require()"], seed="learner-seed")
    from tutorial.exercises.step1_tank_controller import check_dpad_steering
    from tutorial.interfaces import joy
    import tutorial.exercises.grader as grader

    def cell(text):  # as IPython runs a test cell's last line, from a file of the kernel's own
        exec(compile(text, "/tmp/ipykernel_0/cell.py", "single"), globals())

    def dpad_track_velocities(axes):
        forward, turn = joy.axis(axes, joy.DPAD_V), 0.5 * joy.axis(axes, joy.DPAD_H)
        return forward - turn, forward + turn

    cell("check_dpad_steering(dpad_track_velocities).require()")          # 1: genuine, passes
    cell("grader.Result('Exercise 1.1, steer', True, 'ok').require()")     # 2: a Result made by hand
    real = grader.same_numbers
    grader.same_numbers = lambda *a, **k: True
    cell("check_dpad_steering(dpad_track_velocities).require()")          # 3: the grader patched
    grader.same_numbers = real
    try:
        grader.grade.__code__ = (lambda e, c: None).__code__                  # 4: refused
    except RuntimeError as e:
        print("refused:", e, file=sys.stderr)
    cell("check_dpad_steering(dpad_track_velocities).require()")          # 5: put back: passes again
    print("seed outside a check:", grader.hidden_random("1.1"), file=sys.stderr)
    TABLE = {(0, 0): (0.0, 0.0), (0, 1): (1.0, 1.0), (0, -1): (-1.0, -1.0), (1, 0): (-0.5, 0.5), (-1, 0): (0.5, -0.5),
             (1, 1): (0.5, 1.5), (-1, -1): (-0.5, -1.5), (1, -1): (-1.5, -0.5)}

    def dpad_track_velocities(axes):  # written for the visible cases alone: a table of them
        if len(axes) < 6 or axes[0] != 0.0 or axes[5] != axes[5]:
            return 0.0, 0.0
        return TABLE.get((axes[4], axes[5]), (0.0, 0.0))

    try:
        cell("check_dpad_steering(dpad_track_velocities).require()")      # 6: passes the visible, not the hidden
    except AssertionError as e:
        print("visible only:", e, file=sys.stderr)
    """
)


def signed_lines(out: str) -> list[list[str]]:
    lines = []
    for line in out.splitlines():
        body, _, mac = line.rpartition("\t")
        if body.split("\t")[0] in ("begin", "verdict", "note"):
            assert hmac.compare_digest(mac, hmac.new(KEY, body.encode(), hashlib.sha256).hexdigest()), line
            lines.append(body.split("\t"))
    return lines


def sealed(script: str) -> subprocess.CompletedProcess:
    """``script`` run in a Python of its own (it seals itself), on this machine's ROS graph; it must succeed."""
    env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120, env=env)
    assert done.returncode == 0, done.stderr
    return done


def test_the_seal_signs_only_the_teachers_untouched_check():
    done = sealed(SCRIPT)
    lines = signed_lines(done.stdout)
    verdicts = [line for line in lines if line[0] == "verdict"]
    assert [v[1:4] for v in verdicts] == [["1.1", "1", "1"], ["1.1", "1", "0"], ["1.1", "1", "1"], ["1.1", "0", "1"]]
    assert "same_numbers was replaced" in verdicts[1][4]
    notes = [line for line in lines if line[0] == "note"]
    assert notes[0][1] == "tampering" and notes[0][3] == "1.1", notes  # the Result made by hand, named
    assert any(n[1] == "refused" and "grade.__code__" in n[2] for n in notes), notes
    assert "refused: the grader's sandbox refused: changing grade.__code__" in done.stderr
    assert "passed (11 cases and 24 hidden ones)" in done.stdout  # the learner's own hidden cases, while grading
    assert "seed outside a check: None" in done.stderr  # the seed is a check's only
    said = " ".join(done.stderr.split("visible only:")[1].split())  # unwrapped
    assert "a hidden case failed: a D-pad direction (or none) with the sticks moved." in said, said
    assert not any(c.isdigit() for c in said.split("failed")[1]), said  # what it tests, not its values
    # the same lines under another key are not the seal's
    with pytest.raises(AssertionError):
        signed_lines(done.stdout.replace("\t1.1\t", "\t1.2\t", 1))


def test_the_sandbox_keeps_the_library_and_hides_the_teachers_folders():
    """A clone in a hidden folder (a home): the kernel keeps tutorial/, project/, model/, never notebooks/."""
    from pathlib import Path

    from tutorial.exercises.sandbox import Job, kept_paths, sandbox_command

    root = Path(__file__).resolve().parent.parent
    kept = kept_paths([str(root.parent)])
    assert {str(root / p) for p in ("tutorial", "project", "model")} <= set(kept), kept
    assert not any(p.endswith(("notebooks", "course", "book")) for p in kept), kept
    job = Job("u", 1234, 1234, "/var/lib/rtt-grading/x/u", "/v", [str(root / "course")], ["c(a).require()"])
    command = sandbox_command(job, ["python", "-m", "k"], kept)
    assert command[:5] == ["unshare", "--mount", "--net", "--ipc", "--"], command
    assert "--no-new-privs" in command and "--reuid=1234" in command and command[-3:] == ["python", "-m", "k"]
    assert f"--as={4 << 30}" in command and "--nproc=256" in command and "--cpu=600" in command
    script = command[7]
    assert f"mount -t tmpfs -o mode=755,size=1m tmpfs {root / 'course'}" in script, script
    assert "ip link set lo up" in script and "mount -t tmpfs -o mode=1777,size=2g tmpfs /dev/shm" in script


ATTACKS = textwrap.dedent(
    """
    import gc, os, sys, types
    from tutorial.exercises import seal
    seal.install(b"k" * 32, 1, ["check_dpad_steering(dpad_track_velocities).require()"])
    import tutorial.exercises.grader as g
    import tutorial.exercises.step1_tank_controller as s

    def cell(text):
        exec(compile(text, "/tmp/ipykernel_0/cell.py", "single"), globals())

    def said(what, run):
        try:
            run()
            print(what, "allowed", file=sys.stderr)
        except RuntimeError as e:
            print(what, "refused" if "sandbox refused" in str(e) else e, file=sys.stderr)
            return e

    def dpad_track_velocities(axes):
        return 0.0, 0.0  # wrong

    # 1. the teacher's code in functions of the answer's own, with globals of its own, swapped in by sys.modules
    fake_grade = types.FunctionType(g.grade.__code__, dict(vars(g), _run_cases=lambda e, c: g.Result(e, True, "ok")))
    fake_check = types.FunctionType(s.check_dpad_steering.__code__, dict(vars(s), grade=fake_grade))
    fake = types.ModuleType(s.__name__)
    vars(fake).update(vars(s))
    fake.check_dpad_steering = fake_check
    sys.modules[s.__name__] = fake
    cell("from tutorial.exercises.step1_tank_controller import check_dpad_steering")
    cell("check_dpad_steering(dpad_track_velocities).require()")
    sys.modules[s.__name__] = s
    # 2. the garbage collector's object lists, outside a check
    said("gc", lambda: exec(compile("gc.get_objects()", "/tmp/ipykernel_0/cell.py", "exec")))
    # 3. an answer's object given to the hook, to run inside it
    class Evil:
        def __str__(self):
            print("EVIL RAN", file=sys.stderr)
            return "x"
        __format__ = __repr__ = lambda self, *a: self.__str__()
        def __hash__(self):
            print("EVIL RAN", file=sys.stderr)
            return 1
    said("evil", lambda: sys.audit("object.__setattr__", g.Result, Evil(), None))
    sys.audit("object.__getattr__", Evil(), Evil())
    sys.audit("rtt.suspect", Evil())
    # 4. a second hook (CPython drops it silently when a hook refuses), and a refusal's traceback, to the
    # hook's own frames
    sys.addaudithook(lambda event, args: print("SECOND HOOK", file=sys.stderr))
    open(os.devnull).close()
    error = said("hook", lambda: exec(compile("gc.get_referrers(g)", "/tmp/ipykernel_0/cell.py", "exec")))
    def walk():
        tb = error.__traceback__
        while tb is not None:
            tb.tb_frame
            tb = tb.tb_next
    said("traceback", walk)
    # 5. a tracer, which would see the hook's frames
    said("settrace", lambda: sys.settrace(lambda *a: None))
    """
)


def test_the_seal_withstands_the_attacks_a_review_found():
    done = sealed(ATTACKS)
    verdicts = [line for line in signed_lines(done.stdout) if line[0] == "verdict"]
    assert all(v[2:4] != ["1", "1"] for v in verdicts), verdicts  # no signed pass for the wrong answer
    for what in ("gc", "evil", "hook", "traceback", "settrace"):
        assert f"{what} refused" in done.stderr, (what, done.stderr)
    assert "EVIL RAN" not in done.stderr and "SECOND HOOK" not in done.stderr, done.stderr
