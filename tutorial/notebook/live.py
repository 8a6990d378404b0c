"""A notebook output that shows a picture made from what a node receives, redrawn in place.

:class:`LiveOutput` is what :class:`tutorial.notebook.live_plot.LivePlot` (joint
positions) and :class:`tutorial.notebook.live_image.LiveImage` (a camera picture)
share: a node of its own spun on a :class:`tutorial.ros.spin.SpinThread`, an
ordinary image output redrawn twice a second by a refresh thread, and a
``close()`` (what ``reset()`` calls) that keeps the last picture, its title
saying it has stopped.  A saved notebook, and the book, keep that picture.

Threads: the subscription callbacks run on the output's spin thread (a
subclass keeps what they receive under its own lock); the redraw runs on
the refresh thread with matplotlib ``Figure`` objects of its own (no pyplot
state is shared with the kernel); ``show`` and ``close`` run on the kernel thread.
"""

from __future__ import annotations

import threading

from tutorial.notebook import session

REFRESH = 0.5  # s between redraws


class LiveOutput:
    """Base of the live picture outputs; subclasses subscribe in :meth:`subscribe` and draw in :meth:`render`.

    Args:
        node_name: the output's node name.
    """

    def __init__(self, node_name: str):
        import rclpy

        from tutorial.ros.spin import SpinThread

        session.init_ros()
        self.node = rclpy.create_node(node_name)
        self.subscribe(self.node)
        self.spin = SpinThread(self.node).start()
        self.closed = False
        self._handle = None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._refresh, name=f"live-{node_name}", daemon=True)
        self._thread.start()
        session.register(self)

    # ---- for subclasses ------------------------------------------------------
    def subscribe(self, node) -> None:
        """Create the subscriptions on ``node`` (kernel thread, before spinning starts)."""
        raise NotImplementedError

    def render(self, state: str = "live") -> bytes:
        """The picture as PNG bytes, its title ending with ``state`` (any thread)."""
        raise NotImplementedError

    def changed(self) -> bool:
        """Whether something new arrived since the last redraw (refresh thread); default: always redraw."""
        return True

    # ---- the output ------------------------------------------------------------
    def show(self) -> None:
        """Display the picture in this cell's output; it redraws in place (kernel thread)."""
        from IPython.display import Image, display

        self._handle = display(Image(self.render()), display_id=True)

    def _refresh(self) -> None:
        from IPython.display import Image

        while not self._stop.wait(REFRESH):
            if self._handle is not None and self.changed():
                self._handle.update(Image(self.render()))

    def close(self, stopped: str = "stopped") -> None:
        """Stop receiving; the output keeps the last picture, titled ``stopped`` (kernel thread)."""
        from IPython.display import Image

        if self.closed:
            return
        self.closed = True
        self._stop.set()
        self._thread.join(2.0)
        self.spin.stop()
        self.node.destroy_node()
        if self._handle is not None:
            self._handle.update(Image(self.render(stopped)))
        session.forget(self)
