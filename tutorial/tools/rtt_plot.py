"""``rtt-plot``: joint positions over time from ``/<body>/joint_state`` (rqt_plot's stand-in).

    rtt-plot                           # live window if a display exists, else a PNG after 10 s
    rtt-plot --body Tank --duration 8 --output plot.png

The time axis is the message stamp (simulation time), so the plot shows
what the simulation did, whatever the network delay.  Node name ``rtt_plot``.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

from tutorial.interfaces.joint_state import joint_state_topic
from tutorial.ros import env as ros_env
from tutorial.ros import program as ros_program
from tutorial.ros import spin as ros_spin
from tutorial.view.joint_plot import JointStateHistory, draw

NODE_NAME = "rtt_plot"


def has_display() -> bool:
    """Whether a graphical display is available for a live window."""
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def main(argv: list[str] | None = None) -> int:
    """``rtt-plot``: record ``/<body>/joint_state`` and plot it (a window, or a PNG); the exit status."""
    import rclpy
    from rclpy.executors import ExternalShutdownException

    argv = list(sys.argv if argv is None else argv)
    p = argparse.ArgumentParser(prog="rtt-plot", description="Plot joint positions from /<body>/joint_state.")
    p.add_argument("--body", default="Tank", help="body name: the topic is /<body>/joint_state (default Tank)")
    p.add_argument("--duration", type=float, default=10.0, help="seconds to record without a display (default 10)")
    p.add_argument("--output", default="joint_state_plot.png", help="PNG written without a display")
    p.add_argument("--no-window", action="store_true", help="write the PNG even when a display exists")
    args = ros_program.parse_command_line(p, argv)
    topic = joint_state_topic(args.body)
    live = has_display() and not args.no_window
    import matplotlib

    if not live:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ros_env.use_localhost_by_default()
    rclpy.init(args=argv)
    node = rclpy.create_node(NODE_NAME)
    history = JointStateHistory(node, topic)
    spin = ros_spin.SpinThread(node).start()
    fig, ax = plt.subplots(figsize=(8, 4.5))
    try:
        if live:
            plt.ion()
            while plt.fignum_exists(fig.number):
                draw(ax, history.series(), topic)
                plt.pause(0.2)
        else:
            end = time.monotonic() + args.duration
            while time.monotonic() < end:
                time.sleep(min(0.1, max(0.0, end - time.monotonic())))
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        ros_program.ignore_stop_signals()  # a second Ctrl-C must not break the clean-up
        spin.stop()
        series = history.series()
        if not live:
            draw(ax, series, topic)
            fig.tight_layout()
            fig.savefig(args.output, dpi=100)
            print(
                f"[/{NODE_NAME}] {sum(len(t) for t, _ in series.values())} points of {len(series)} joints "
                f"written to {args.output}",
                flush=True,
            )
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
