"""A program running on one host (a network namespace), its output read as it comes.

Notebook 08 (:mod:`tutorial.notebook.two_hosts`) and the cross-host benchmark
(:mod:`benchmarks.experiments.network`) start the tutorial's programs on
their hosts with :class:`HostProgram`: stdout and stderr are one stream,
each line kept with the monotonic time it arrived, so a test or a
benchmark can tell *when* a monitor said "stale" as well as *that* it did.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

from tutorial.tools.network.hosts import Host

ROOT_DIR = Path(__file__).resolve().parents[3]  # the repository: tutorial/tools/network/host_program.py


class HostProgram:
    """``argv`` started on ``host`` (``ip netns exec``) in the project's folder, its output collected.

    Args:
        host: where it runs.
        argv: the command, e.g. ``[sys.executable, "-u", "-m", "tutorial.tools.rtt_run", ...]``.
        env: variables added to the host's environment (:meth:`Host.env`).

    Attributes:
        p: the ``subprocess.Popen``.

    A reader thread appends each output line; every other method may be
    called from any one thread (the notebook's, the benchmark's): the lock
    below is what the reader and that thread share.
    """

    def __init__(self, host: Host, argv: list[str], env: dict[str, str] | None = None):
        self.host = host
        self.argv = argv
        self.p = subprocess.Popen(
            host.command(argv),
            cwd=ROOT_DIR,
            env=host.env(**(env or {})),
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        self._lines: list[tuple[float, str]] = []  # (time.monotonic() on arrival, the line)
        self._lock = threading.Lock()  # the reader thread appends, the caller's thread reads
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        for line in iter(self.p.stdout.readline, ""):
            with self._lock:
                self._lines.append((time.monotonic(), line.rstrip("\n")))

    def timed_lines(self) -> list[tuple[float, str]]:
        """Every line so far with its arrival time (``time.monotonic()``, s)."""
        with self._lock:
            return list(self._lines)

    def lines(self) -> list[str]:
        """Every line so far."""
        return [line for _, line in self.timed_lines()]

    def text(self) -> str:
        """Every line so far, as one text."""
        return "\n".join(self.lines())

    def records(self, event: str) -> list[dict]:
        """The JSON records of one event this program printed (``rtt-run --json``), in order."""
        out = []
        for line in self.lines():
            if line.startswith("{") and f'"event": "{event}"' in line:
                try:
                    out.append(json.loads(line))
                except ValueError:
                    continue  # a line cut short as the program was killed
        return out

    def first(self, predicate, timeout: float) -> float | None:
        """The arrival time of the first line for which ``predicate(line)`` holds, waiting up to ``timeout`` s.

        None when no such line came in time, or the program ended without one.
        """
        deadline = time.monotonic() + timeout
        while True:
            for t, line in self.timed_lines():
                if predicate(line):
                    return t
            if time.monotonic() >= deadline or (self.p.poll() is not None and not self._reader.is_alive()):
                return None
            time.sleep(0.02)  # polling another process's output: a deadline loop

    @property
    def running(self) -> bool:
        """The program has not ended (nor been stopped)."""
        return self.p.poll() is None

    def wait_for(self, predicate, timeout: float) -> bool:
        """Whether ``predicate(self)`` became true within ``timeout`` s (checked every 0.1 s)."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if predicate(self):
                return True
            time.sleep(0.1)  # polling another process's output under a deadline
        return bool(predicate(self))

    def stop(self, timeout: float = 10.0) -> int:
        """Ctrl-C (SIGINT), then SIGKILL after ``timeout`` s; its exit status."""
        if self.p.poll() is None:
            self.p.send_signal(signal.SIGINT)
            try:
                self.p.wait(timeout)
            except subprocess.TimeoutExpired:
                self.p.kill()
                self.p.wait()
        self._reader.join(5)
        return self.p.returncode


def python(module: str, *args: str) -> list[str]:
    """The command that runs ``python -u -m module args...`` with this interpreter."""
    return [sys.executable, "-u", "-m", module, *args]
