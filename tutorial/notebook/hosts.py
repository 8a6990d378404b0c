"""Notebook 08's two hosts: the robot and the operator as network namespaces, and the programs on them.

:class:`TwoHosts` makes them (:class:`tutorial.network.hosts.Network`) when this
computer allows it (root, ``ip``, ``nft``, ``tc``), starts the tutorial's
programs on either host as separate processes, reads what they print, and
removes everything in :meth:`TwoHosts.close` (also what a notebook's earlier
kernel left).  Without root, :attr:`TwoHosts.problem` says why, and every
method that would need the hosts returns None, so each cell can say so
instead of failing.  Main thread (the notebook's) only.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import threading
import time

from tutorial.network.hosts import Host, Network, why_unavailable

ROOT_DIR = __import__("pathlib").Path(__file__).resolve().parents[2]


class Program:
    """A program running on a host, its output lines collected as they come (a reader thread)."""

    def __init__(self, host: Host, argv: list[str], env: dict[str, str]):
        self.host = host
        self.p = subprocess.Popen(
            host.command(argv),
            cwd=ROOT_DIR,
            env=host.env(**env),
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        self._lines: list[str] = []
        self._lock = threading.Lock()  # the reader thread appends, the notebook reads
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        for line in iter(self.p.stdout.readline, ""):
            with self._lock:
                self._lines.append(line.rstrip("\n"))

    def lines(self) -> list[str]:
        with self._lock:
            return list(self._lines)

    def records(self, event: str) -> list[dict]:
        """The JSON records of one event this program printed (``rtt-run --json``)."""
        out = []
        for line in self.lines():
            if line.startswith("{") and f'"event": "{event}"' in line:
                out.append(json.loads(line))
        return out

    def wait_for(self, predicate, timeout: float) -> bool:
        """Whether ``predicate(self)`` became true within ``timeout`` s (checked every 0.1 s)."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if predicate(self):
                return True
            time.sleep(0.1)  # polling another process's output under a deadline
        return bool(predicate(self))

    def stop(self) -> None:
        """Ctrl-C, then SIGKILL after 10 s."""
        if self.p.poll() is None:
            self.p.send_signal(signal.SIGINT)
            try:
                self.p.wait(10)
            except subprocess.TimeoutExpired:
                self.p.kill()
                self.p.wait()
        self._reader.join(5)


def python(module: str, *args: str) -> list[str]:
    return [sys.executable, "-u", "-m", module, *args]


class TwoHosts:
    """``robot`` (198.18.25.1) and ``operator`` (198.18.25.2), or the reason they cannot be made."""

    def __init__(self):
        self.problem = why_unavailable()
        self.net: Network | None = None
        self.programs: list[Program] = []
        if self.problem is None:
            self.net = Network(("robot", "operator")).open()

    @property
    def ok(self) -> bool:
        return self.net is not None

    def __getitem__(self, name: str) -> Host:
        return self.net[name]

    def describe(self) -> str:
        if not self.ok:
            return f"no hosts here: {self.problem}"
        return "\n".join(
            f"{h.name:<9} {h.address:<13} namespace {h.name}, its own /dev/shm" for h in self.net.hosts.values()
        )

    def start(self, host: str, argv: list[str], **env: str) -> Program:
        program = Program(self[host], argv, env)
        self.programs.append(program)
        return program

    def simulation(self, host: str = "robot", project: str = "project/step2.yaml", *args: str, **env: str) -> Program:
        return self.start(host, python("tutorial.tools.rtt_run", project, "--headless", "--json", *args), **env)

    def monitor(self, host: str = "operator", name: str = "rtt_viewer", **env: str) -> Program:
        project = "project/step3.yaml"
        argv = python("tutorial.tools.rtt_run", project, "--headless", "--json", "--ros-args", "-r", f"__node:={name}")
        return self.start(host, argv, **env)

    def image_viewer(self, host: str = "operator", transport: str = "raw") -> Program:
        out = f"{self[host].shm_dir}/camera_{transport}.png"
        return self.start(
            host, python("tutorial.tools.rtt_image", "--transport", transport, "--no-window", "--output", out)
        )

    def stop_all(self) -> None:
        """Stop every program started so far; the faults are cleared."""
        for program in self.programs:
            program.stop()
        self.programs.clear()
        if self.ok:
            for host in self.net.hosts.values():
                host.clear_faults()

    def renew(self) -> None:
        """Stop every program and make both hosts afresh (as if both computers had restarted)."""
        self.close()
        if self.problem is None:
            self.net = Network(("robot", "operator")).open()

    def close(self) -> None:
        """Stop the programs and remove the hosts (safe to call twice, and without hosts)."""
        self.stop_all()
        if self.net is not None:
            self.net.close()
            self.net = None


def publishers(monitor: Program) -> int:
    """The newest count of joint-state publishers the monitor reported (0 before any)."""
    seen = monitor.records("publishers")
    return seen[-1]["count"] if seen else 0


def states_applied(monitor: Program) -> int:
    statuses = monitor.records("status")
    return statuses[-1]["applied"] if statuses else 0


def image_rates(viewer: Program) -> list[float]:
    """The pictures per second ``rtt-image`` reported, once a second."""
    rates = []
    for line in viewer.lines():
        if " img/s, " in line:
            try:
                rates.append(float(line.split("] ", 1)[1].split(" img/s", 1)[0]))
            except (IndexError, ValueError):
                continue
    return rates
