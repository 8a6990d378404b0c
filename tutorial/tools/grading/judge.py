"""``python -I -m tutorial.tools.grading.judge FD VERDICTS [MODULES]``: the teacher's checks, in a process of their own.

An answer and a check in one process are no wall: the answer can reach the
check's memory (:mod:`tutorial.tools.grading.seal` says how).  So, while
grading, the checks of :data:`JUDGED` (every exercise's) run here, in the judge, which
:class:`tutorial.tools.grading.sandbox.SandboxedKernelManager` starts beside
each graded kernel, outside its sandbox.  The judge imports the teacher's
checks (those of the assignment's check ``MODULES``, comma-separated) before the kernel runs any cell, keeps the
learner's seed of hidden
cases (read from its standard input, never an argument another user can read),
and shares with the kernel only a socket (``FD``), over which data crosses
(:mod:`tutorial.tools.grading.wire`):

1. the kernel's test cell calls the check (:mod:`tutorial.tools.grading.judged`
   put a stand-in in its place), which asks: ``{"check": name}``;
2. the judge runs the teacher's check with a stand-in for the answer
   (:class:`Answer`): each call of it sends the arguments, ``{"call": [...]}``,
   and the kernel runs the learner's function on them and sends back what it
   returned or raised; a class's check observes it instead
   (:func:`tutorial.exercises.grader.observe`): ``{"observe": experiment,
   "args": [...]}``, and the kernel runs that experiment (a function of the
   checks' module) on the learner's class and sends back what it saw, as
   data, or what it raised;
3. the judge writes the verdict to ``VERDICTS`` (which the grader alone reads:
   ``course/sandboxing.py``) and sends the kernel the check's line to show.

The expected values, the hidden cases' rules and the seed never leave this
process; an answer learns a hidden case's input, as any function does, and
only whether the check passed.  Each check runs once: asked again, the judge
refuses (its first verdict stands), so no answer can search the hidden cases
by trying.  The kernel can say anything on the socket; whatever it says, the
worst it gets is the verdict its answers earn.

Its lines in ``VERDICTS`` begin with ``judged``: ``judged begin N``,
``judged verdict N PASSED INTACT WHY``, ``judged note FLAG WHAT N``, each
signed with a key of the grader's (read after the seed), which the kernel never holds.  Runs as
the grader (it runs only the teacher's code); one thread.
"""

from __future__ import annotations

import builtins
import hmac
import os
import re
import socket
import sys
import threading

from tutorial.exercises.grader import CaseFailed, Result
from tutorial.tools.grading import wire

# The checks the judge runs, by module: every exercise's.  A function's check calls it across the socket; a
# class's check has the kernel run its experiments on the class (tutorial.exercises.grader.observe).
JUDGED = {
    "tutorial.exercises.step1_tank_controller": ("check_dpad_steering", "check_shot_counter"),
    "tutorial.exercises.step2_joint_state_publisher": ("check_selected_joints", "check_pose_publisher"),
    "tutorial.exercises.step3_viewer": ("check_own_matcher", "check_wrong_model"),
    "tutorial.exercises.step4_imu_publisher": ("check_peak_publisher", "check_collision_reporter"),
    "tutorial.exercises.step5_imu_viewer": ("check_horizontal_arrow", "check_in_order"),
    "tutorial.exercises.step6_camera": ("check_gray_camera", "check_camera_info"),
    "tutorial.exercises.record_and_replay": ("check_release_times", "check_peak_speed"),
    "tutorial.exercises.across_machines": ("check_lossy_link_qos", "check_camera_settings"),
    "tutorial.exercises.stock_ros2_tools": ("check_lookup",),
    "tutorial.exercises.parameters_and_services": ("check_judge_rate", "check_switch_tracks"),
    "tutorial.exercises.managed_nodes_and_actions": ("check_after",),
}
JUDGED_NAMES = frozenset(n for names in JUDGED.values() for n in names)
NUMBER = re.compile(r"Exercise (\d+\.\d+)")
BREAKS = re.compile(r"[\t\n\r\x0b\x0c\x1c-\x1e\x85\u2028\u2029]")  # a tab, and every line break of str.splitlines()
MAX_FIELD = 500  # characters of one field of a line
MAX_NOTES, MAX_NOTES_IN_ALL = 5, 50  # notes written for one check, and in all (the rest are counted)
GONE = "the grading kernel is gone"


