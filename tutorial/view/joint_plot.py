"""Joint positions over time, received over ROS 2, and their plot (rqt_plot's job).

:class:`JointStateHistory` keeps ``(stamp, positions)`` from a JointState
topic; :func:`draw` plots it against the message stamps (simulation time),
so the plot shows what the simulation did, whatever the network delay.
``rtt-plot`` and the notebooks' live plot (:mod:`tutorial.notebook.live_plot`)
use both.
"""

from __future__ import annotations

import threading

from tutorial.interfaces.joint_state import joint_state_qos
from tutorial.interfaces.timing import stamp_seconds

MAX_POSITION = 1e6  # rad or m: a larger position is a broken publisher's


class JointStateHistory:
    """Collects (stamp, positions) from a JointState topic.

    The subscription callback (spin thread) appends under a lock; the main
    thread takes a copy to draw.

    Args:
        node: the ``rclpy`` node.
        topic: e.g. ``/Tank/joint_state``.
        max_samples: oldest samples are dropped beyond this many.

    A position that is not finite or is beyond :data:`MAX_POSITION` (a broken
    publisher: no joint turns a million radians) is not kept; each is counted
    in :attr:`rejected`.  Kept, it would stretch the plot's axis until every
    real line lay flat.
    """

    def __init__(self, node, topic: str, max_samples: int = 100_000):
        from sensor_msgs.msg import JointState

        self._lock = threading.Lock()
        self.samples: list[tuple[float, dict[str, float]]] = []
        self.rejected = 0  # positions not kept (see above); under the lock
        self.max_samples = max_samples
        self.subscription = node.create_subscription(JointState, topic, self.on_message, joint_state_qos())

    def on_message(self, msg) -> None:
        t = stamp_seconds(msg.header.stamp)
        values = {n: float(p) for n, p in zip(msg.name, msg.position) if abs(p) <= MAX_POSITION}  # NaN fails too
        rejected = min(len(msg.name), len(msg.position)) - len(values)
        with self._lock:
            self.rejected += rejected
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
    """Draw the series on a matplotlib Axes (the thread that owns its figure).

    The lines go in the order of ``series`` (:meth:`JointStateHistory.series`
    keeps the message's joint order, the model's), so each joint has the
    colour a plot of the model's own joint order gives it.
    """
    ax.clear()
    for name, (ts, qs) in series.items():
        ax.plot(ts, qs, label=name)
    ax.set_xlabel("simulation time (s)")
    ax.set_ylabel("position (rad or m)")
    ax.set_title(topic)
    if series:
        ax.legend(loc="upper left")
    ax.grid(True, alpha=0.3)
