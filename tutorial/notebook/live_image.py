"""A live camera picture in a notebook output (``rqt_image_view``'s role).

:class:`LiveImage` subscribes an image topic (``/Tank/camera/image`` by
default) and shows the newest picture in an ordinary image output, redrawn
in place twice a second, like :class:`tutorial.notebook.live_plot.LivePlot`.  A
saved notebook (and the book) keeps the last picture; its title says whether
it is live or stopped, and the picture's stamp.

Threads: the subscription callback runs on the image's spin thread, in
:class:`tutorial.view.images.ImageReceiver`, which checks every message
(:func:`tutorial.interfaces.image.image_to_array`) and swaps the newest picture in
under its lock; the redraw runs on a refresh thread with a matplotlib
``Figure`` of its own (no pyplot state is shared with the kernel); ``show``
and ``close`` run on the kernel thread.
"""

from __future__ import annotations

import io

from tutorial.notebook.live import LiveOutput


class LiveImage(LiveOutput):
    """The newest picture of an image topic, live in a notebook output.

    Args:
        topic: a ``sensor_msgs/Image`` topic; subscribed best effort, keep
            last 1 (the camera's QoS; it matches reliable publishers too).
        node_name: the node's name.

    It registers with the session: ``reset()`` closes it, and the output
    keeps the last picture, titled as stopped.
    """

    def __init__(self, topic: str = "/Tank/camera/image", node_name: str = "rtt_live_image"):
        self.topic = topic
        self._drawn = None  # number of the picture last drawn (refresh thread)
        super().__init__(node_name)

    def subscribe(self, node) -> None:
        from tutorial.view.images import ImageReceiver

        self.receiver = ImageReceiver(node, self.topic)

    def changed(self) -> bool:
        """A picture arrived since the last redraw (refresh thread): redraw only then."""
        newest = self.receiver.newest()
        number = newest.number if newest is not None else None
        if number == self._drawn:
            return False
        self._drawn = number
        return True

    def received(self) -> int:
        """How many pictures have been accepted so far (any thread)."""
        return self.receiver.counts()["accepted"]

    def rejected(self) -> int:
        """How many messages were refused as unreadable (any thread)."""
        return self.receiver.counts()["rejected"]

    def newest(self):
        """The newest picture, a :class:`tutorial.view.images.ReceivedImage`, or None (any thread)."""
        return self.receiver.newest()

    def figure(self, state: str = "live"):
        """A matplotlib ``Figure`` of the newest picture, titled with its stamp and ``state`` (any thread).

        The figure is its own (not pyplot's), so any thread may draw it.
        """
        import numpy as np
        from matplotlib.figure import Figure

        newest = self.receiver.newest()
        counts = self.receiver.counts()
        fig = Figure(figsize=(4.8, 4.0), layout="constrained")
        ax = fig.add_subplot()
        ax.set_axis_off()
        if newest is None:
            ax.imshow(np.full((240, 320, 3), 200, np.uint8))
            ax.text(160, 120, "no picture yet", ha="center", va="center")
            title = f"{self.topic} ({state})"
        else:
            ax.imshow(newest.pixels)
            title = f"{self.topic}  t = {newest.stamp:.2f} s\n({state})"
        ax.set_title(title, fontsize=10)
        rejected = f", {counts['rejected']} rejected" if counts["rejected"] else ""
        ax.text(
            0.5,
            -0.03,
            f"{counts['accepted']} pictures received{rejected}",
            transform=ax.transAxes,
            ha="center",
            va="top",
            fontsize=9,
        )
        return fig

    def render(self, state: str = "live") -> bytes:
        """:meth:`figure` as PNG bytes (any thread)."""
        buf = io.BytesIO()
        self.figure(state).savefig(buf, format="png", dpi=80)
        return buf.getvalue()

    def close(self, stopped: str = "stopped: the last picture received") -> None:
        super().close(stopped)
