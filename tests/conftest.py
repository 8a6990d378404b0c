"""Test set-up: every ROS 2 participant of this session stays on this machine; each test has one tier.

``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`` keeps discovery traffic on the
loopback interface, and a ``ROS_DOMAIN_ID`` unique to this test session keeps
it apart from any other session running here.  Both are set before rclpy is
imported and are inherited by every process a test starts.  (The network
tier's own hosts, network namespaces the test makes, are the one place
``SUBNET`` is used: ``tests/netns.py``.)

Tiers, as pytest markers (``pytest -m unit``, ``make test-fast``):

===============  ==============================================================
tier             what a test of it does
===============  ==============================================================
``unit``         plain Python, MuJoCo and files: no ROS context, no process
``ros``          rclpy in this process (the ``ros`` or ``node`` fixture)
``cross_process`` our programs as separate processes, talking over ROS 2
``launch``       the ``launch_py/`` files, every node a process
``browser``      a real (headless) Chromium: meshcat pages, JupyterLab
``notebooks``    the notebooks, cell by cell, against their saved outputs (nbval)
``network``      two or three hosts in network namespaces, with faults (root only)
===============  ==============================================================

A test's tier is the tier marker closest to it (the function's, else its
module's ``pytestmark``); a test with none is ``cross_process`` when it uses
the ``procs`` fixture, ``ros`` when it uses ``ros`` or ``node``, else ``unit``.
A test that ends up with two tiers stops the collection.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ["ROS_DOMAIN_ID"] = str(1 + (os.getpid() * 7919 + int(time.time())) % 100)
os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")
os.environ.setdefault("PYTHONFAULTHANDLER", "1")  # a hung child prints its threads' stacks on SIGABRT
os.environ.setdefault("RTT_TEST_MODE", "1")  # notebooks run under nbval: shorter interactive runs

from tutorial.notebook.session import wait_until  # noqa: E402,F401 - after the environment; one polling helper for all

ROOT = Path(__file__).resolve().parent.parent
PROJECT = ROOT / "project"
MODEL = ROOT / "model"


class ViewerNode:
    """A stand-in for a viewer's rclpy node, for its controllers' tests without ROS: it keeps the subscriptions
    made (each a namespace of what ``create_subscription`` was given) and those destroyed, in order."""

    def __init__(self):
        self.subscriptions, self.destroyed = [], []

    def get_fully_qualified_name(self):
        return "/rtt_viewer"

    def create_subscription(self, msg_type, topic, callback, qos, event_callbacks=None):
        from types import SimpleNamespace

        made = SimpleNamespace(
            msg_type=msg_type, topic=topic, topic_name=topic, callback=callback, qos=qos, events=event_callbacks
        )
        self.subscriptions.append(made)
        return made

    def destroy_subscription(self, subscription):
        self.destroyed.append(subscription)


TIERS = ("unit", "ros", "cross_process", "launch", "browser", "notebooks", "network")

# The session's clean-up of Fast DDS's files in /dev/shm: entered when the session starts, left when it ends.
_SHM_CLEAN_UP = contextlib.ExitStack()


def pytest_sessionstart(session) -> None:
    from tutorial.ros.shm import new_leftovers_removed

    _SHM_CLEAN_UP.enter_context(new_leftovers_removed())


def pytest_sessionfinish(session, exitstatus) -> None:
    """Remove the Fast DDS files in /dev/shm that appeared during the session and no live process uses.

    Several tests kill a node with SIGKILL on purpose (a crash, a recorder
    killed), and a killed participant leaves its files: whoever left them,
    they are nobody's any more (:func:`tutorial.ros.shm.new_leftovers_removed`).
    """
    _SHM_CLEAN_UP.close()


def pytest_configure(config):
    for tier in TIERS:
        config.addinivalue_line("markers", f"{tier}: the {tier.replace('_', '-')} tier (see tests/conftest.py)")


NEEDS_HOSTS = "# NEEDS_HOSTS"  # the first line of a notebook cell that runs programs on network hosts


def skip_cells_needing_hosts(items) -> None:
    """Skip, saying why, the notebook cells that need network hosts where none can be made.

    Notebook 08 runs programs on two hosts made of network namespaces
    (:mod:`tutorial.tools.network.hosts`, root only).  Its cells that need them begin
    with ``# NEEDS_HOSTS``; without hosts they print ``no hosts here: <why>``,
    not their saved outputs (from a run that had hosts), so nbval skips
    exactly those cells.  Every other cell, the exercises too, is checked.
    """
    needing = [i for i in items if NEEDS_HOSTS in getattr(getattr(i, "cell", None), "source", "")]
    if not needing:
        return
    from tutorial.tools.network.hosts import why_unavailable

    problem = why_unavailable()
    if problem is not None:
        for item in needing:
            item.add_marker(pytest.mark.skip(reason=f"this cell needs its own network hosts: {problem}"))


def pytest_collection_modifyitems(config, items):
    """Give every test exactly one tier marker (see the module's docstring); skip cells that need absent hosts."""
    skip_cells_needing_hosts(items)
    for item in items:
        marked = {m.name for m in item.iter_markers() if m.name in TIERS}
        if len(marked) > 1:
            raise pytest.UsageError(f"{item.nodeid} has more than one tier: {sorted(marked)}")
        if marked:
            continue
        fixtures = set(getattr(item, "fixturenames", ()))
        if item.path.suffix == ".ipynb":
            tier = "notebooks"
        elif "procs" in fixtures:
            tier = "cross_process"
        elif fixtures & {"ros", "node"}:
            tier = "ros"
        else:
            tier = "unit"
        item.add_marker(getattr(pytest.mark, tier))


HEARD: list = []  # what the grading kernel's seal would hear of the checks (an audit hook: one per process)
SEED: list = []  # while it holds a seed, the hook puts it in the checks' seed box (rtt.seed), as the seal does
KERNEL: list = []  # while it holds a callable, the hook puts it in observe()'s box (rtt.observe), as the judge does


def _hear(event: str, args: tuple) -> None:
    if event.startswith("rtt."):
        HEARD.append((event, args))
        if event == "rtt.seed" and SEED:
            args[0].append(SEED[0])
        if event == "rtt.observe" and KERNEL:
            args[0].append(KERNEL[0])


def hear_the_checks() -> list:
    """HEARD, emptied: from now on it gets each (event, args) of the checks' audit events for the seal."""
    if not getattr(sys, "_rtt_test_hears_checks", False):
        sys.addaudithook(_hear)
        sys._rtt_test_hears_checks = True
    HEARD.clear()
    return HEARD


@pytest.fixture(scope="session")
def ros():
    """rclpy initialised once for the session's in-process tests."""
    import rclpy

    rclpy.init()
    yield rclpy
    rclpy.try_shutdown()


@pytest.fixture
def node(ros, request):
    """A fresh node named after the test."""
    n = ros.create_node("test_" + request.node.name.replace("[", "_").replace("]", "").replace("-", "_")[:40])
    yield n
    n.destroy_node()


def publishers_seen(proc) -> int:
    """The newest publisher count a viewer reported (its ``publishers`` records), 0 before any.

    Waiting for it is how a test knows the viewer's side has matched a
    publisher: discovery is not symmetric, and a publisher that already
    counts the viewer may still send into the void.
    """
    seen = proc.records("publishers")
    return seen[-1]["count"] if seen else 0


def publish_and_wait_applied(pub, view, names, positions, applied: int, timeout: float = 30) -> None:
    """Publish one ``JointState`` and wait until the viewer's status line counts ``applied`` messages applied.

    The status line comes once a second.  Sending the next message only after
    this makes a keep-last-1 reader unable to have one replaced (a stalled
    viewer) or coalesced (one applied late); a lost message fails the wait.
    """
    from sensor_msgs.msg import JointState

    msg = JointState()
    msg.name, msg.position = names, positions
    pub.publish(msg)
    view.wait_for_line(
        lambda line: (
            line.startswith("{")
            and json.loads(line).get("event") == "status"
            and json.loads(line)["applied"] >= applied
        ),
        timeout=timeout,
    )


def module_command(module: str, *args: str) -> list[str]:
    """``python -m module args`` with this interpreter."""
    return [sys.executable, "-u", "-m", module, *args]


def ros2(*args: str, timeout: float = 60) -> subprocess.CompletedProcess:
    """``rtt-ros2 ARGS`` as a learner types it, to its end: its exit status, output and errors."""
    command = [sys.executable, "-m", "tutorial.tools.rtt_ros2", *args]
    return subprocess.run(command, capture_output=True, text=True, timeout=timeout, cwd=ROOT)


class Proc:
    """A child process whose output lines are collected as they come; killed at the end of the test."""

    def __init__(self, cmd: list[str], **kw):
        import threading

        self.cmd = cmd
        self.p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT, **kw)
        self.lines: list[str] = []
        self._cond = threading.Condition()
        self._err: list[str] = []
        self._threads = [
            threading.Thread(target=self._read, args=(self.p.stdout, self.lines), daemon=True),
            threading.Thread(target=self._read, args=(self.p.stderr, self._err), daemon=True),
        ]
        for t in self._threads:
            t.start()

    def _read(self, stream, sink) -> None:
        for line in iter(stream.readline, ""):
            with self._cond:
                sink.append(line.rstrip("\n"))
                self._cond.notify_all()
        stream.close()

    @property
    def out(self) -> str:
        with self._cond:
            return "\n".join(self.lines)

    @property
    def err(self) -> str:
        with self._cond:
            return "\n".join(self._err)

    def count(self, predicate) -> int:
        """How many output lines so far satisfy ``predicate``."""
        with self._cond:
            return sum(1 for line in self.lines if predicate(line))

    def wait_for_count(self, predicate, n: int, timeout: float) -> str:
        """Wait until ``n`` output lines satisfy ``predicate``; the n-th. Fails after ``timeout`` s."""
        deadline = time.monotonic() + timeout
        with self._cond:
            while True:
                matches = [line for line in self.lines if predicate(line)]
                if len(matches) >= n:
                    return matches[n - 1]
                left = deadline - time.monotonic()
                if left <= 0 or (self.p.poll() is not None and not any(t.is_alive() for t in self._threads)):
                    raise AssertionError(f"not {n} such lines from {self.cmd} in {timeout} s:\n{self.out}\n{self.err}")
                self._cond.wait(min(left, 0.2))

    def wait_for_line(self, predicate, timeout: float) -> str:
        """The first output line for which ``predicate(line)`` is true; fails after ``timeout`` s."""
        return self.wait_for_count(predicate, 1, timeout)

    def wait(self, timeout: float) -> int:
        try:
            self.p.wait(timeout)
        except subprocess.TimeoutExpired:
            # SIGABRT first: with faulthandler on (PYTHONFAULTHANDLER, set above),
            # Python prints every thread's stack, which says where it hung.
            self._signal_then_kill(signal.SIGABRT)
            for t in self._threads:
                t.join(5)
            raise AssertionError(f"{self.cmd} did not finish in {timeout} s\n{self.out}\n{self.err}") from None
        for t in self._threads:
            t.join(10)
        return self.p.returncode

    def json_records(self) -> list[dict]:
        return [json.loads(line) for line in self.out.splitlines() if line.startswith("{")]

    def records(self, event: str) -> list[dict]:
        """The JSON output records of one ``event`` kind so far, oldest first."""
        return [r for r in self.json_records() if r.get("event") == event]

    def summary(self) -> dict:
        records = self.records("summary")
        assert records, f"no summary from {self.cmd}:\n{self.out}\n{self.err}"
        return records[-1]

    def kill(self) -> None:
        """Stop it at the end of a test: Ctrl-C first, so its node removes its Fast DDS
        shared-memory files (a SIGKILLed node leaves them in /dev/shm), then SIGKILL after 5 s."""
        if self.p.poll() is None:
            self._signal_then_kill(signal.SIGINT)

    def _signal_then_kill(self, sig: int, grace: float = 5.0) -> None:
        """Send ``sig``, wait ``grace`` s for the process to end, then SIGKILL it and reap it."""
        self.p.send_signal(sig)
        try:
            self.p.wait(grace)
        except subprocess.TimeoutExpired:
            self.p.kill()
            self.p.wait()


@pytest.fixture
def procs():
    """Start child processes with ``procs(cmd)``; any still running at the end are killed."""
    started: list[Proc] = []

    def start(cmd, **kw) -> Proc:
        p = Proc(cmd, **kw)
        started.append(p)
        return p

    yield start
    for p in started:
        p.kill()
