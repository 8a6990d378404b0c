"""A small launcher for the ``launch_py/`` files (``ros2 launch`` has no PyPI wheel).

It keeps ROS 2 launch's vocabulary: a :class:`LaunchDescription` lists
:class:`NodeProcess` actions, each started as its own process with its output
prefixed by the node name.  Stopping follows ``ros2 launch``'s escalation:
on Ctrl-C or SIGTERM every node gets SIGINT, then SIGTERM, then SIGKILL,
and the whole shutdown ends within :data:`SHUTDOWN_TIMEOUT` s.  One step is
added before SIGKILL: SIGABRT, which Python's ``faulthandler`` (turned on in
every node with ``PYTHONFAULTHANDLER``) answers by printing where each of the
node's threads is, so a node that hangs in its clean-up says where.  A node marked
``required`` (ROS 1 launch's ``required="true"``) shuts everything down when
it exits.  Children also get SIGTERM if the launcher itself dies (Linux's
parent-death signal), so none is left behind.  Once every child is gone,
the files Fast DDS kept in ``/dev/shm`` for them and nobody uses any more
are removed (:func:`tutorial.ros.shm.remove_unused_fast_dds_shm`): a killed node leaves them.

Exit status: 0 when every node ended cleanly, 1 when any failed (its name
is printed), 130 is never used: an interrupted launch whose nodes all
stopped cleanly is a success.
"""

from __future__ import annotations

import argparse
import ctypes
import os
import resource
import signal
import subprocess
import sys
import threading
import time
from dataclasses import dataclass, field

from tutorial.ros.shm import SHM_DIR, fast_dds_shm_files, is_segment, remove_unused_fast_dds_shm

SHUTDOWN_TIMEOUT = 5.0  # s, from the stop request to the last child gone
_SIGINT_GRACE = 3.0  # s before SIGINT escalates to SIGTERM
_SIGTERM_GRACE = 1.2  # s before SIGTERM escalates to SIGABRT
_SIGABRT_GRACE = 0.3  # s for faulthandler to print the stacks before SIGKILL
PR_SET_PDEATHSIG = 1
_LIBRARY_ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # holds tutorial/
_SHM_SAMPLE_PERIOD = 1.0  # s between looks at every /dev/shm file the children map


@dataclass
class NodeProcess:
    """One node to launch, as its own process (the role of ``launch_ros.actions.Node``, named apart from it).

    Attributes:
        name: the node name; passed as ``--ros-args -r __node:=name`` and used as the output prefix.
        module: the Python module to run with ``python -m``.
        arguments: command-line arguments before ``--ros-args``.
        required: when it exits, shut the whole launch down.
    """

    name: str
    module: str
    arguments: list[str] = field(default_factory=list)
    required: bool = False

    def command(self) -> list[str]:
        """The node's command line: ``python -m module arguments --ros-args -r __node:=name``."""
        return [sys.executable, "-u", "-m", self.module, *self.arguments, "--ros-args", "-r", f"__node:={self.name}"]


@dataclass
class LaunchDescription:
    """The nodes of one launch, started in order."""

    nodes: list[NodeProcess]


def _die_with_parent() -> None:  # runs in the child between fork and exec
    try:
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGTERM)
    except OSError:
        pass


