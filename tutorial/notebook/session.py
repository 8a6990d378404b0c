"""The notebook session: ROS once per kernel, and a reset that stops what cells started.

Every notebook starts with::

    from tutorial.notebook.session import init_ros, reset, TEST_MODE

Threads in a notebook: the kernel's main thread runs the cells and the
widget callbacks.  Things that run on after a cell has finished (a
simulation, a live plot, a teleop panel's node) register here when they
start; :func:`reset` closes them all, newest first, so a section can be
re-run from its first cell.  Each closed thing leaves its output saying
so: a recording in place of a live 3D view, a disabled panel with a line
saying why.

``RTT_TEST_MODE=1`` (set by the test suite) shortens the interactive runs;
it never changes what a checked output says.
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable
from pathlib import Path

from tutorial.ros import env as ros_env

TEST_MODE = os.environ.get("RTT_TEST_MODE") == "1"
ROOT = Path(__file__).resolve().parent.parent.parent
PROJECT = ROOT / "project"
MODEL = ROOT / "model"

_active: list = []  # things with a .close() started from cells, oldest first


def init_ros() -> None:
    """Initialise rclpy once per kernel, without its signal handlers (kernel thread).

    rclpy would otherwise take over SIGINT and shut ROS down when you press
    the notebook's "interrupt" button.  Calling it again does nothing.  On a class's hub it warns (stderr)
    when ``ROS_DOMAIN_ID`` is not the learner's own domain (:func:`tutorial.ros.env.assigned_domain_warning`),
    and says when a kernel of this server was stopped for going over its memory limit
    (:func:`memory_limit_note`) or the learner's last server was stopped for want of use (:func:`idle_stop_note`).
    """
    import rclpy
    from rclpy.signals import SignalHandlerOptions

    ros_env.use_localhost_by_default()
    if not rclpy.ok():
        # a domain set by hand since the kernel started (a learner's shutdown() and init again) is said here
        ros_env.warn_if_not_assigned_domain()
        rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
        for note in (memory_limit_note(), idle_stop_note()):
            if note:
                print(note, file=sys.stderr)


def memory_limit_note(cgroup_root: Path = Path("/sys/fs/cgroup/memory"), seen: Path | None = None) -> str:
    """What to tell a learner whose server holds a kernel stopped at its memory limit since they were last
    told; "" if none was.

    On a class's hub each learner's server is in a memory cgroup of its own (``course/limits.py``, or the
    learner's container), whose ``memory.oom_control`` counts the processes stopped for going over
    ``MEM_LIMIT`` bytes.  ``seen`` (default ``~/.cache/ros-tank-tutorial/memory-limit``) keeps the count
    already told, so each stop is told once.  Any thread.
    """
    seen = seen or Path.home() / ".cache" / "ros-tank-tutorial" / "memory-limit"
    try:
        line = next(x for x in Path("/proc/self/cgroup").read_text().splitlines() if x.split(":")[1] == "memory")
        group = cgroup_root / line.split(":", 2)[2].lstrip("/")
        if not group.exists():  # in a container, whose own group is the root of what it sees
            group = cgroup_root
        control = (group / "memory.oom_control").read_text()
        killed = int(control.split("oom_kill ")[1].split()[0])
        limit = int(os.environ["MEM_LIMIT"])
    except (OSError, StopIteration, IndexError, KeyError, ValueError):
        return ""
    told = f"{group} {killed}"
    try:
        before = seen.read_text().split()
        if len(before) == 2 and before[0] == str(group) and int(before[1]) >= killed:
            return ""
    except (OSError, ValueError):
        pass
    if not killed:
        return ""
    try:
        seen.parent.mkdir(parents=True, exist_ok=True)
        seen.write_text(told)
    except OSError:
        pass  # told again next time: better than never
    return (
        f"Note: a process of your server was stopped for using more than its memory limit "
        f"({limit / 1024**3:.1f} GiB), and Jupyter restarted the kernel: that is why the earlier cells' "
        "results and runs are gone. Use less memory (smaller arrays, fewer runs at once, reset() between runs)."
    )


def idle_stop_note(seen: Path | None = None) -> str:
    """What to tell a learner whose last server the class's idle culler stopped, once; "" otherwise.

    The hub puts the stop into the server's environment (``RTT_IDLE_STOP``: ISO time, seconds idle, the
    class's timeout in seconds; ``course/idle_stops.py``).  ``seen`` (default
    ``~/.cache/ros-tank-tutorial/idle-stop``) keeps the stop already told, so the server's later kernels
    say nothing.  Any thread.
    """
    seen = seen or Path.home() / ".cache" / "ros-tank-tutorial" / "idle-stop"
    stop = os.environ.get("RTT_IDLE_STOP", "")
    try:
        when, idle_s, timeout_s = stop.split()
        idle, timeout = (f"{int(x)} s" if int(x) < 120 else f"{round(int(x) / 60)} min" for x in (idle_s, timeout_s))
    except ValueError:
        return ""  # none, or not the hub's
    try:
        if seen.read_text() == stop:
            return ""
    except OSError:
        pass
    try:
        seen.parent.mkdir(parents=True, exist_ok=True)
        seen.write_text(stop)
    except OSError:
        pass  # told again next time: better than never
    when = when.replace("T", " ").removesuffix("Z")
    return (
        f"Note: your last server was stopped at {when} UTC after {idle} without use (this class stops a server "
        f"after {timeout}), with every simulation, joystick and view it ran. Your notebooks and "
        "files are as you last saved them: run the cells again to start over."
    )


def register(thing):
    """Remember ``thing`` (anything with ``close()``) for :func:`reset`; returns it."""
    _active.append(thing)
    return thing


def forget(thing) -> None:
    """Drop ``thing`` from the registry (it closed itself)."""
    if thing in _active:
        _active.remove(thing)


def reset() -> None:
    """Close every run, view, panel and plot started by earlier cells (kernel thread).

    Run it at the top of a section so the section can be re-run safely.
    One thing failing to close does not stop the others from closing.
    """
    while _active:
        thing = _active.pop()
        try:
            thing.close()
        except Exception as exc:  # noqa: BLE001 - keep closing the rest, but say so
            print(f"reset: {type(thing).__name__} did not close cleanly: {exc!r}")


def wait_until(predicate: Callable[[], bool], timeout: float, poll: float = 0.05) -> bool:
    """Poll ``predicate`` until it is true or ``timeout`` s pass; its last value (any thread)."""
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() >= deadline:
            return bool(predicate())
        time.sleep(poll)
    return True