class Interrupted(BaseException):
    """The kernel stopped running the answer (the cell's timeout interrupted it): the check ends, no verdict."""


class Answer:
    """The judge's stand-in for the learner's function: a call sends its arguments to the kernel and returns
    what the answer returned there (built from data), or raises what it raised (its class's name and message).

    Raises (from a call): ``NotImplementedError`` for the learner's stub; a built-in exception as itself (a
    ``KeyError`` a statement asks for); any other as an ``Exception`` subclass of the same name;
    :class:`Interrupted` when the kernel says it was interrupted; ``ConnectionError`` when the kernel is gone.
    """

    def __init__(self, channel: Channel, name: str, run):
        self._channel, self._run = channel, run
        self.__name__ = self.__qualname__ = name

    def __call__(self, *args):
        return self._reply(self._channel.ask({"id": self._run, "call": [wire.encode(a) for a in args]}))

    def observe(self, experiment, *args):
        """What ``experiment(the learner's class, *args)`` gave in the kernel (a check's
        :func:`~tutorial.exercises.grader.observe`, while the judge runs it), or what it raised, as a call's."""
        name = f"{experiment.__module__}:{experiment.__qualname__}"
        return self._reply(
            self._channel.ask({"id": self._run, "observe": name, "args": [wire.encode(a) for a in args]})
        )

    def _reply(self, reply: dict):
        if "check" in reply:  # the kernel went on to another check (this one's cell was interrupted)
            self._channel.push_back(reply)
            raise Interrupted
        if "return" in reply:
            try:
                value = wire.decode(reply["return"])
            except wire.WireError as exc:  # never what the kernel's own encoder sends
                self._channel.note("tampering", f"the kernel sent back what is no value ({exc})")
                raise
            self._channel.note_own_classes(value)
            return value
        if "raised" in reply:
            raise _exception(reply["raised"])
        if "abort" in reply:
            raise Interrupted
        raise wire.WireError("the kernel answered a call with neither a value nor an exception")


def _exception(said) -> Exception:
    """The exception an answer raised, from what the kernel said of it (``{"type", "builtin", "args",
    "not_done"}``): never its class, only a class of its name."""
    said = dict(said)
    name = str(said.get("type", "Exception"))
    name = name if wire.NAME.fullmatch(name) else "Exception"
    try:
        args = tuple(wire.decode(said.get("args", [])))
    except wire.WireError:
        args = ()
    args = tuple(a if type(a) in (str, int, float, bool) or a is None else repr(a)[: wire.MAX_TEXT] for a in args)
    if said.get("not_done") is True:
        return NotImplementedError(*args)
    failed = said.get("case_failed")
    if type(failed) is list and len(failed) == 2:  # the experiment's run failed: the case fails, as it said
        return CaseFailed(*(str(text)[: wire.MAX_CASE_TEXT] for text in failed))
    builtin = getattr(builtins, name, None)
    if said.get("builtin") is True and isinstance(builtin, type) and issubclass(builtin, Exception):
        try:
            return builtin(*args)
        except Exception:  # noqa: BLE001 - arguments that class will not take (an OSError's): its text alone
            return builtin(" ".join(map(str, args)))
    return type(name, (Exception,), {"__module__": "answer"})(*args)


