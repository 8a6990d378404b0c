"""ROS 2 process set-up: localhost-only discovery and the project's Fast DDS profile by default, init and spin.

ROS 2 Jazzy finds other nodes by multicast discovery.  Its reach is set by
``ROS_AUTOMATIC_DISCOVERY_RANGE`` (``LOCALHOST``, ``SUBNET``, ``OFF``,
``SYSTEM_DEFAULT``) and the group of nodes that see each other by
``ROS_DOMAIN_ID`` (0-101).  This tutorial defaults to ``LOCALHOST``: its nodes
only see nodes on the same machine.  That is the switch to flip for a real
robot: ``export ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET`` before starting.

The variables are read by the middleware when ``rclpy.init`` creates a context,
so :func:`use_localhost_by_default` must run before that; importing
:mod:`tutorial` does it.  It also names the project's Fast DDS profile
(:func:`use_project_profiles_by_default`): reliable writers repair a lost
message within milliseconds, which a monitor on a lossy link needs.

A ROS 2 installation sourced in the same shell (``source /opt/ros/jazzy/setup.bash``)
puts a second build of rclpy and its libraries on the paths: ``PYTHONPATH``
comes before this environment's ``site-packages``, so ``import rclpy`` would
load the installation's rclpy (built for the system's Python) with this
environment's libraries, or the other way round.  Importing this module
checks for it (:func:`sourced_ros_installation`) and stops the program with
a clear message when rclpy would come from elsewhere; it only warns when a
ROS installation is sourced but this environment's rclpy still comes first.
``RTT_ALLOW_SOURCED_ROS=1`` skips the check.
"""

from __future__ import annotations

import ast
import os
import signal
import sys
import threading
import weakref
from collections.abc import Mapping, MutableMapping, Sequence
from pathlib import Path

DISCOVERY_RANGE_VARIABLE = "ROS_AUTOMATIC_DISCOVERY_RANGE"
DEFAULT_DISCOVERY_RANGE = "LOCALHOST"
ALLOW_SOURCED_ROS_VARIABLE = "RTT_ALLOW_SOURCED_ROS"
ROS_PATH_VARIABLES = ("AMENT_PREFIX_PATH", "PYTHONPATH", "LD_LIBRARY_PATH")


def sourced_ros_installation(
    environ: Mapping[str, str] | None = None, rclpy_origin: str | None = "find", prefix: str = sys.prefix
) -> tuple[str, str] | None:
    """Whether a ROS 2 installation is sourced into this environment: ``(level, message)`` or None.

    Args:
        environ: the environment to look at (``os.environ`` by default).
        rclpy_origin: where ``import rclpy`` would load it from (found
            without importing it by default; None: not found).
        prefix: this environment's prefix (``sys.prefix``).

    Returns:
        None when nothing is sourced; ``("error", message)`` when rclpy would
        be imported from a ``PYTHONPATH`` entry outside ``prefix`` (two rclpy
        builds: it fails, or mixes libraries); ``("warning", message)`` when a ROS installation is
        on the paths (``AMENT_PREFIX_PATH``, ``PYTHONPATH``,
        ``LD_LIBRARY_PATH`` entries outside ``prefix`` that belong to one) but
        this environment's rclpy is still the one imported.

    Any thread may call it; it changes nothing.
    """
    env = os.environ if environ is None else environ
    if rclpy_origin == "find":
        import importlib.util

        spec = importlib.util.find_spec("rclpy")
        rclpy_origin = spec.origin if spec is not None else None
    home = os.path.realpath(prefix)

    def outside(path: str) -> bool:
        real = os.path.realpath(path)
        return real != home and not real.startswith(home + os.sep)

    installs = [p for p in env.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p and outside(p)]
    roots = [os.path.realpath(p) for p in installs] + ["/opt/ros"]
    found = [
        f"{name} has {path}"
        for name in ROS_PATH_VARIABLES
        for path in env.get(name, "").split(os.pathsep)
        if path and outside(path) and any(os.path.realpath(path).startswith(r) for r in roots)
    ]
    # PYTHONPATH comes before site-packages: an rclpy under one of its entries shadows ours.  (An entry
    # that holds this environment, e.g. the project's folder with .venv inside it, shadows nothing.)
    shadowing = [
        p
        for p in env.get("PYTHONPATH", "").split(os.pathsep)
        if p and outside(p) and rclpy_origin is not None and outside(rclpy_origin)
        if os.path.realpath(rclpy_origin).startswith(os.path.realpath(p) + os.sep)
    ]
    if shadowing:
        level = "error"
        what = f"rclpy would be imported from {os.path.dirname(rclpy_origin)}, not from this environment ({prefix})"
    elif found:
        level = "warning"
        what = "this environment's rclpy comes first, but the installation's libraries and messages are on the paths"
    else:
        return None
    return level, (
        f"a ROS 2 installation is sourced in this shell ({'; '.join(found) or 'PYTHONPATH'}): {what}. "
        "Two builds of rclpy on one path fail in confusing ways. Run the rtt-* programs and notebooks in a "
        "shell that has not sourced /opt/ros/<distro>/setup.bash (open a new terminal, or `env -u PYTHONPATH "
        "-u AMENT_PREFIX_PATH -u LD_LIBRARY_PATH ...`), and ros2, RViz2 and robot_state_publisher in another "
        f"(see the README, 'With ROS 2 installed'). {ALLOW_SOURCED_ROS_VARIABLE}=1 skips this check."
    )