class Launch:
    """Runs a :class:`LaunchDescription` (main thread; output threads only copy lines).

    Args:
        description: what to start.
        out: where prefixed output lines go (a text stream).
    """

    def __init__(self, description: LaunchDescription, out=None):
        self.description = description
        self.out = out or sys.stdout
        self.procs: dict[str, subprocess.Popen] = {}
        self._print_lock = threading.Lock()
        self._threads: list[threading.Thread] = []
        # A plain flag, set by the signal handler in run(): a handler must not take a
        # lock (threading.Event.set() does) that the interrupted main thread may hold.
        self.stop_requested = False
        self.stopping = False
        self.failed: list[str] = []
        self.forced: dict[str, signal.Signals] = {}  # node -> the last signal the shutdown had to send past SIGTERM
        self.shm_files: set[str] = set()  # Fast DDS files in /dev/shm the children used (main thread)
        self._next_shm_sample = 0.0

    def _pump(self, name: str, stream) -> None:
        for raw in iter(stream.readline, b""):
            line = raw.decode(errors="replace").rstrip("\n")
            with self._print_lock:  # one whole line at a time from every node
                print(f"[{name}] {line}", file=self.out, flush=True)
        stream.close()

    def start(self) -> None:
        """Start every node of the description, in order, with its output prefixed (main thread)."""
        env = dict(os.environ)
        env.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
        # The nodes import this library from wherever the launcher found it (a clone need not be installed).
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [_LIBRARY_ROOT, env.get("PYTHONPATH")]))
        env["PYTHONUNBUFFERED"] = "1"
        env["PYTHONFAULTHANDLER"] = "1"  # a crash, or the launcher's SIGABRT, prints every thread's stack
        for node in self.description.nodes:
            proc = subprocess.Popen(
                node.command(),
                stdout=subprocess.PIPE,
                stderr=subprocess.STDOUT,
                stdin=subprocess.DEVNULL if node.module != "tutorial.tools.rtt_joy" else None,
                env=env,
                preexec_fn=_die_with_parent,
            )
            self.procs[node.name] = proc
            t = threading.Thread(target=self._pump, args=(node.name, proc.stdout), daemon=True)
            t.start()
            self._threads.append(t)
            self._say(f"started {node.name} (pid {proc.pid})")

    def _say(self, text: str) -> None:
        with self._print_lock:
            print(f"[launch] {text}", file=self.out, flush=True)

    def wait(self, poll: float = 0.05) -> int:
        """Wait until a required node exits, a node fails, or a stop is requested; then shut down."""
        required = {n.name for n in self.description.nodes if n.required}
        reported: set[str] = set()
        while not self.stop_requested:
            finished = {name: p.returncode for name, p in self.procs.items() if p.poll() is not None}
            for name, code in finished.items():
                if name not in reported:
                    reported.add(name)
                    self._say(f"{name} exited with code {code}")
                    if code != 0:
                        self.failed.append(name)
            if self.failed or required & finished.keys() or len(finished) == len(self.procs):
                break
            self.note_shared_memory(mapped=time.monotonic() >= self._next_shm_sample)
            time.sleep(poll)  # polling the children and the flag: a stop is seen within `poll` s
        return self.shutdown()

    def shutdown(self) -> int:
        """SIGINT, then SIGTERM, then SIGABRT (stacks), then SIGKILL; every child is gone within SHUTDOWN_TIMEOUT s."""
        self.stopping = True
        self.note_shared_memory()
        start = first = time.monotonic()
        stages = (
            (signal.SIGINT, _SIGINT_GRACE),
            (signal.SIGTERM, _SIGTERM_GRACE),
            (signal.SIGABRT, _SIGABRT_GRACE),
            (signal.SIGKILL, None),
        )
        for sig, grace in stages:
            alive = {name: p for name, p in self.procs.items() if p.poll() is None}
            if not alive:
                break
            if sig == signal.SIGABRT:
                self._say_hung(alive, time.monotonic() - first)
            for name, p in alive.items():
                p.send_signal(sig)
                if sig in (signal.SIGABRT, signal.SIGKILL):
                    self.forced[name] = sig
            deadline = start + (grace if grace is not None else SHUTDOWN_TIMEOUT - 0.2)
            for p in alive.values():
                try:
                    p.wait(max(0.0, deadline - time.monotonic()) if grace is not None else None)
                except subprocess.TimeoutExpired:
                    pass
            start = time.monotonic() if grace is not None else start
        for t in self._threads:
            t.join(1.0)
        self.remove_shared_memory()
        for name, p in self.procs.items():
            code = p.returncode
            if code not in (0, None) and name not in self.failed and code != -signal.SIGINT:
                self.failed.append(name)
        if self.failed:
            self._say("failed: " + ", ".join(f"{name} ({self._ended(name)})" for name in sorted(set(self.failed))))
            return 1
        self._say("all nodes stopped cleanly")
        return 0

    def _say_hung(self, alive: dict[str, subprocess.Popen], waited: float) -> None:
        """Name the nodes still running after SIGINT and SIGTERM, and keep SIGABRT from writing a core file.

        The core-file limit is the kernel's for a core written as a file; a
        system that pipes cores to a handler (systemd-coredump, apport) may
        still collect one.
        """
        self._say(
            f"{', '.join(alive)} did not stop within {waited:.1f} s: sending SIGABRT, "
            "so Python prints the stack of every thread (below, with the node's prefix)"
        )
        for p in alive.values():
            try:
                resource.prlimit(p.pid, resource.RLIMIT_CORE, (0, 0))
            except (OSError, ValueError):
                pass  # gone meanwhile, or not ours to change: the abort may then write a core file

    def _ended(self, name: str) -> str:
        """How node ``name`` ended, for the report: ``exit 1``, ``killed by SIGKILL``, or stopped by the launcher."""
        code = self.procs[name].returncode
        forced = self.forced.get(name)
        if forced is not None and code == -forced:
            return f"did not stop: the launcher sent {forced.name}"
        return _exit_status(code)

    def note_shared_memory(self, mapped: bool = True) -> None:
        """Add the Fast DDS files in /dev/shm the children use now to :attr:`shm_files` (main thread).

        The wait loop looks at the files they hold open (their own) at every
        poll, and at all they map once every :data:`_SHM_SAMPLE_PERIOD` s.
        """
        if mapped:
            self._next_shm_sample = time.monotonic() + _SHM_SAMPLE_PERIOD
        for p in self.procs.values():
            if p.poll() is None:  # a reaped child's pid may be another process's by now
                self.shm_files |= fast_dds_shm_files(p.pid, mapped)

    def remove_shared_memory(self) -> None:
        """Once every child is gone: remove the files they used that nobody uses any more (main thread).

        A node killed by a signal left its participant's files; the line says so.
        """
        removed = remove_unused_fast_dds_shm(self.shm_files)
        killed = sorted(
            name
            for name, p in self.procs.items()
            if p.returncode is not None and p.returncode < 0 and p.returncode != -signal.SIGINT
        )
        if killed and any(is_segment(name) for name in removed):
            self._say(
                f"removed {len(removed)} Fast DDS shared-memory files the nodes left in {SHM_DIR} "
                f"({', '.join(killed)} killed)"
            )


