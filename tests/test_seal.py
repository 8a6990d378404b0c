"""The grading kernel's seal (tutorial/tools/grading/seal.py), in a process of its own (a sealed process stays sealed).

A genuine check signs a verdict that passes; the same check after the grader
was patched, or a Result made by hand, does not; a patched function's code is
refused; the signature holds only with the key.  Then each rule of the hook
that a mutation round found untested (benchmarks/RESULTS.md, *The seal*):
what an answer opens, links to a process's memory, frames during a check,
code claiming the library's files, processes and connections, and the ways
a verdict is not the teacher's.  The sandbox around it
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
    from tutorial.tools.grading import seal
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


def sealed(script: str, cwd=None) -> subprocess.CompletedProcess:
    """``script`` run in a Python of its own (it seals itself), on this machine's ROS graph; it must succeed.

    ``cwd``: its working folder (default this one's); it imports the ``tutorial`` this process imported.
    """
    import tutorial

    env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST")
    paths = [os.path.dirname(os.path.dirname(tutorial.__file__)), env.get("PYTHONPATH", "")]
    env["PYTHONPATH"] = os.pathsep.join(p for p in paths if p)
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120, env=env, cwd=cwd)
    assert done.returncode == 0, done.stderr
    return done


def test_the_seal_signs_only_the_teachers_untouched_check():
    done = sealed(SCRIPT)
    lines = signed_lines(done.stdout)
    verdicts = [line for line in lines if line[0] == "verdict"]
    assert [v[1:4] for v in verdicts] == [["1.1", "1", "1"], ["1.1", "1", "0"], ["1.1", "1", "1"], ["1.1", "0", "1"]]
    assert [line for line in lines if line[0] == "begin"] == [["begin", "1.1"]] * 4  # each check named as it begins
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


def test_the_seal_trusts_the_modules_a_check_imports_only_when_it_runs():
    """2.1's check imports the scripted run's modules inside its functions: they are imported, and so snapshot,
    before any answer runs (an answer could otherwise import one first and replace what is in it, unseen)."""
    done = sealed(
        "from tutorial.tools.grading import seal\n"
        "print(*(m.__name__ for m in seal.trusted_modules(['tutorial.exercises.step2_joint_state_publisher'])))"
    )
    trusted = set(done.stdout.split())
    lazily = {"tutorial.notebook.runs", "tutorial.app.reference.tank_controller", "tutorial.joystick.scripted"}
    assert lazily <= trusted, lazily - trusted
    assert "tutorial.exercises.step1_tank_controller" not in trusted  # only the checks named, and the grader
    done = sealed(
        "import sys\n"
        "from tutorial.tools.grading import seal\n"
        "seal.install(b'k' * 32, 1, [], checks=['tutorial.exercises.step1_tank_controller'])\n"
        "print(*sorted(n for n in sys.modules if n.startswith('tutorial.exercises.step')))"
    )
    assert done.stdout.split() == ["tutorial.exercises.step1_tank_controller"]  # install imports only those named


def test_an_answer_reading_the_projects_and_models_is_not_noted_and_one_reading_elsewhere_is(tmp_path):
    """The answer works in a folder of its own: opening the system's files, the project files and models the
    library reads, or its own files, is quiet; opening a file elsewhere or in a hidden folder (were it there or
    not, named by an absolute or a relative path) is noted, and named."""
    (tmp_path / "hidden").mkdir()
    (tmp_path / "hidden" / "secret").write_text("the teacher's")  # one noted path is there
    done = sealed(
        textwrap.dedent(
            f"""
            import os, tutorial
            from tutorial.tools.grading import seal
            seal.install(b"k" * 32, 1, [], hidden=[{str(tmp_path / "hidden")!r}])
            repository = os.path.dirname(os.path.dirname(os.path.realpath(tutorial.__file__)))
            with open("mine.txt", "w") as f:
                f.write("my own")
            for path in (
                "/dev/null",
                "/proc/self/status",
                "/sys/rtt-not-there",
                "/etc/hostname",
                "/usr/rtt-not-there",
                "/lib/rtt-not-there",
                "/run/rtt-not-there",
                os.path.join(repository, "project/step1.yaml"),
                os.path.join(repository, "model/tank.xml"),
                "mine.txt",
                os.path.join(repository, "course/source/secret"),
                "/var/rtt\tnot-there",
                os.path.relpath("/var/rtt-relative"),
                os.path.join({str(tmp_path)!r}, "hidden", "secret"),
            ):
                try:
                    open(path).close()
                except OSError:
                    pass
            """
        ),
        cwd=tmp_path,
    )
    import tutorial

    repository = os.path.dirname(os.path.dirname(os.path.realpath(tutorial.__file__)))
    notes = [line for line in signed_lines(done.stdout) if line[0] == "note"]
    assert {n[1] for n in notes} == {"outside"}, notes
    assert [n[2] for n in notes] == [
        *([f"opened {repository}/course/source/secret"] if not repository.startswith("/tmp/") else []),  # else allowed
        "opened /var/rtt not-there",  # a tab in a field is a space: the line's fields stay apart
        "opened /var/rtt-relative",
        f"opened {tmp_path / 'hidden' / 'secret'}",
    ], notes


def test_an_answer_cannot_open_a_process_s_memory_directly_or_through_a_chain_of_relative_links(tmp_path):
    """Opening /proc/self/mem (where the seal's key lives) is refused, and so is a link to a link to it, made
    before the seal; making a link to /proc is refused after; a link to a file of the answer's own opens."""
    done = sealed(
        textwrap.dedent(
            """
            import os, sys
            os.symlink("b", "a")  # a -> b -> /proc/self/mem, each link relative to its folder
            os.symlink("/proc/self/mem", "b")
            os.mkdir("links")
            os.symlink("y", "links/x")  # the same in a folder that is not the working one (which has no y)
            os.symlink("/proc/self/mem", "links/y")
            with open("real.txt", "w") as f:
                f.write("plain")
            os.symlink("real.txt", "c")
            from tutorial.tools.grading import seal
            seal.install(b"k" * 32, 1, [])
            for path in ("/proc/self/mem", os.path.abspath("a"), "a", "links/x", "c"):
                try:
                    with open(path, "rb") as f:
                        print("read", path, f.read(5), file=sys.stderr)
                except RuntimeError as e:
                    print("refused", path, e, file=sys.stderr)
            links = ((os.symlink, "/proc/self/mem"), (os.symlink, "../../proc/1/mem"), (os.link, "/proc/self/mem"))
            for make, source in links:
                try:
                    make(source, "d")
                except RuntimeError as e:
                    print("refused", e, file=sys.stderr)
            os.symlink("real.txt", "e")  # a link elsewhere: made
            """
        ),
        cwd=tmp_path,
    )
    said = [line for line in done.stderr.splitlines() if line.startswith(("read ", "refused "))]
    assert said[:4] == [
        "refused /proc/self/mem the grader's sandbox refused: opening /proc/self/mem",
        f"refused {tmp_path / 'a'} the grader's sandbox refused: opening {tmp_path / 'a'}",
        f"refused a the grader's sandbox refused: opening {tmp_path / 'a'}",
        f"refused links/x the grader's sandbox refused: opening {tmp_path / 'links' / 'x'}",
    ], done.stderr
    assert said[4] == "read c b'plain'", done.stderr
    assert said[5:] == [
        "refused the grader's sandbox refused: a link to /proc/self/mem",
        "refused the grader's sandbox refused: a link to ../../proc/1/mem",
        "refused the grader's sandbox refused: a link to /proc/self/mem",  # a hard link
    ], done.stderr
    assert (tmp_path / "e").is_symlink() and not (tmp_path / "d").exists()


# A sealed script's start: the seal installed for exercise 1.1's test cell, its check and module imported, a cell
# run as IPython runs a test cell's last line, and a right answer.
SEALED_1_1 = textwrap.dedent(
    """
    import sys
    from tutorial.tools.grading import seal
    seal.install(b"k" * 32, 1, ["check_dpad_steering(dpad_track_velocities).require()"])
    from tutorial.exercises.step1_tank_controller import check_dpad_steering
    import tutorial.exercises.step1_tank_controller as step1
    from tutorial.interfaces import joy

    def cell(text):
        exec(compile(text, "/tmp/ipykernel_0/cell.py", "single"), globals())

    def dpad_track_velocities(axes):
        forward, turn = joy.axis(axes, joy.DPAD_V), 0.5 * joy.axis(axes, joy.DPAD_H)
        return forward - turn, forward + turn
    """
)


def test_a_verdict_from_another_statement_a_hand_made_result_or_a_changed_class_method_is_not_the_teachers():
    """require() from a statement other than the test cell's is no verdict of the cell; a Result made by hand
    under any name is noted as tampering; a check's function replaced before the check and put back during it
    is found, and so is a check of the answer's own under the check's name; a note names the check it came
    during, and no check after it; a class method's code of the library cannot be changed; a number of the
    answer's own class that equals everything is told to the teacher; another thread's frames, and a thread
    started with the answer's tracer, are refused."""
    done = sealed(
        SEALED_1_1
        + textwrap.dedent(
            """
            import os
            from tutorial.core.controller import SimpleController
            import tutorial.exercises.grader as grader

            cell("r = check_dpad_steering(dpad_track_velocities).require()")  # not the test cell's statement
            cell("grader.Result('steer left', True, 'ok').require()")  # made by hand, under a name of no exercise
            real, calls = grader.same_numbers, []
            grader.same_numbers = lambda *a, **k: True  # replaced before the check, put back during it

            def dpad_track_velocities(axes):
                if not calls:
                    grader.same_numbers = real
                    try:
                        open("/var/rtt-during").close()
                    except OSError:
                        pass
                calls.append(axes)
                forward, turn = joy.axis(axes, joy.DPAD_V), 0.5 * joy.axis(axes, joy.DPAD_H)
                return forward - turn, forward + turn

            cell("check_dpad_steering(dpad_track_velocities).require()")
            try:
                open("/var/rtt-after").close()
            except OSError:
                pass
            try:
                SimpleController.start.__code__ = (lambda self: True).__code__  # the library's lifecycle
            except RuntimeError as e:
                print("refused:", e, file=sys.stderr)
            real_axis = joy.axis
            joy.axis = lambda axes, index: real_axis(axes, index)  # a library function the check uses, wrapped
            cell("check_dpad_steering(dpad_track_velocities).require()")
            joy.axis = real_axis
            cells = grader.CaseFailed.__init__.__closure__
            cells[0].cell_contents = AssertionError  # a closure of the grader's (super()'s class) changed
            cell("check_dpad_steering(dpad_track_velocities).require()")
            cells[0].cell_contents = grader.CaseFailed
            teachers = check_dpad_steering

            def check_dpad_steering(func):  # shadowed: a check of the answer's own
                return grader.grade("Exercise 1.1, steer", [grader.Case("anything", lambda: None)])

            cell("check_dpad_steering(dpad_track_velocities).require()")
            check_dpad_steering = teachers

            class Same(float):  # a number equal to every other
                def __eq__(self, other):
                    return True

                __hash__ = float.__hash__

            def dpad_track_velocities(axes):
                return Same(0.0), Same(0.0)

            try:
                cell("check_dpad_steering(dpad_track_velocities).require()")
            except AssertionError:
                pass
            try:
                sys._current_frames()
            except RuntimeError as e:
                print("refused:", e, file=sys.stderr)
            import threading

            threading.settrace(lambda *a: None)  # a thread started with the answer's tracer
            thread = threading.Thread(target=lambda: None)
            thread.start()
            thread.join()
            """
        )
    )
    lines = signed_lines(done.stdout)
    verdicts = [line for line in lines if line[0] == "verdict"]
    assert [v[1:] for v in verdicts] == [
        ["1.1", "1", "0", "require() was not called by the test cell's statement"],
        ["1.1", "1", "0", "tutorial.exercises.grader.same_numbers was replaced"],  # when the check began
        ["1.1", "1", "0", "tutorial.interfaces.joy.axis was replaced"],
        ["1.1", "1", "0", "tutorial.exercises.grader.CaseFailed.__init__'s closure was changed"],
        ["1.1", "1", "0", "grade() was not called by one of the teacher's checks"],  # the shadowed check
        ["1.1", "0", "1", ""],  # the numbers equal to every other: failed, by the teacher's check
    ], verdicts
    notes = [line[1:] for line in lines if line[0] == "note"]
    assert notes == [
        ["tampering", "a verdict not made by the teacher's check and require()", "?"],
        ["outside", "opened /var/rtt-during", "1.1"],  # during the check: the check's
        ["outside", "opened /var/rtt-after", ""],  # after it: the next check's
        ["refused", "changing SimpleController.start.__code__", ""],
        ["tampering", "an answer returned a Same, a class of its own that compares as it likes", "1.1"],
        ["refused", "sys._current_frames", ""],
        ["refused", "sys.settrace", ""],  # in the thread, which its tracer would have watched
    ], notes
    assert "refused: the grader's sandbox refused: changing SimpleController.start.__code__" in done.stderr, done.stderr
    assert "refused: the grader's sandbox refused: sys._current_frames" in done.stderr, done.stderr


def test_frames_code_processes_and_connections_of_an_answer_are_refused_or_noted_as_the_seal_says():
    """Outside a check an answer may read its own frames; during one it may not.  Code claiming a file of the
    library is refused; a process started and a connection tried are noted (the network tier has none)."""
    done = sealed(
        textwrap.dedent(
            """
            import inspect, os, socket, subprocess, sys, threading, types
            import tutorial
            import tutorial.exercises.grader as grader
            from tutorial.tools.grading import seal
            seal.install(b"k" * 32, 1, ["check_dpad_steering(dpad_track_velocities).require()"])
            from tutorial.exercises.step1_tank_controller import check_dpad_steering
            from tutorial.interfaces import joy

            def said(what, attack):
                try:
                    print(what, "gave", attack(), file=sys.stderr)
                except RuntimeError as e:
                    print(what, e, file=sys.stderr)

            def own_traceback_frame():
                try:
                    1 / 0
                except ZeroDivisionError as e:
                    return e.__traceback__.tb_frame.f_code.co_name

            said("frame", lambda: sys._getframe().f_code.co_name)
            said("traceback", own_traceback_frame)
            calls = []

            def dpad_track_velocities(axes):
                if not calls:  # during the check
                    said("frame during", lambda: sys._getframe().f_code.co_name)
                    said("traceback during", own_traceback_frame)
                    said("currentframe during", lambda: inspect.currentframe().f_code.co_name)
                    # a function of the answer's with the grader's globals, saying the check ended: not the grader
                    types.FunctionType(compile("sys.audit('rtt.check_end')", "answer", "exec"), vars(grader))()
                    said("frame after its end", lambda: sys._getframe().f_code.co_name)
                calls.append(axes)
                forward, turn = joy.axis(axes, joy.DPAD_V), 0.5 * joy.axis(axes, joy.DPAD_H)
                return forward - turn, forward + turn

            check_dpad_steering(dpad_track_velocities)
            said("compile", lambda: compile("1", tutorial.__file__, "eval"))
            said("replace", lambda: (lambda: 0).__code__.replace(co_filename=tutorial.__file__))
            said("process", lambda: subprocess.run(["true"]).returncode)
            with socket.socket() as s:
                said("connect", lambda: s.connect_ex(("127.0.0.1", 9)) is not None)  # refused or not: noted
            threading.setprofile(lambda *a: None)  # a thread started with the answer's profiler
            thread = threading.Thread(target=lambda: None)
            thread.start()
            thread.join()
            """
        )
    )
    asked = ("frame", "traceback", "currentframe", "compile", "replace", "process", "connect")
    said = [line for line in done.stderr.splitlines() if line.split(" ")[0] in asked]
    refused = "the grader's sandbox refused:"
    assert said == [
        "frame gave <lambda>",
        "traceback gave own_traceback_frame",
        f"frame during {refused} reading frames during a check",
        f"traceback during {refused} reading tb_frame during a check",
        f"currentframe during {refused} reading frames during a check",
        f"frame after its end {refused} reading frames during a check",
        f"compile {refused} code claiming to be the library's ({tutorial_file()})",
        f"replace {refused} code claiming to be the library's ({tutorial_file()})",
        "process gave 0",
        "connect gave True",
    ], done.stderr
    notes = [line[1:] for line in signed_lines(done.stdout) if line[0] == "note"]
    assert notes[-3:] == [
        ["processes", "subprocess.Popen", ""],
        ["network", "socket.connect", ""],
        ["refused", "sys.setprofile", ""],  # in the thread
    ], notes


def tutorial_file() -> str:
    """The file of the ``tutorial`` package this process imported (the one the sealed Python imports)."""
    import tutorial

    return tutorial.__file__


def test_the_sandbox_keeps_the_library_and_hides_the_teachers_folders():
    """A clone in a hidden folder (a home): the kernel keeps tutorial/, project/, model/, never notebooks/."""
    from pathlib import Path

    from tutorial.tools.grading.sandbox import Job, kept_paths, sandbox_command

    root = Path(__file__).resolve().parent.parent
    kept = kept_paths([str(root.parent)])
    assert {str(root / p) for p in ("tutorial", "project", "model")} <= set(kept), kept
    assert not any(p.endswith(("notebooks", "course", "book")) for p in kept), kept
    job = Job("u", 1234, 1234, "/var/lib/rtt-grading/x/u", "/v", [str(root / "course")], ["c(a).require()"])
    command = sandbox_command(job, ["python", "-m", "k"], kept)
    assert command[:5] == ["unshare", "--mount", "--net", "--ipc", "--"], command
    assert "--no-new-privs" in command and "--reuid=1234" in command and command[-3:] == ["python", "-m", "k"]
    assert f"--as={4 << 30}" in command and "--nproc=256" in command and "--cpu=600:605" in command
    script = command[7]
    assert f"mount -t tmpfs -o mode=755,size=1m tmpfs {root / 'course'}" in script, script
    assert "ip link set lo up" in script and "mount -t tmpfs -o mode=1777,size=2g tmpfs /dev/shm" in script
    # the rest read-only, but the job's folder (bound onto itself first) and the private folders
    bound = script.index("mount --bind /var/lib/rtt-grading/x/u /var/lib/rtt-grading/x/u")
    assert bound < script.index("remount,bind,ro")
    assert "mount -t mqueue mqueue /dev/mqueue" in script  # the new IPC namespace's queues, not the host's
    assert 'mount -o remount,bind,ro "$mp"' in script and "|/var/lib/rtt-grading/x/u|/tmp|/var/tmp|/dev/shm)" in script


def test_the_sandbox_leaves_nothing_writable_but_its_own_folders():
    """The sandbox's mounts, run for real (root): a file in /run/lock, in a folder anyone may write on the root
    file system, or on a mount of its own whose name has a space (mountinfo writes it \\040) is refused; the
    job's folder and the private /tmp take one, and nothing written there reaches this machine's own folders."""
    import secrets
    import shlex
    import shutil
    from pathlib import Path

    from tutorial.tools.grading.sandbox import Job, sandbox_command

    if os.geteuid() != 0 or not shutil.which("unshare"):
        pytest.skip("the sandbox's namespaces need root")
    folder = Path("/var/lib/rtt-grading") / f"probe-{secrets.token_hex(4)}"  # where grading's jobs are (not /tmp)
    (folder / "k").mkdir(parents=True)
    outside = folder.with_name(folder.name + "-host")  # this machine's, beside the job's folder
    open_to_all, spaced = outside / "open", outside / "a mount"
    open_to_all.mkdir(parents=True)
    spaced.mkdir()
    mounted = False
    try:
        os.chown(folder / "k", 65534, 65534)
        os.chmod(open_to_all, 0o1777)  # writable by anyone, on the file system that holds /var/lib
        subprocess.run(["mount", "-t", "tmpfs", "-o", "mode=1777,size=1m", "tmpfs", str(spaced)], check=True)
        mounted = True
        job = Job("nobody", 65534, 65534, str(folder), "/v", [], ["c(a).require()"])
        tries = {
            "/run/lock": "refused",
            str(open_to_all): "refused",
            str(spaced): "refused",
            str(folder / "k"): "written",
            "/tmp": "written",
        }
        probe = "; ".join(
            f"(touch {shlex.quote(p + '/rtt-probe')} 2>/dev/null && echo {shlex.quote(p)}=written"
            f" || echo {shlex.quote(p)}=refused)"
            for p in tries
        )
        # without the sandbox, this user writes each of them
        assert (
            subprocess.run(
                [
                    "setpriv",
                    "--reuid=65534",
                    "--regid=65534",
                    "--clear-groups",
                    "sh",
                    "-c",
                    f"touch {shlex.quote(str(open_to_all))}/w {shlex.quote(str(spaced))}/w",
                ]
            ).returncode
            == 0
        )
        done = subprocess.run(
            sandbox_command(job, ["sh", "-c", probe], []), capture_output=True, text=True, timeout=60, check=False
        )
        assert done.returncode == 0, done.stderr
        said = dict(line.rsplit("=", 1) for line in done.stdout.splitlines())
        assert said == tries, (said, done.stderr)
        assert not Path("/run/lock/rtt-probe").exists() and not Path("/tmp/rtt-probe").exists()
        assert not (open_to_all / "rtt-probe").exists() and not (spaced / "rtt-probe").exists()
    finally:
        if mounted:
            subprocess.run(["umount", str(spaced)], check=False)
        shutil.rmtree(folder, ignore_errors=True)
        shutil.rmtree(outside, ignore_errors=True)
        Path("/run/lock/rtt-probe").unlink(missing_ok=True)  # a sandbox that let it through


def test_a_checks_own_constant_replaced_before_it_and_put_back_while_it_runs_is_tampering():
    """The check builds its table from the module's DPAD_SPEED as it begins: an answer that changed it before
    and puts it back from inside the check leaves nothing changed at the end; the change seen at the begin
    still counts."""
    script = SEALED_1_1 + textwrap.dedent(
        """
        real = step1.DPAD_SPEED
        cell("step1.DPAD_SPEED = 0.0")

        def dpad_track_velocities(axes):
            step1.DPAD_SPEED = real  # put back while the check runs
            return 0.0, 0.0

        try:
            cell("check_dpad_steering(dpad_track_velocities).require()")
        except AssertionError:
            pass
        """
    )
    verdicts = [line[1:] for line in signed_lines(sealed(script).stdout) if line[0] == "verdict"]
    assert verdicts == [["1.1", "0", "0", "tutorial.exercises.step1_tank_controller.DPAD_SPEED was replaced"]]


def test_a_name_a_check_reads_only_through_what_it_calls_replaced_is_tampering():
    """What a check uses is the names its code reads and, in turn, the names read by the functions it calls
    (looked up in its module): step1's own binding of the grader's same_numbers is one, which the check reads
    only through what it calls.  An answer that rebinds that one (not the grader's) is told."""
    script = SEALED_1_1 + textwrap.dedent(
        """
        def dpad_track_velocities(axes):
            return 0.0, 0.0  # wrong

        cell("step1.same_numbers = lambda *a, **k: True")
        try:
            cell("check_dpad_steering(dpad_track_velocities).require()")
        except AssertionError:
            pass  # the check itself compared with the grader's own
        """
    )
    verdicts = [line[1:] for line in signed_lines(sealed(script).stdout) if line[0] == "verdict"]
    assert verdicts == [["1.1", "0", "0", "tutorial.exercises.step1_tank_controller.same_numbers was replaced"]]


def test_a_check_modules_imports_inside_its_functions_are_found_modules_alone(tmp_path, monkeypatch):
    """What a check imports inside a function is trusted before any answer runs: a module named by its path,
    or from its package (``from tutorial.interfaces import joy``); a function or class it imports is no module."""
    from tutorial.tools.grading.seal import _tutorial_imports

    (tmp_path / "lazy_check.py").write_text(
        "def check():\n"
        "    from tutorial.interfaces import joy, imu\n"
        "    from tutorial.core.world import build_world\n"
        "    import tutorial.notebook.runs\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    import lazy_check

    assert sorted(_tutorial_imports(lazy_check)) == [
        "tutorial.core.world",
        "tutorial.interfaces",
        "tutorial.interfaces.imu",
        "tutorial.interfaces.joy",
        "tutorial.notebook.runs",
    ]


def test_the_seals_own_data_replaced_by_an_answer_is_tampering():
    """The hook keeps its own copies (install rebuilds it with private globals), so an answer that empties the
    seal's list of noted events changes nothing it does; it is still told as tampering at the next check, as
    any change to a check module's data is."""
    script = SEALED_1_1 + textwrap.dedent(
        """
        cell("import tutorial.tools.grading.seal as s; s.NOTED = frozenset()")
        cell("check_dpad_steering(dpad_track_velocities).require()")
        """
    )
    verdicts = [line[1:] for line in signed_lines(sealed(script).stdout) if line[0] == "verdict"]
    assert verdicts == [["1.1", "1", "0", "tutorial.tools.grading.seal.NOTED was replaced"]], verdicts


# What a cheating answer does with a frame it got: reads the check's own expected values below it
READ_EXPECTED = textwrap.dedent(
    """
    def expected_from(frame):  # the check's own expected value, from the frames below this one (f_back: no audit)
        while frame is not None and "expected" not in frame.f_locals:
            frame = frame.f_back
        return frame.f_locals["expected"] if frame is not None else (0.0, 0.0)

    def own_traceback():
        try:
            1 / 0
        except ZeroDivisionError as e:
            return e.__traceback__
    """
)
STACK_WALKS = READ_EXPECTED + textwrap.dedent(
    """
    import collections, inspect, logging, traceback, types, typing

    def deeper(n):  # walk_stack(None) starts four frames up
        return deeper(n - 1) if n else next(traceback.walk_stack(None))[0]

    class Frames:  # traceback.extract_stack's real code with globals of the answer's: its StackSummary is this
        @staticmethod
        def extract(frames, limit=None):
            Frames.taken = next(frames)[0]

    own_names = dict(vars(traceback), StackSummary=Frames)
    extract_stack = types.FunctionType(traceback.extract_stack.__code__, own_names, None, (None, None))

    def through_own_names():
        extract_stack()
        return Frames.taken

    WALKS = {
        "traceback.walk_stack": lambda: deeper(4),
        "traceback.walk_tb": lambda: next(traceback.walk_tb(own_traceback()))[0],
        "inspect.stack": lambda: inspect.stack()[0].frame,
        "inspect.getinnerframes": lambda: inspect.getinnerframes(own_traceback())[0].frame,
        "traceback.extract_stack, with the answer's globals": through_own_names,
        # the check's locals as text: the answer parses them (here, only tries)
        "traceback.StackSummary": lambda: traceback.StackSummary.extract(
            traceback.walk_stack(None), capture_locals=True
        )
        and None,
    }
    log = logging.getLogger("answer")
    log.addHandler(logging.NullHandler())

    def honest(axes):  # libraries that take a frame only to read it themselves
        log.warning("axes %s", axes)
        try:
            own_traceback().tb_next.tb_next  # an error of the answer's own, told with its traceback
        except AttributeError:
            log.exception("told")
            traceback.format_exc()
        traceback.extract_stack()
        collections.namedtuple("Tracks", "left right")
        typing.TypeVar("T")
        from matplotlib import _api
        from scipy._lib import _bunch

        _api.warn_external("a plot's warning")  # matplotlib's, for the answer's line
        _bunch._make_tuple_bunch("Fit", ["slope", "intercept"])  # scipy.stats' result classes
        forward, turn = joy.axis(axes, joy.DPAD_V), 0.5 * joy.axis(axes, joy.DPAD_H)
        return forward - turn, forward + turn

    for name, walk in WALKS.items():
        dpad_track_velocities = lambda axes: expected_from(walk())
        try:
            cell("check_dpad_steering(dpad_track_velocities).require()")
            print(name, "passed", file=sys.stderr)
        except (AssertionError, RuntimeError) as e:
            print(name, "refused" if "sandbox refused" in str(e) else "failed", file=sys.stderr)
    dpad_track_velocities = honest
    cell("check_dpad_steering(dpad_track_velocities).require()")
    """
)


def test_a_library_that_walks_the_stack_for_an_answer_during_a_check_is_refused_and_one_that_reads_it_is_not():
    """From any frame, f_back and f_locals (which Python does not audit) lead down to the check's own expected
    values.  So while an answer runs inside a check, a frame taken for it by a library (traceback's walks,
    inspect's, a stack summary with its locals) is refused, as its own are; logging, tracebacks told as text,
    namedtuple, typing, matplotlib's warnings and scipy's result classes, which read their caller's frame
    themselves, still work there.
    At b088ed8, walk_stack, walk_tb and getinnerframes gave full marks; until 2026-11-29, so did
    ``traceback.extract_stack``'s own code made into a function with the answer's globals (a library's code
    that reads a frame itself is trusted only with its module's own globals)."""
    done = sealed(SEALED_1_1 + STACK_WALKS)
    said = [line for line in done.stderr.splitlines() if line.startswith(("traceback.", "inspect."))]
    assert said == [
        "traceback.walk_stack refused",
        "traceback.walk_tb refused",
        "inspect.stack refused",
        "inspect.getinnerframes refused",
        "traceback.extract_stack, with the answer's globals refused",
        "traceback.StackSummary refused",
    ], done.stderr
    verdicts = [line[1:] for line in signed_lines(done.stdout) if line[0] == "verdict"]
    frames, tb_frame = "reading frames during a check", "reading tb_frame during a check"
    assert [v[3] for v in verdicts[:6]] == [frames, tb_frame, frames, tb_frame, frames, frames], verdicts
    assert verdicts[6] == ["1.1", "1", "1", ""], verdicts  # the honest answer, logging and tracebacks on the way


def test_a_paused_generators_frame_taken_before_a_check_is_tampering():
    """A generator's frame taken while it is paused (here its own sys._getframe(), outside any check) gets a
    new f_back each time it is resumed: inside a check, the check's.  The seal looks for such frames of the
    answer's when a check begins."""
    script = (
        SEALED_1_1
        + READ_EXPECTED
        + textwrap.dedent(
            """
        def paused():
            me = sys._getframe()  # outside a check: allowed
            yield None
            while True:
                yield expected_from(me)

        generator = paused()
        next(generator)
        dpad_track_velocities = lambda axes: next(generator)
        cell("check_dpad_steering(dpad_track_velocities).require()")
        generator.close()
        import warnings

        def honest():  # its frame made by Python alone: an exception caught inside it, a warning
            while True:
                try:
                    1 / 0
                except ZeroDivisionError:
                    warnings.warn("divided by zero")
                yield 0.0

        samples = honest()
        next(samples)  # paused, with its frame made, across the next check
        dpad_track_velocities = lambda axes: (0.0, 0.0)
        try:
            cell("check_dpad_steering(dpad_track_velocities).require()")
        except AssertionError:
            pass
        """
        )
    )
    verdicts = [line[1:] for line in signed_lines(sealed(script).stdout) if line[0] == "verdict"]
    assert verdicts == [
        ["1.1", "1", "0", "an answer's paused generator had its frame taken"],  # it read the answers
        ["1.1", "0", "1", ""],  # closed; the honest generator paused beside it is no tampering
    ], verdicts


def test_without_a_seed_a_check_runs_its_visible_cases_alone():
    """A learner's own run has no seed, so no hidden case: install's default."""
    done = sealed(SEALED_1_1 + "print(check_dpad_steering(dpad_track_velocities), file=sys.stderr)\n")
    assert "passed (11 cases)" in done.stderr, done.stderr


def test_a_thread_inside_the_hook_lets_no_other_threads_event_pass():
    """The hook lets its own events pass, thread by thread: while one thread of an answer is inside it (each of its
    refusals writes a signed note, and the write lets the other thread run), the other thread's frame reads are
    still refused, and so are its own.  A guard shared by all threads let one thread's reads through the other's
    refusals (found by mutation: ``me = None``)."""
    script = SEALED_1_1 + textwrap.dedent(
        """
        import threading

        sys.setswitchinterval(1e-6)  # hand the interpreter lock over as often as it can be
        read, refused, stop, ready = [], [0, 0], threading.Event(), threading.Event()

        def frames(who, until):
            while not until():
                ready.set()
                try:
                    read.append((who, sys._getframe().f_code.co_name))
                except RuntimeError:
                    refused[who] += 1

        def dpad_track_velocities(axes):
            if not stop.is_set():  # the first call, during the check
                other = threading.Thread(target=frames, args=(1, stop.is_set))
                other.start()
                ready.wait(10)
                count = iter(range(3000))
                frames(0, lambda: next(count, None) is None)
                stop.set()
                other.join(10)
            forward, turn = joy.axis(axes, joy.DPAD_V), 0.5 * joy.axis(axes, joy.DPAD_H)
            return forward - turn, forward + turn

        check_dpad_steering(dpad_track_velocities)
        print("read", read[:3], "refused", refused[0], refused[1] > 0, file=sys.stderr)
        """
    )
    said = [line for line in sealed(script).stderr.splitlines() if line.startswith("read ")]
    assert said == ["read [] refused 3000 True"], said


def test_a_library_uses_ctypes_for_an_answer_and_the_answer_itself_may_not():
    """Raw memory is refused to an answer's own code, not to the library code it calls (multiprocessing's shared
    values are ctypes objects): only the caller's file says whose the call is, past ctypes' own Python
    (``string_at`` wraps its C function: a review read an object's bytes through it)."""
    script = textwrap.dedent(
        """
        from tutorial.tools.grading import seal
        seal.install(b"k" * 32, 1, [])

        def cell(text):
            exec(compile(text, "/tmp/ipykernel_0/cell.py", "exec"), globals())

        cell("import multiprocessing\\nprint('a library:', multiprocessing.Value('i', 3).value)")
        try:
            cell("import ctypes\\nctypes.c_int.from_buffer(bytearray(4))")
            print("the answer: allowed")
        except RuntimeError as e:
            print("the answer:", "refused" if "sandbox refused" in str(e) else e)
        try:
            cell("ctypes.string_at(id(b'secret') + 32, 6)")
            print("through string_at: allowed")
        except RuntimeError as e:
            print("through string_at:", "refused" if "sandbox refused" in str(e) else e)
        """
    )
    done = sealed(script)
    assert "a library: 3" in done.stdout and "the answer: refused" in done.stdout, done.stdout
    assert "through string_at: refused" in done.stdout, done.stdout
    notes = [line[1:3] for line in signed_lines(done.stdout)]
    assert notes == [["refused", "ctypes.cdata/buffer"], ["refused", "ctypes.string_at"]], notes


def test_the_kernel_refuses_the_keyrings_to_itself_and_every_process_it_starts():
    """keyrings.refuse(), as the sealed kernel calls it (no_new_privs, as setpriv gives it): a key put in the
    thread's own keyring before is refused after, in the process and in a child; the rest of the system works."""
    code = textwrap.dedent(
        """
        import ctypes, subprocess, sys
        from tutorial.tools.grading import keyrings
        libc = ctypes.CDLL(None, use_errno=True)
        def add_key():  # into the thread's own keyring (-1), which ends with it: nothing is left behind
            ok = libc.syscall(*(ctypes.c_long(a) if isinstance(a, int) else a
                                for a in (248, b"user", b"rtt-probe", b"x", 1, -1))) >= 0
            return "added" if ok else f"refused {ctypes.get_errno()}"
        print("before", add_key())
        libc.prctl(38, 1, 0, 0, 0)  # PR_SET_NO_NEW_PRIVS
        keyrings.refuse()
        print("after", add_key())
        print("child", subprocess.run([sys.executable, "-c", CHILD], capture_output=True, text=True).stdout.strip())
        print("open", open(__import__("os").devnull).read() == "")
        """
    )
    child = "import ctypes\nlibc = ctypes.CDLL(None, use_errno=True)\n"
    child += "print(libc.syscall(250, 0, -4, 0) < 0 and ctypes.get_errno())\n"
    code = f"CHILD = {child!r}\n" + code  # the child asks for its user keyring's ID
    ran = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=False)
    assert ran.returncode == 0, ran.stderr
    assert ran.stdout.split("\n")[:4] == ["before added", "after refused 1", "child 1", "open True"], ran.stdout


ATTACKS = textwrap.dedent(
    """
    import gc, os, sys, types
    from tutorial.tools.grading import seal
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
    notes = [line[1:3] for line in signed_lines(done.stdout) if line[0] == "note"]
    assert ["refused", "reading the grader's own frames"] in notes, notes  # the teacher reads why


def test_the_libraries_a_check_draws_and_compares_with_replaced_are_tampering_and_a_failed_cases_frames_go():
    """Found by a red-team review, each gave full points unflagged: ``random.Random`` replaced (every check ran
    its visible cases alone), and the check's own frames read from an answer's exception once the check had
    ended (every case, hidden ones with what they expect).  Now a replaced ``random.Random`` or
    ``numpy.allclose``, or a method of ``random.Random``, is tampering, the seed goes to no Random an answer
    changed, an exception an answer raised in a case has no frames left when the check returns, and the
    check's frames that one it caught itself leads to (``f_back``) hold nothing once the check has ended."""
    script = SEALED_1_1.replace(
        '["check_dpad_steering(dpad_track_velocities).require()"])',
        '["check_dpad_steering(dpad_track_velocities).require()"], seed="s")',
    ) + textwrap.dedent(
        """
        import random, numpy
        real, seen = random.Random, []

        class Spy(real):
            def __init__(self, x=None):
                seen.append(x)
                super().__init__(x)

        random.Random = Spy
        cell("check_dpad_steering(dpad_track_velocities).require()")
        print("seeds seen:", seen, file=sys.stderr)
        random.Random, real_allclose = real, numpy.allclose
        numpy.allclose = lambda *a, **k: True
        cell("check_dpad_steering(dpad_track_velocities).require()")
        numpy.allclose = real_allclose
        real_seed = random.Random.seed
        random.Random.seed = lambda self, *a, **k: seen.append(a) or real_seed(self, *a, **k)
        cell("check_dpad_steering(dpad_track_velocities).require()")
        print("seeds seen by a method:", seen, file=sys.stderr)
        random.Random.seed = real_seed
        kept = []

        def probe(axes):
            kept.append(ValueError())
            raise kept[0]

        try:
            cell("check_dpad_steering(probe).require()")
        except AssertionError:
            pass
        print("frames left:", kept[0].__traceback__, file=sys.stderr)

        def caught(axes):  # its own exception, caught inside the case: its frame's f_back is the check's
            try:
                raise ValueError
            except ValueError as e:
                kept.append(e)
            return 0.0, 0.0

        try:
            cell("check_dpad_steering(caught).require()")
        except AssertionError:
            pass
        back = kept[-1].__traceback__.tb_frame.f_back
        locals_now = back.f_code.co_name, dict(back.f_locals), dict(back.f_back.f_locals)
        print("the check's locals:", *locals_now, file=sys.stderr)
        # a second review: a thread of the answer's whose target is a C callable has no answer frame on its stack
        import _thread, gc, operator, threading

        try:
            cell("check_dpad_steering(caught).require()")
        except AssertionError:
            pass
        out = []
        t = threading.Thread(target=out.extend, args=(map(operator.attrgetter("tb_frame"), [kept[-1].__traceback__]),))
        t.start()
        t.join()
        back = out[0].f_back
        print("from a thread, the check's locals:", back.f_code.co_name, dict(back.f_locals), file=sys.stderr)
        t = threading.Thread(target=out.extend, args=(map(gc.get_objects, [None]),))
        t.start()
        t.join()
        ended = threading.Event()  # a raw thread's exception goes to sys.unraisablehook, once it is refused
        sys.unraisablehook = lambda unraisable: ended.set()
        _thread.start_new_thread(out.extend, (map(gc.get_objects, [None]),))  # a raw thread: no Python frame at all
        print("raw thread ended:", ended.wait(30.0), file=sys.stderr)
        print("objects got:", len(out), file=sys.stderr)
        cell("check_dpad_steering(dpad_track_velocities).require()")
        """
    )
    done = sealed(script)
    verdicts = [line[1:] for line in signed_lines(done.stdout) if line[0] == "verdict"]
    assert verdicts[0][:3] == ["1.1", "1", "0"] and "random.Random was replaced" in verdicts[0][3], verdicts
    assert verdicts[1][:3] == ["1.1", "1", "0"] and "numpy.allclose was replaced" in verdicts[1][3], verdicts
    assert verdicts[2][:3] == ["1.1", "1", "0"] and "random.Random.seed was replaced" in verdicts[2][3], verdicts
    assert len(verdicts) == 7 and all(v[:2] == ["1.1", "0"] for v in verdicts[3:6]), verdicts  # the probes: wrong
    assert verdicts[6] == ["1.1", "1", "1", ""], verdicts  # all put back: genuine
    assert "seeds seen: []" in done.stderr and "seeds seen by a method: []" in done.stderr, done.stderr
    assert "frames left: None" in done.stderr, done.stderr
    assert "the check's locals: <lambda> {} {}" in done.stderr, done.stderr  # the case's, then _run_cases'
    assert "from a thread, the check's locals: <lambda> {}" in done.stderr, done.stderr
    assert "raw thread ended: True" in done.stderr, done.stderr
    assert "objects got: 1" in done.stderr, done.stderr  # the frame alone: both lists of every object refused
    notes = [line[1:3] for line in signed_lines(done.stdout) if line[0] == "note"]
    assert ["refused", "gc.get_objects in a thread other than the kernel's main thread"] in notes, notes
    assert ["refused", "gc.get_objects from a thread with no Python code"] in notes, notes


def test_an_answer_that_replaces_a_builtin_during_a_check_does_not_change_the_seals_answers():
    """The hook runs with a private copy of the builtins: an answer that makes any() say yes to "does this library
    keep the frame to itself?" while it walks the stack, and puts any() back before the check sees it, is still
    refused.  With the builtins shared (the mutant install_38), it got full marks, genuine."""
    script = (
        SEALED_1_1
        + READ_EXPECTED
        + textwrap.dedent(
            """
        import builtins, traceback

        def dpad_track_velocities(axes):
            real = builtins.any
            builtins.any = lambda names: len(list(names)) == len(seal.FRAME_CONSUMERS)  # only the hook asks that
            try:
                frame = next(traceback.walk_tb(own_traceback()))[0]
            finally:
                builtins.any = real  # put back within the call: the snapshot at the check's end sees nothing
            return expected_from(frame)

        try:
            cell("check_dpad_steering(dpad_track_velocities).require()")
        except (AssertionError, RuntimeError) as e:
            print("refused" if "sandbox refused" in str(e) else "failed", file=sys.stderr)
        """
        )
    )
    done = sealed(script)
    assert "refused" in done.stderr.split(), done.stderr
    verdicts = [line[1:] for line in signed_lines(done.stdout) if line[0] == "verdict"]
    assert verdicts == [["1.1", "0", "0", "reading tb_frame during a check"]], verdicts


def test_a_check_modules_helper_changed_through_its_closure_is_tampering():
    """A helper made by a decorator (step5's contextmanager _viewer) holds the function it runs in a closure
    cell, which an answer can set without any audit event: swapped before the check, it is told at the check's
    begin, as a changed closure of a function the check uses in its own module."""
    script = textwrap.dedent(
        """
        import sys
        from tutorial.tools.grading import seal
        seal.install(b"k" * 32, 1, ["check_horizontal_arrow(HorizontalArrow).require()"],
                     checks=["tutorial.exercises.step5_imu_viewer"])
        import tutorial.exercises.step5_imu_viewer as step5
        from tutorial.exercises.step5_imu_viewer import check_horizontal_arrow

        class HorizontalArrow:
            pass

        def no_viewer(cls, name):  # the check's viewer, swapped for the answer's
            raise RuntimeError("the answer's viewer")
            yield

        step5._viewer.__closure__[0].cell_contents = no_viewer
        try:
            exec(compile("check_horizontal_arrow(HorizontalArrow).require()", "/tmp/ipykernel_0/cell.py", "single"))
        except (AssertionError, RuntimeError):
            pass
        """
    )
    verdicts = [line[1:] for line in signed_lines(sealed(script).stdout) if line[0] == "verdict"]
    assert verdicts == [["5.1", "0", "0", "tutorial.exercises.step5_imu_viewer._viewer's closure was changed"]]


def test_a_paused_coroutines_frame_taken_before_a_check_is_tampering():
    """As a paused generator's (above): a coroutine's frame, taken while it waits, has the check's below it when
    the answer resumes it inside the check.  (The mutant that looked up a coroutine's code under another name
    let it through, and any coroutine in the kernel then stopped the whole scan.)"""
    script = (
        SEALED_1_1
        + READ_EXPECTED
        + textwrap.dedent(
            """
        class Pause:
            def __await__(self):
                return (yield None)

        found = []

        async def reader():
            me = sys._getframe()  # outside a check: allowed
            while True:
                await Pause()
                found.append(expected_from(me))

        coroutine = reader()
        coroutine.send(None)  # paused at its first await

        def dpad_track_velocities(axes):
            coroutine.send(None)
            return found[-1]

        cell("check_dpad_steering(dpad_track_velocities).require()")
        """
        )
    )
    verdicts = [line[1:] for line in signed_lines(sealed(script).stdout) if line[0] == "verdict"]
    assert verdicts == [["1.1", "1", "0", "an answer's paused generator had its frame taken"]], verdicts


def test_a_library_compiled_from_its_source_by_the_import_system_imports_unnoted():
    """Where no cached code can be read or written (a read-only library, a new pycache_prefix), the import system
    compiles the library's source: its frames (frozen, "<frozen importlib._bootstrap>") are Python's own, not an
    answer's claiming the library's file name.  And the compiled code it writes, outside the answer's folder and
    far below the answer's import, is the import system's file, not one the answer opened: not noted."""
    import tempfile

    with tempfile.TemporaryDirectory(dir="/var/tmp") as cache:  # outside the answer's folder and /tmp/
        done = sealed(
            "import sys\n"
            "from tutorial.tools.grading import seal\n"
            "seal.install(b'k' * 32, 1, [])\n"
            f"sys.pycache_prefix = {cache!r}\n"
            "sys.dont_write_bytecode = False\n"  # whatever PYTHONDONTWRITEBYTECODE says
            "assert 'colorsys' not in sys.modules\n"  # imported here, not before
            "import colorsys\n"
            "print('imported', colorsys.__name__)\n"
        )
        written = [p.name for p in __import__("pathlib").Path(cache).rglob("*.pyc")]
    assert "imported colorsys" in done.stdout, done.stderr
    assert written and written[0].startswith("colorsys."), written  # it was compiled here, and written
    assert [line for line in signed_lines(done.stdout) if line[0] == "note"] == [], done.stdout


def test_only_the_kernels_signal_handlers_are_set_and_no_second_signal_module_is_made():
    """Python hands a signal handler the running frame with no audit event: an answer's handler, raised inside a
    case (``signal.raise_signal``), read every local of the check (``expected``, ``cases``) through ``f_back``.
    Now ``signal.signal`` sets only SIG_DFL, SIG_IGN, ``default_int_handler`` and the kernel's own handler, by
    its code object; a second ``_signal`` module (whose ``signal()`` would be real), by import or by
    ``_imp.create_builtin``, is refused; another built-in module is made as before.  A handler set past the
    gate (with the real function kept from before the seal) makes the next verdict not the teacher's.  A third
    review's wins are refused: a handler compiled by the import system's loader under a library's file name and
    function name (its own code, with the answer's globals), a library's real handler behind a partial whose
    arguments move the frame to a parameter whose error hands it back (``AttributeError.obj``), and an answer's
    code run inside the hook (there a finalizer, run when the hook clears a check's ended frames), where its
    events once passed unwatched: from there the hook's frames lead to its key."""
    script = (
        "import _signal\nbefore_the_seal = _signal.signal\n"
        + SEALED_1_1
        + textwrap.dedent(
            """
            import asyncio, functools, importlib.util, signal, _imp
            seen, kept = {}, _signal

            def spy(signum, frame):
                while frame is not None:
                    seen.update(frame.f_locals)
                    frame = frame.f_back

            def attempt(label, set_it):
                try:
                    set_it()
                    print(label, "set", file=sys.stderr)
                except RuntimeError as e:
                    print(label, "refused", file=sys.stderr)

            attempt("spy", lambda: signal.signal(signal.SIGUSR2, spy))
            attempt("partial", lambda: signal.signal(signal.SIGUSR2, functools.partial(dict.__setitem__, seen)))
            attempt("method", lambda: signal.signal(signal.SIGUSR2, seen.__setitem__))
            attempt("default", lambda: signal.signal(signal.SIGUSR1, signal.SIG_DFL))
            attempt("ignore", lambda: signal.signal(signal.SIGUSR2, signal.SIG_IGN))
            attempt("interrupt", lambda: signal.signal(signal.SIGINT, signal.default_int_handler))
            attempt("asyncio", lambda: signal.signal(signal.SIGUSR1, asyncio.unix_events._sighandler_noop))
            shifted = functools.partial(asyncio.runners.Runner._on_sigint, object(), 0)
            attempt("shifted", lambda: signal.signal(signal.SIGUSR1, shifted))
            import importlib.machinery, types
            source, path = b"def _sighandler_noop(signum, frame):\\n    spy(signum, frame)\\n", "<frozen asyncio>"
            try:
                forged = importlib.machinery.SourceFileLoader("x", path).source_to_code(source, path)
                print("forged compiled", file=sys.stderr)
            except RuntimeError:
                print("forged refused", file=sys.stderr)

            def reimported():
                del sys.modules["_signal"]
                try:
                    import _signal as fresh
                finally:
                    sys.modules["_signal"] = kept
                fresh.signal(signal.SIGUSR2, spy)

            attempt("import", reimported)
            attempt("create", lambda: _imp.create_builtin(importlib.util.find_spec("_signal")).signal(12, spy))
            attempt("create _imp", lambda: _imp.create_builtin(importlib.util.find_spec("_imp")))
            print("another built-in:", __import__("_symtable").__name__, file=sys.stderr)

            honest = dpad_track_velocities

            def dpad_track_velocities(axes):
                signal.raise_signal(signal.SIGUSR2)  # ignored: the spy was never set
                return honest(axes)

            cell("check_dpad_steering(dpad_track_velocities).require()")
            dpad_track_velocities = honest
            print("seen:", sorted(seen), file=sys.stderr)
            def dpad_track_velocities(axes):  # the handler put back during the check, once it has been used
                before_the_seal(signal.SIGUSR2, kept.SIG_IGN)
                return honest(axes)

            before_the_seal(signal.SIGUSR2, spy)  # past the gate, as a hole in it would, before the check
            cell("check_dpad_steering(dpad_track_velocities).require()")
            dpad_track_velocities = honest
            cell("check_dpad_steering(dpad_track_velocities).require()")

            def dpad_track_velocities(axes):  # past the gate during the check, after its start
                before_the_seal(signal.SIGUSR2, spy)
                return honest(axes)

            cell("check_dpad_steering(dpad_track_velocities).require()")
            """
        )
    )
    done = sealed(script)
    for label, said in [("spy", "refused"), ("partial", "refused"), ("method", "refused"), ("default", "set")]:
        assert f"{label} {said}" in done.stderr, done.stderr
    for label, said in [("ignore", "set"), ("interrupt", "set"), ("asyncio", "refused"), ("shifted", "refused")]:
        assert f"{label} {said}" in done.stderr, done.stderr
    for said in (
        "import refused",
        "create refused",
        "create _imp refused",
        "another built-in: _symtable",
        "forged refused",
    ):
        assert said in done.stderr, done.stderr
    assert "seen: []" in done.stderr, done.stderr  # the case's locals: none reached the spy
    verdicts = [line[1:] for line in signed_lines(done.stdout) if line[0] == "verdict"]
    assert verdicts[0] == ["1.1", "1", "1", ""], verdicts  # the check itself: passed, the teacher's
    assert verdicts[1][:3] == ["1.1", "1", "0"] and "a signal handler not the kernel's" in verdicts[1][3], verdicts
    assert verdicts[2] == ["1.1", "1", "1", ""], verdicts  # put back: the teacher's again
    assert verdicts[3][:3] == ["1.1", "1", "0"] and "a signal handler not the kernel's" in verdicts[3][3], verdicts
    notes = [line[2] for line in signed_lines(done.stdout) if line[:2] == ["note", "refused"]]
    assert sum("a signal handler of the answer's" in n for n in notes) == 5, notes
    assert "code claiming to be the library's (<frozen asyncio>)" in notes, notes
    assert sum("a second _signal or _imp module" in n for n in notes) == 3, notes


def test_an_answers_code_run_inside_the_hook_is_refused_what_the_hook_may_do_there():
    """The hook lets pass the events of its own work (its frame reads, gc); code of an answer's that ran inside it
    once had the same pass.  A third review ran one there, a signal's handler on an interval timer, and read
    the hook's frames, and from them its key.  Here the same handler, set past the gate with the real function
    kept from before the seal (as a hole in the gate would), fires until 200 land inside the hook (a deadline
    loop of compile() calls, each an event the hook works on).  Inside its guard, its frame read is refused as
    code run there; around its guard, as a frame that leads to the hook's.  Not closed, and said in seal.py: the
    few lines where the hook asks who raised an event (about one landing in five here)."""
    script = (
        "import _signal\nbefore_the_seal = _signal.signal\n"
        + SEALED_1_1
        + textwrap.dedent(
            """
        import signal, time
        from collections import Counter
        inside, outside = [], []

        def spy(signum, frame):
            try:
                taken = sys._getframe(1)
            except RuntimeError as e:
                inside.append(str(e))
                return
            if "seal.py" in taken.f_code.co_filename:
                inside.append("took the hook's frame in " + taken.f_code.co_name)
            else:
                outside.append(taken.f_code.co_name)

        before_the_seal(signal.SIGALRM, spy)
        signal.setitimer(signal.ITIMER_REAL, 0.0003, 0.0003)
        deadline = time.monotonic() + 60.0
        while len(inside) < 200 and time.monotonic() < deadline:
            compile("1", "<probe>", "eval")
        signal.setitimer(signal.ITIMER_REAL, 0)
        for said, count in Counter(inside).items():
            print(count, said, file=sys.stderr)
        print("landings:", len(inside), "outside:", len(outside) > 0, file=sys.stderr)
        """
        )
    )
    done = sealed(script)
    assert "outside: True" in done.stderr and "landings: 20" in done.stderr, done.stderr
    counts = {
        line.split(" ", 1)[1]: int(line.split(" ", 1)[0]) for line in done.stderr.splitlines() if line[0].isdigit()
    }
    inside_the_guard = counts.get("the grader's sandbox refused: code run inside the seal's hook", 0)
    around_it = counts.get("the grader's sandbox refused: reading the grader's own frames", 0)
    taken = sum(n for said, n in counts.items() if said.startswith("took the hook's frame in "))
    assert inside_the_guard > 0 and around_it > 0, done.stderr
    assert inside_the_guard + around_it > 2 * taken, done.stderr  # most landings refused