def _check_sourced_ros() -> None:
    """At import: stop with the message of an ``error``, print a ``warning`` (see :func:`sourced_ros_installation`)."""
    if os.environ.get(ALLOW_SOURCED_ROS_VARIABLE) == "1":
        return
    found = sourced_ros_installation()
    if found is None:
        return
    level, message = found
    print(f"rtt: {'ERROR' if level == 'error' else 'WARNING'}: {message}", file=sys.stderr, flush=True)
    if level == "error":
        raise SystemExit(2)


_check_sourced_ros()


def use_localhost_by_default(environ: MutableMapping[str, str] | None = None) -> str:
    """Make localhost-only discovery the default unless the user chose otherwise.

    Args:
        environ: the environment to change; ``os.environ`` when None.

    Returns:
        The discovery range now in force (the user's, if one was set).

    Any thread may call this, but it only matters before ``rclpy.init``.
    """
    env = os.environ if environ is None else environ
    return env.setdefault(DISCOVERY_RANGE_VARIABLE, DEFAULT_DISCOVERY_RANGE)


PROFILES_VARIABLE = "FASTRTPS_DEFAULT_PROFILES_FILE"  # the name Fast DDS 2.x (Jazzy's 2.14) reads
PROJECT_PROFILES = Path(__file__).with_name("fastdds_profiles.xml")


def use_project_profiles_by_default(environ: MutableMapping[str, str] | None = None) -> str:
    """Make this project's Fast DDS profile the default unless the user named a file of theirs.

    The profile (``tutorial/ros/fastdds_profiles.xml``, where the reasons and
    the measured figures are) makes reliable writers repair a lost message
    within milliseconds instead of Fast DDS's 3 s heartbeat: on a lossy link
    a 50 Hz monitor then shows nearly every state, not only those the link
    kept.  QoS policies still come from the code.  Another middleware
    (``RMW_IMPLEMENTATION``) ignores the variable.  To run without it, name
    a file of your own (``<profiles xmlns="..."/>`` holds nothing).

    Args:
        environ: the environment to change; ``os.environ`` when None.  An
            empty ``FASTRTPS_DEFAULT_PROFILES_FILE`` counts as not set.

    Returns:
        The profiles file now in force (the user's, if one was set).

    Main thread, before any ROS 2 thread starts (it writes the environment,
    which C code reads unlocked); it only matters before the process's first
    node: Fast DDS reads the file once, when it creates a participant.
    """
    env = os.environ if environ is None else environ
    if not env.get(PROFILES_VARIABLE):
        env[PROFILES_VARIABLE] = str(PROJECT_PROFILES)
    return env[PROFILES_VARIABLE]


def discovery_summary() -> str:
    """One line saying which ROS 2 peers this process can reach, for start-up logs."""
    return "ROS 2 discovery: range={} domain={}".format(
        os.environ.get(DISCOVERY_RANGE_VARIABLE, "SYSTEM_DEFAULT"),
        os.environ.get("ROS_DOMAIN_ID", "0"),
    )


def init(args: Sequence[str] | None = None):
    """Initialise rclpy for this process with localhost discovery by default.

    Args:
        args: the command line, ``--ros-args ...`` included (``sys.argv`` style).

    Returns:
        The command line with the ROS arguments removed, for argparse.

    Call from the main thread, once per process (or once per ``try_shutdown``).
    """
    use_localhost_by_default()
    import rclpy
    from rclpy.utilities import remove_ros_args

    rclpy.init(args=list(args) if args is not None else None)
    return remove_ros_args(list(args) if args is not None else None)


ROS_ARGS_HELP = "they are -r FROM:=TO, -p NAME:=VALUE, --params-file FILE, --log-level LEVEL"


