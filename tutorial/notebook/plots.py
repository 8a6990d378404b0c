"""A live plot of ``/<body>/joint_state`` in a notebook output (``rqt_plot``'s role).

The plot is an ordinary image output, redrawn twice a second in place, so
a saved notebook (and the book) keeps the last picture.  Its title says
whether it is live or stopped.

Threads: the subscription callback runs on the plot's spin thread and
appends to the recorder (which locks its own samples); the redraw runs on
the plot's refresh thread with a matplotlib ``Figure`` of its own (no
pyplot state is shared with the kernel); ``show`` and ``close`` run on the
kernel thread.
"""

from __future__ import annotations

import io
import threading

from tutorial.notebook import session

REFRESH = 0.5  # s between redraws


class LivePlot:
    """Joint positions from ``/<body>/joint_state`` over simulation time.

    Args:
        body: body name; the topic is ``/<body>/joint_state``.
        window: seconds of simulation time shown.
        node_name: the plot's node name.
    """

    def __init__(self, body: str = "Tank", window: float = 10.0, node_name: str = "rtt_live_plot"):
        import rclpy

        from tutorial.plot_node import JointStateRecorder
        from tutorial.ros_env import SpinThread

        session.init_ros()
        self.node = rclpy.create_node(node_name)
        self.topic = f"/{body}/joint_state"
        self.recorder = JointStateRecorder(self.node, self.topic)
        self.spin = SpinThread(self.node).start()
        self.window = window
        self.closed = False
        self._handle = None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._refresh, name="live-plot", daemon=True)
        self._thread.start()
        session.register(self)

    def received(self) -> int:
        """How many samples of the first joint have arrived (any thread)."""
        series = self.recorder.series()
        return max((len(ts) for ts, _ in series.values()), default=0)

    def render(self, state: str = "live") -> bytes:
        """The current plot as PNG bytes (any thread: it uses its own Agg figure)."""
        from matplotlib.figure import Figure

        from tutorial.plot_node import draw

        series = self.recorder.series()
        latest = max((ts[-1] for ts, _ in series.values() if ts), default=0.0)
        start = latest - self.window
        trimmed = {n: ([t for t in ts if t >= start], [q for t, q in zip(ts, qs) if t >= start])
                   for n, (ts, qs) in series.items()}
        fig = Figure(figsize=(7, 3))
        ax = fig.add_subplot()
        draw(ax, trimmed, f"{self.topic} ({state})")
        fig.tight_layout()
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=80)
        return buf.getvalue()

    def show(self) -> None:
        """Display the plot in this cell's output; it redraws in place (kernel thread)."""
        from IPython.display import Image, display

        self._handle = display(Image(self.render()), display_id=True)

    def _refresh(self) -> None:
        from IPython.display import Image

        while not self._stop.wait(REFRESH):
            if self._handle is not None:
                self._handle.update(Image(self.render()))

    def close(self) -> None:
        """Stop receiving; the output keeps the last plot, titled as stopped (kernel thread)."""
        from IPython.display import Image

        if self.closed:
            return
        self.closed = True
        self._stop.set()
        self._thread.join(2.0)
        self.spin.stop()
        self.node.destroy_node()
        if self._handle is not None:
            self._handle.update(Image(self.render("stopped: the last plot it drew")))
        session.forget(self)