class Channel:
    """The judge's end of the socket: one message out, the kernel's reply in.  A lock, because rclpy may call
    an :class:`Answer` from an executor's thread while a check waits on the main one (10.1's node)."""

    def __init__(self, sock: socket.socket, verdicts: str, key: bytes = b""):
        self._sock = sock
        self._reader = sock.makefile("rb")
        self._lock = threading.Lock()
        self._fd = os.open(verdicts, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o600)
        self._key = key
        self._back: list[dict] = []  # a request read while a check waited for its answer
        self.number: str | None = None  # the exercise of the check now running
        self.notes: list[str] = []  # what the kernel did wrong during it (tampering): the first MAX_NOTES
        self.noted = 0  # notes in all, written or not
        self.more = 0  # notes of the check now running past its first MAX_NOTES, only counted
        self.answer: Answer | None = None  # the stand-in of the check now running, whose experiments it observes

    def send(self, message: dict) -> None:
        self._sock.sendall(wire.dumps(message))

    def receive(self) -> dict | None:
        """The kernel's next message; None when it is gone.

        Raises:
            wire.WireError: a line that is no message.
        """
        if self._back:
            return self._back.pop()
        line = self._reader.readline(wire.MAX_LINE + 1)
        if not line:
            return None
        if not line.endswith(b"\n"):
            while line and not line.endswith(b"\n"):  # the rest of it read and dropped: the next line is a message
                line = self._reader.readline(wire.MAX_LINE + 1)
            raise wire.WireError(f"a message of more than {wire.MAX_LINE} bytes")
        return wire.loads(line)

    def push_back(self, message: dict) -> None:
        """``message`` is the next :meth:`receive` gives."""
        self._back.append(message)

    def ask(self, message: dict) -> dict:
        with self._lock:
            self.send(message)
            reply = self.receive()
        if reply is None:
            raise ConnectionError(GONE)
        return reply

    def write(self, *fields: str) -> None:
        """One line in the verdict file, signed (:func:`signed`): a tab or any line break (``str.splitlines()``'s)
        in a field a space.  The seal's reader writes the kernel's lines into the same file, so a line cut short
        (the disk full) could be finished by one of theirs: unsigned then, and the grader takes no such line."""
        clean = [BREAKS.sub(" ", str(f))[:MAX_FIELD] for f in fields]
        os.write(self._fd, (signed(self._key, "\t".join(["judged", *clean])) + "\n").encode("utf-8", "replace"))

    def note(self, flag: str, what: str) -> None:
        """A note in the verdict file; past :data:`MAX_NOTES` of a check, or between checks, only counted."""
        self.noted += 1
        if len(self.notes) >= MAX_NOTES:
            self.more += 1  # counted, never kept: an answer could send junk without end
            return
        self.notes.append(what)
        if self.noted <= MAX_NOTES_IN_ALL:
            self.write("note", flag, what, self.number or "")

    def note_own_classes(self, value) -> None:
        """Note an answer's value holding an object of a class of its own that compares as it likes."""
        todo = [value]
        while todo:
            v = todo.pop()
            if isinstance(v, wire.Opaque) and v.own_eq:
                self.note("tampering", f"an answer returned a {v.kind}, a class of its own that compares as it likes")
                return
            if type(v) in (list, tuple):
                todo += v
            elif type(v) is dict:
                todo += [*v.keys(), *v.values()]


def checks(modules: list[str] | None = None) -> dict:
    """The teacher's checks of :data:`JUDGED` in ``modules`` (the assignment's check modules; None: all), by
    name, imported now (before the kernel runs any cell)."""
    import importlib

    found = {}
    for module, names in JUDGED.items():
        if modules is not None and module not in modules:
            continue  # another assignment's: not imported (about 0.15 s a module)
        loaded = importlib.import_module(module)
        found.update({name: getattr(loaded, name) for name in names})
    return found