def remove_ros_args_or_fail(args: Sequence[str]) -> list[str]:
    """The command line without its ROS arguments, for argparse; a bad ROS argument is one clear error.

    rcl parses ``--ros-args ...`` (``-r from:=to``, ``-p name:=value``...);
    ``rclpy.utilities.remove_ros_args`` raises its own exception types for a
    malformed rule, and ``rclpy.init`` would fail the same way.  A program
    calls this first, so a typo there ends in one line and exit status 2,
    not a traceback.

    Args:
        args: ``sys.argv`` style, the program name first.

    Raises:
        ValueError: a ROS argument rcl does not accept; the text says which, in one line.

    Any thread may call it; it needs no ``rclpy.init``.
    """
    from rclpy.utilities import remove_ros_args

    try:
        return list(remove_ros_args(list(args)))
    except Exception as exc:  # noqa: BLE001 - rclpy's RCLInvalidROSArgsError, UnknownROSArgsError, ...
        if type(exc).__name__ == "UnknownROSArgsError":  # its text is the list of them, as Python writes one
            try:
                detail = "unknown: " + " ".join(str(a) for a in ast.literal_eval(str(exc)))
            except (ValueError, SyntaxError, TypeError):
                detail = f"unknown: {exc}"
        else:
            detail = str(exc).split(", at /")[0].splitlines()[0] if str(exc) else type(exc).__name__
        raise ValueError(f"bad ROS arguments after --ros-args: {detail} ({ROS_ARGS_HELP})") from None


def parse_command_line(parser, argv: Sequence[str]):
    """``parser``'s parse of ``argv`` without its ROS arguments; a bad ROS argument exits in one line.

    What a program's ``main`` calls instead of ``parser.parse_args``: rcl's
    own errors for ``--ros-args -r foo`` would otherwise be a traceback.

    Args:
        parser: an ``argparse.ArgumentParser``; its ``prog`` starts the error line.
        argv: ``sys.argv`` style, the program name first.

    Returns:
        The ``argparse.Namespace`` of the program's own arguments.

    Raises:
        SystemExit: status 2, after ``<prog>: bad ROS arguments after --ros-args: ...``
            on stderr (and argparse's own exits for the program's arguments).

    Main thread (argparse may exit); it needs no ``rclpy.init``.
    """
    try:
        plain = remove_ros_args_or_fail(argv)
    except ValueError as exc:
        print(f"{parser.prog}: {exc}", file=sys.stderr)
        raise SystemExit(2) from None
    return parser.parse_args(plain[1:])


class StopRequest:
    """Ctrl-C or SIGTERM as a request: set by the signal handler, read by the program's main loop.

    ``install()`` (main thread) makes SIGINT and SIGTERM set ``requested``
    and call ``on_stop`` (if given), instead of raising ``KeyboardInterrupt``
    wherever the main thread happens to be: inside rclpy's executor, an
    interrupted call leaves a half-made object whose clean-up prints a
    traceback later.  Pair it with ``rclpy.init(...,
    signal_handler_options=SignalHandlerOptions.NO)``, so rclpy does not
    install its own handler over this one.

    A plain attribute, not a ``threading.Event``: a signal handler runs on
    the main thread between two bytecodes, possibly inside ``Event.wait``
    holding the event's lock, and ``Event.set`` would take it again.
    ``on_stop`` runs in the handler, so it must be as plain (set a flag).
    """

    def __init__(self, on_stop=None):
        self.requested = False
        self._on_stop = on_stop

    def __call__(self, signum, frame) -> None:
        self.requested = True
        if self._on_stop is not None:
            self._on_stop()

    def install(self) -> StopRequest:
        """Handle SIGINT and SIGTERM from now on (main thread only); ``self``.

        Raises:
            ValueError: called from a thread other than the main thread.
        """
        signal.signal(signal.SIGINT, self)
        signal.signal(signal.SIGTERM, self)
        return self


