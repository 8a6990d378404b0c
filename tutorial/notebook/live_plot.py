"""A live plot of ``/<body>/joint_state`` in a notebook output (``rqt_plot``'s role).

The plot is an ordinary image output, redrawn twice a second in place, so
a saved notebook (and the book) keeps the last picture.  Its title says
whether it is live or stopped.

Threads: the subscription callback runs on the plot's spin thread and
appends to the history (which locks its own samples); the redraw runs on
the plot's refresh thread with a matplotlib ``Figure`` of its own (no
pyplot state is shared with the kernel); ``show`` and ``close`` run on the
kernel thread.
"""

from __future__ import annotations

import io

from tutorial.notebook.live import LiveOutput


class LivePlot(LiveOutput):
    """Joint positions from ``/<body>/joint_state`` over simulation time.

    Args:
        body: body name; the topic is ``/<body>/joint_state``.
        window: seconds of simulation time shown.
        node_name: the plot's node name.
    """

    def __init__(self, body: str = "Tank", window: float = 10.0, node_name: str = "rtt_live_plot"):
        self.topic = f"/{body}/joint_state"
        self.window = window
        super().__init__(node_name)

    def subscribe(self, node) -> None:
        from tutorial.view.joint_plot import JointStateHistory

        self.history = JointStateHistory(node, self.topic)

    def received(self) -> int:
        """How many samples of the first joint have arrived (any thread)."""
        series = self.history.series()
        return max((len(ts) for ts, _ in series.values()), default=0)

    def render(self, state: str = "live") -> bytes:
        """The current plot as PNG bytes (any thread: it uses its own Agg figure)."""
        from matplotlib.figure import Figure

        from tutorial.view.joint_plot import draw

        series = self.history.series()
        latest = max((ts[-1] for ts, _ in series.values() if ts), default=0.0)
        start = latest - self.window
        trimmed = {
            n: ([t for t in ts if t >= start], [q for t, q in zip(ts, qs) if t >= start])
            for n, (ts, qs) in series.items()
        }
        fig = Figure(figsize=(7, 3))
        ax = fig.add_subplot()
        draw(ax, trimmed, f"{self.topic} ({state})")
        fig.tight_layout()
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=80)
        return buf.getvalue()

    def close(self, stopped: str = "stopped: the last plot it drew") -> None:
        super().close(stopped)
