"""The graded kernel's side of the judge: each check of :data:`~tutorial.tools.grading.judge.JUDGED` asks it.

:mod:`tutorial.tools.grading.sealed_kernel` calls :func:`install` before any
cell runs, when the grader gave the kernel a socket to the judge
(``RTT_JUDGE_FD``).  The check functions of those modules are then stand-ins:
``check_dpad_steering(dpad_track_velocities)`` asks the judge to run the
teacher's check, runs the answer on each input the judge sends (or, for a
class, each experiment the judge names, on the class) and sends back what it
returned or raised (:mod:`tutorial.tools.grading.wire`), and gives the
check's line as a :class:`JudgedResult`.  Nothing here decides a grade: the
judge writes the verdict, so an answer that replaces this code only loses its
own points.  Each run begins and ends with an ``rtt.judged`` audit event, at
which the kernel's seal compares the checks' modules and experiments with its
snapshot (an experiment replaced could report what a right class would).
The kernel's main thread (a cell's).
"""

from __future__ import annotations

import functools
import importlib
import os
import shutil
import socket
import sys
import tempfile
import threading

from tutorial.exercises.grader import EXPERIMENTS, CaseFailed, Result, not_done
from tutorial.tools.grading import wire
from tutorial.tools.grading.judge import JUDGED

ENV = "RTT_JUDGE_FD"


class JudgedResult(Result):
    """A check's result as the judge sent it.  ``require()`` raises as :class:`Result`'s does, telling no seal:
    the judge already wrote the verdict."""

    def require(self) -> Result:
        if not self.passed:
            raise AssertionError(self.wrapped())
        return self


class Judge:
    """The kernel's end of the socket.

    Each run of a check has an ``id``, which the judge's messages carry: one left over from a check the cell's
    timeout interrupted is skipped.  An RLock, because one check at a time asks; an answer that runs a check
    inside its own call ends the outer one (the judge gives it no verdict).
    """

    def __init__(self, sock: socket.socket):
        self._sock = sock
        self._reader = sock.makefile("rb")
        self._lock = threading.RLock()
        self._runs = 0

    def _send(self, message: dict) -> None:
        self._sock.sendall(wire.dumps(message))

    def run(self, name: str, answer) -> JudgedResult:
        """Have the judge run check ``name`` on ``answer``, running it on each input the judge sends.

        Raises:
            BaseException: what interrupted the answer or the wait (the cell's timeout's ``KeyboardInterrupt``),
                after telling the judge.
        """
        with self._lock:
            self._runs += 1
            run = self._runs
            sys.audit("rtt.judged", "begin", name)  # the seal compares the teacher's code with its snapshot
            try:
                self._send({"check": name, "id": run, "answer": getattr(answer, "__name__", "answer")})
                while True:
                    line = self._reader.readline(wire.MAX_LINE + 1)
                    if not line:
                        raise ConnectionError("the judge is gone")
                    message = wire.loads(line)
                    if message.get("id") != run:
                        continue  # the judge's for a check interrupted before
                    if "result" in message:
                        got = dict(message["result"])
                        passed, case = got.get("passed") is True, got.get("case")
                        exercise, said = str(got.get("exercise")), str(got.get("message"))
                        return JudgedResult(exercise, passed, said, case if type(case) is str else None)
                    if "observe" in message:  # a class's check: one of its experiments, on the class
                        self._send({"id": run, **_called(_experiment(answer, message["observe"]), message.get("args"))})
                    else:
                        self._send({"id": run, **_called(answer, message.get("call"))})
            except (OSError, wire.WireError) as exc:  # the judge gone or broken: no verdict, so 0 points
                return JudgedResult(name, False, f"the grader's judge could not run this check ({exc}).")
            except BaseException:
                try:
                    self._send({"abort": run})  # the judge drops the check: no verdict
                finally:
                    raise
            finally:
                sys.audit("rtt.judged", "end", name)  # again, its experiments run, however it ended


def _called(answer, call) -> dict:
    """What ``answer(*call)`` gave, as the judge's reply: what it returned, or what it raised (an ``Exception``;
    anything else, such as the cell's ``KeyboardInterrupt``, goes on up)."""
    folder = tempfile.mkdtemp(prefix="rtt-judged-")  # a file the check made for the answer (7.1's bag), removed after
    try:
        value = answer(*wire.decode(call, folder=folder))
    except Exception as exc:  # noqa: BLE001 - the answer's bug, said to the judge with its class's name
        said = {"type": type(exc).__name__, "builtin": type(exc).__module__ == "builtins", "not_done": not_done(exc)}
        if isinstance(exc, CaseFailed):  # an experiment's own failure (the run failed): it fails the case, as said
            said["case_failed"] = [str(exc.what)[: wire.MAX_CASE_TEXT], str(exc.hint)[: wire.MAX_CASE_TEXT]]
        try:
            said["args"] = wire.encode(list(exc.args))
        except wire.WireError:
            said["args"] = [str(exc)[: wire.MAX_TEXT]]
        return {"raised": said}
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    try:
        return {"return": wire.encode(value)}
    except wire.WireError as exc:
        return {"return": {"opaque": [type(value).__name__, f"<a value the grader cannot read: {exc}>", False]}}


def _experiment(cls, name):
    """Experiment ``name`` ("module:function", marked :func:`~tutorial.exercises.grader.experiment`) on ``cls``.

    Raises (when called): ``LookupError`` for a name that is no experiment.
    """
    found = EXPERIMENTS.get(name) if type(name) is str else None
    if found is None:
        return _no_experiment(name)
    return functools.partial(found, cls)


def _no_experiment(name):
    def refused(*args):
        raise LookupError(f"no such experiment of the checks: {str(name)[:80]}")

    return refused


def install(fd: int, modules: list[str] | None = None) -> None:
    """Put a stand-in asking the judge on ``fd`` (a connected Unix socket) in place of each judged check of
    ``modules`` (the assignment's check modules; None: all)."""
    os.set_inheritable(fd, False)  # an answer's subprocess gets no end of it
    judge = Judge(socket.socket(fileno=fd))
    for module, names in JUDGED.items():
        if modules is not None and module not in modules:
            continue
        loaded = importlib.import_module(module)
        for name in names:
            setattr(loaded, name, _asking(judge, name, getattr(loaded, name)))


def _asking(judge: Judge, name: str, teachers):
    def check(answer) -> JudgedResult:
        return judge.run(name, answer)

    check.__name__ = check.__qualname__ = name
    check.__doc__ = teachers.__doc__
    check.__wrapped__ = teachers  # the seal reads what the teacher's check uses from it, when it is installed
    return check