def ignore_stop_signals() -> None:
    """Ignore further Ctrl-C and SIGTERM while the program cleans up (main thread, at the start of clean-up).

    Ctrl-C in a terminal sends SIGINT to every process of the foreground
    group, and a launcher then sends each of its nodes another one.  Without
    this, that second signal raises ``KeyboardInterrupt`` in the middle of
    ``destroy_node()`` and prints a traceback.  A clean-up that hangs is still
    ended: a launcher escalates to SIGKILL.

    Raises:
        ValueError: called from a thread other than the main thread.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)


SPIN_POLL = 0.1  # s: how often the spin thread checks whether it should stop

EXECUTOR_VARIABLE = "RTT_EXECUTOR"  # "single" (the default) or "events"
_spun_nodes: weakref.WeakSet = weakref.WeakSet()  # nodes given to a SpinThread, see SpinThread


def make_executor(context):
    """The executor a :class:`SpinThread` uses: rclpy's ``SingleThreadedExecutor``, chosen on purpose.

    It is the executor ``rclpy.spin()`` uses, so a learner's own nodes run
    their callbacks the way this tutorial's do.  rclpy's ``EventsExecutor``
    dispatches from C++ and measured faster here (``book/benchmarks.md``: at
    1 kHz the viewer shows each state sooner and uses less CPU), but in Jazzy
    it is experimental: it refuses guard conditions, and its ``shutdown()``
    and ``create_task()`` hang when called from another thread while it
    spins (``SpinThread`` never does that).  It is not kept out for losing
    messages: reading one stream at the same time, the two executors missed
    about the same messages (``python -m benchmarks.delivery``), although a
    CI run once lost one of 10 messages sent 250 ms apart with it (cause
    not found).  ``RTT_EXECUTOR=events`` selects it, for measuring.

    Args:
        context: the ``rclpy.context.Context`` of the node(s) to spin.

    Raises:
        ValueError: ``RTT_EXECUTOR`` is neither ``single`` nor ``events``.
    """
    choice = os.environ.get(EXECUTOR_VARIABLE, "single")
    if choice not in ("single", "events"):
        raise ValueError(f"{EXECUTOR_VARIABLE}={choice!r}: use 'single' or 'events'")
    if choice == "events":
        from rclpy.experimental import EventsExecutor

        return EventsExecutor(context=context)
    from rclpy.executors import SingleThreadedExecutor

    return SingleThreadedExecutor(context=context)


class SpinThread:
    """Spins one node's callbacks on a background thread.

    This is the analog of roscpp's ``AsyncSpinner``, which the original
    tutorial relied on: subscription callbacks run on *this* thread, never on
    the main thread or the simulation thread.  That is why a callback may not
    touch state owned by another thread, and why Step 1 uses a lock and
    Step 3 uses :func:`tutorial.core.call_later.call_later`.

    The thread calls ``spin_once`` until :meth:`stop` sets its stop flag, so
    stopping never calls into the executor from another thread and takes at
    most ``SPIN_POLL`` s.  If the ROS context is shut down first, the thread
    ends too.

    Args:
        node: the ``rclpy.node.Node`` whose callbacks to run.
        hand_over_to: the :class:`tutorial.core.call_later.MainLoop` its callbacks
            post to, if any: after each callback the thread steps aside
            (:meth:`~tutorial.core.call_later.MainLoop.yield_to_owner`, at most
            1 ms) so the main thread runs the posted work before the
            executor's own bookkeeping holds the interpreter lock.

    Raises:
        RuntimeError: the node was already given to a SpinThread (one per node
            in its life: moved to a second ``EventsExecutor``, a node missed the
            messages of its first moments there, a silent loss).

    ``start`` and ``stop`` are called from the thread that owns the node
    (normally the main thread).  An exception raised by a callback ends the
    spinning; it is kept in :attr:`error` for the owner to report.
    """

    def __init__(self, node, hand_over_to=None):
        self.node = node
        self._hand_over_to = hand_over_to
        # One thread, one executor: callbacks of this node never run in
        # parallel with each other, only in parallel with the other threads.
        if node in _spun_nodes:
            raise RuntimeError(
                f"node {node.get_fully_qualified_name()} was already spun by a SpinThread; "
                "create a new node to spin it again"
            )
        self.executor = make_executor(node.context)
        _spun_nodes.add(node)
        self.executor.add_node(node)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._spin, name="ros-spin", daemon=True)
        self.error: BaseException | None = None

    def _spin(self) -> None:
        from rclpy.executors import ExternalShutdownException

        try:
            while not self._stop.is_set():
                self.executor.spin_once(timeout_sec=SPIN_POLL)
                if self._hand_over_to is not None:
                    self._hand_over_to.yield_to_owner()
        except ExternalShutdownException:
            pass
        except BaseException as exc:  # noqa: BLE001 - kept for the owner to report
            self.error = exc

    def start(self) -> SpinThread:
        """Start spinning on the background thread; returns self."""
        self._thread.start()
        return self

    def stop(self, timeout: float = 2.0) -> bool:
        """Stop spinning and wait for the thread (at most ``timeout`` s); True when it ended.

        Afterwards the node is removed from the executor and the executor is
        shut down (its guard conditions and threads released), so the node
        may be destroyed.
        """
        self._stop.set()
        if self._thread.ident is not None:
            self._thread.join(timeout)
        ended = not self._thread.is_alive()
        if ended:
            # Safe only now: the spinning thread has ended, nothing else uses the executor.
            self.executor.remove_node(self.node)
            self.executor.shutdown(timeout_sec=0)
        return ended