def _exit_status(code: int | None) -> str:
    """How a child ended, for the launcher's report: ``exit 1``, ``killed by SIGKILL``."""
    if code is not None and code < 0:
        return f"killed by {signal.Signals(-code).name}"
    return f"exit {code}"


def launch_parser(description: str) -> argparse.ArgumentParser:
    """The command line every launch file shares; ``description`` (the launch file's docstring) is shown as written,
    its example commands one to a line."""
    p = argparse.ArgumentParser(description=description, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--demo", action="store_true", help="scripted joystick input instead of a gamepad/keyboard")
    p.add_argument("--headless", action="store_true", help="no meshcat pages")
    p.add_argument(
        "--duration", type=float, default=None, metavar="SECONDS", help="stop after this many seconds of simulated time"
    )
    p.add_argument(
        "--record",
        default=None,
        metavar="FILE.mcap",
        help="also record the step's topics to FILE.mcap (rtt-bag record, node rtt_bag)",
    )
    p.add_argument(
        "--tf",
        action="store_true",
        help="with --record: the simulation also publishes the robot description and odometry (rtt-run "
        "--describe), and the recording holds them and /tf, /tf_static and /robot_description, so Foxglove and "
        "RViz2 replay the robot in 3D (rtt-bag record --tf)",
    )
    return p


def run(description: LaunchDescription) -> int:
    """Start the nodes, wait, stop them all; the process's exit status (main thread).

    Ctrl-C and SIGTERM both start the shutdown.
    """
    launch = Launch(description)

    def request_stop(signum, frame):
        launch.stop_requested = True  # no lock taken here: see Launch.__init__

    signal.signal(signal.SIGINT, request_stop)
    signal.signal(signal.SIGTERM, request_stop)
    launch.start()
    return launch.wait()
