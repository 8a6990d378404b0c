"""What every ``rtt-*`` program shares: its command line (``--ros-args``) and its stop on Ctrl-C or SIGTERM."""

from __future__ import annotations

import ast
import signal
import sys
from collections.abc import Sequence

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
    ended: the launcher sends SIGABRT, which prints every thread's stack
    (``PYTHONFAULTHANDLER``), then SIGKILL.

    Raises:
        ValueError: called from a thread other than the main thread.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
