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
import threading
import time

from tutorial import ros_env

NODE_NAME = "rtt_plot"


class JointStateRecorder:
    """Collects (stamp, positions) from a JointState topic.

    The subscription callback (spin thread) appends under a lock; the main
    thread takes a copy to draw.

    Args:
        node: the ``rclpy`` node.
        topic: e.g. ``/Tank/joint_state``.
        max_samples: oldest samples are dropped beyond this many.
    """

    def __init__(self, node, topic: str, max_samples: int = 100_000):
        from sensor_msgs.msg import JointState

        from tutorial.controllers.joint_state_publisher import joint_state_qos

        self._lock = threading.Lock()
        self.samples: list[tuple[float, dict[str, float]]] = []
        self.max_samples = max_samples
        self.subscription = node.create_subscription(JointState, topic, self.on_message, joint_state_qos())

    def on_message(self, msg) -> None:
        t = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        values = {n: float(p) for n, p in zip(msg.name, msg.position)}
        with self._lock:
            self.samples.append((t, values))
            if len(self.samples) > self.max_samples:
                del self.samples[: len(self.samples) - self.max_samples]

    def series(self) -> dict[str, tuple[list[float], list[float]]]:
        """joint name -> (times s, positions) copied out under the lock."""
        with self._lock:
            samples = list(self.samples)
        out: dict[str, tuple[list[float], list[float]]] = {}
        for t, values in samples:
            for name, q in values.items():
                ts, qs = out.setdefault(name, ([], []))
                ts.append(t)
                qs.append(q)
        return out


def draw(ax, series: dict, topic: str) -> None:
    """Draw the series on a matplotlib Axes (main thread)."""
    ax.clear()
    for name, (ts, qs) in sorted(series.items()):
        ax.plot(ts, qs, label=name)
    ax.set_xlabel("simulation time (s)")
    ax.set_ylabel("position (rad or m)")
    ax.set_title(topic)
    if series:
        ax.legend(loc="upper left")
    ax.grid(True, alpha=0.3)


def has_display() -> bool:
    """Whether a graphical display is available for a live window."""
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def main(argv: list[str] | None = None) -> int:
    """``rtt-plot``: record ``/<body>/joint_state`` and plot it (a window, or a PNG); the exit status."""
    import rclpy
    from rclpy.executors import ExternalShutdownException
    from rclpy.utilities import remove_ros_args

    argv = list(sys.argv if argv is None else argv)
    p = argparse.ArgumentParser(prog="rtt-plot", description="Plot joint positions from /<body>/joint_state.")
    p.add_argument("--body", default="Tank", help="body name: the topic is /<body>/joint_state (default Tank)")
    p.add_argument("--duration", type=float, default=10.0, help="seconds to record without a display (default 10)")
    p.add_argument("--output", default="joint_state_plot.png", help="PNG written without a display")
    p.add_argument("--no-window", action="store_true", help="write the PNG even when a display exists")
    args = p.parse_args(remove_ros_args(argv)[1:])
    topic = f"/{args.body}/joint_state"
    live = has_display() and not args.no_window
    import matplotlib

    if not live:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ros_env.use_localhost_by_default()
    rclpy.init(args=argv)
    node = rclpy.create_node(NODE_NAME)
    recorder = JointStateRecorder(node, topic)
    spin = ros_env.SpinThread(node).start()
    fig, ax = plt.subplots(figsize=(8, 4.5))
    try:
        if live:
            plt.ion()
            while plt.fignum_exists(fig.number):
                draw(ax, recorder.series(), topic)
                plt.pause(0.2)
        else:
            end = time.monotonic() + args.duration
            while time.monotonic() < end:
                time.sleep(min(0.1, max(0.0, end - time.monotonic())))
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        ros_env.ignore_stop_signals()  # a second Ctrl-C must not break the clean-up
        spin.stop()
        series = recorder.series()
        if not live:
            draw(ax, series, topic)
            fig.tight_layout()
            fig.savefig(args.output, dpi=100)
            print(f"[/{NODE_NAME}] {sum(len(t) for t, _ in series.values())} points of {len(series)} joints "
                  f"written to {args.output}", flush=True)
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
