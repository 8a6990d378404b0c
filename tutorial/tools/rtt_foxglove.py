"""``rtt-foxglove``: the running simulation, live in Foxglove (``foxglove_bridge``'s stand-in).

    rtt-run project/step2.yaml --describe &   # the simulation, with its URDF and odometry
    rtt-foxglove                              # then, in Foxglove: Open connection, ws://127.0.0.1:8765

Serves every ROS 2 topic as it is (CDR with its ``ros2msg`` schema) and the
robot in 3D: ``/robot_description`` and ``/tf``, ``/tf_static`` computed from
the bodies' descriptions, odometry and joint states
(:mod:`tutorial.tools.foxglove.bridge`).  Binds to 127.0.0.1 unless ``--host`` says
otherwise.  Runs until Ctrl-C or SIGTERM (or ``--duration``).

Exit status: 0 stopped; 1 a failure while running; 2 a bad command line or a
port that cannot be used.
"""

from __future__ import annotations

import argparse
import functools
import sys
import time

from tutorial.ros import env as ros_env
from tutorial.ros import program as ros_program

PROG = "rtt-foxglove"
_say = functools.partial(print, flush=True)


def main(argv: list[str] | None = None) -> int:
    """``rtt-foxglove``: serve until stopped; the exit status (main thread)."""
    import rclpy
    from rclpy.signals import SignalHandlerOptions

    from tutorial.tools.bag.record_tf import add_frame_prefix_argument
    from tutorial.tools.foxglove.bridge import DEFAULT_HOST, DEFAULT_PORT, NODE_NAME, FoxgloveBridge

    argv = list(sys.argv if argv is None else argv)
    p = argparse.ArgumentParser(prog=PROG, description="Serve the ROS 2 topics and the robot in 3D to Foxglove.")
    p.add_argument("--host", default=DEFAULT_HOST, help=f"address to bind (default {DEFAULT_HOST}: this machine only)")
    p.add_argument("--port", type=int, default=DEFAULT_PORT, help=f"TCP port (default {DEFAULT_PORT}; 0: any free)")
    p.add_argument("--topics", nargs="+", metavar="TOPIC", help="serve only these topics (TF is served in any case)")
    p.add_argument("--duration", type=float, default=None, metavar="SECONDS", help="stop after this long")
    add_frame_prefix_argument(p)
    args = ros_program.parse_command_line(p, argv)
    if not 0 <= args.port <= 65535:
        p.error("--port must be 0 to 65535")
    stop = ros_program.StopRequest().install()
    ros_env.use_localhost_by_default()
    rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
    bridge = FoxgloveBridge(
        args.host, args.port, args.topics, NODE_NAME, output=_say, tf_frame_prefix=args.tf_frame_prefix
    )
    status = 0
    try:
        try:
            bridge.start()
        except RuntimeError as exc:
            print(f"{PROG}: {exc}", file=sys.stderr, flush=True)
            return 2
        deadline = None if args.duration is None else time.monotonic() + args.duration
        while not stop.requested and (deadline is None or time.monotonic() < deadline):
            if bridge.error is not None:
                print(f"{PROG}: stopped: {bridge.error!r}", file=sys.stderr, flush=True)
                status = 1
                break
            time.sleep(0.05)  # the stop flag and the deadline are seen within 50 ms
    finally:
        ros_program.ignore_stop_signals()
        try:
            served = ", ".join(f"{t} {n}" for t, n in sorted(bridge.forwarded.items())) or "nothing"
            bridge.close()
            _say(f"[/{NODE_NAME}] served: {served}")
        finally:
            rclpy.try_shutdown()
    return status


if __name__ == "__main__":
    sys.exit(main())