def serve(channel: Channel, found: dict) -> None:
    """Answer the kernel's requests until it is gone: each check once, its verdict written, its line sent."""
    done: set[str] = set()
    while True:
        try:
            request = channel.receive()
        except wire.WireError as exc:
            channel.note("tampering", f"the kernel sent what is no request ({exc})")
            continue
        if request is None:
            return
        if "check" not in request:
            continue  # an abort of a check already dropped, or a reply to it
        name, run = request.get("check"), request.get("id")
        if type(name) is not str or name not in found:
            channel.note("tampering", f"the kernel asked for no check of the judge's: {str(name)[:60]!r}")
            channel.send({"id": run, "result": _refusal(str(name)[:60], "no such check while grading.")})
            continue
        if name in done:
            channel.note("checked again", f"{name} asked for again: its first verdict stands")
            said = "this check already ran while grading; its first verdict stands."
            channel.send({"id": run, "result": _refusal(name, said)})
            continue
        done.add(name)
        channel.number, channel.notes, channel.more = None, [], 0
        answer = channel.answer = Answer(channel, _answer_name(request.get("answer")), run)
        try:
            result = found[name](answer)
        except Interrupted:
            continue  # no verdict: the exercise gets 0 (the cell's timeout is flagged from the notebook)
        except ConnectionError:
            return
        except Exception as exc:  # noqa: BLE001 - the check's own error outside its cases: it fails, the rest run
            said = f"the check could not judge this answer ({type(exc).__name__}: {exc})."
            result = Result(name, False, said)
        why = "; ".join(channel.notes) + (f" (and {channel.more} more)" if channel.more else "")
        channel.write("verdict", channel.number, int(result.passed), int(not channel.notes), why)
        try:
            said = {k: getattr(result, k) for k in ("exercise", "passed", "message", "case")}
            channel.send({"id": run, "result": said})
        except OSError:
            return


def signed(key: bytes, body: str) -> str:
    """``body`` and its signature (HMAC-SHA256 with ``key``, hex), tab-separated: how the judge writes a line."""
    return body + "\t" + hmac.new(key, body.encode("utf-8", "replace"), "sha256").hexdigest()


def genuine(key: bytes, line: str) -> str | None:
    """``line``'s body if ``key`` signed it (:func:`signed`), else None (a line cut short, or not the judge's)."""
    body, _, mac = line.rpartition("\t")
    good = hmac.new(key, body.encode("utf-8", "replace"), "sha256").hexdigest()
    return body if hmac.compare_digest(mac.encode("utf-8", "replace"), good.encode()) else None


def _refusal(name: str, why: str) -> dict:
    return {"exercise": name, "passed": False, "message": why, "case": None}


def _answer_name(name) -> str:
    return name if type(name) is str and wire.NAME.fullmatch(name) else "answer"


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    fd, verdicts = int(argv[0]), argv[1]
    modules = argv[2].split(",") if len(argv) > 2 else None
    seed = sys.stdin.readline().strip()  # the learner's seed of hidden cases: the grader's, on a pipe
    key = bytes.fromhex(sys.stdin.readline().strip())  # what the judge signs its lines with: the grader's too
    sock = socket.socket(fileno=fd)
    channel = Channel(sock, verdicts, key)

    def hook(event: str, args: tuple) -> None:
        """The checks' own events, as the seal would take them in a kernel: the seed given, each check's start
        written down (a check that never ends, its cell stopped, leaves its begin without a verdict)."""
        if event == "rtt.seed" and seed and type(args[0]) is list:
            args[0].append(seed)
        elif event == "rtt.observe" and channel.answer is not None and type(args[0]) is list:
            args[0].append(channel.answer.observe)  # a class's experiment: run where the class is, the kernel
        elif event == "rtt.check_begin":
            found = NUMBER.match(str(args[0]))
            channel.number = found.group(1) if found else "?"
            channel.write("begin", channel.number)

    found = checks(modules)
    sys.addaudithook(hook)
    import rclpy

    rclpy.init()  # 10.1's check sets its parameter on a node of its own
    try:
        serve(channel, found)
    finally:
        rclpy.try_shutdown()
        sock.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
