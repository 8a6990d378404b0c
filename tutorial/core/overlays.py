"""Overlays: shapes a controller asks to have drawn over the 3D view (arrows, for now).

The viewer's meshcat scene belongs to the main thread, and controllers do
not talk to meshcat themselves.  A controller gets ``config.overlays`` in
``configure`` and asks it for an arrow once::

    arrow = config.overlays.arrow("Tank/acceleration", color=(1.0, 0.2, 0.2))
    arrow.set(origin, vector, visible=True)     # main thread, whenever it changes

:meth:`Arrow.set` only stores numbers: nothing here knows meshcat.  The App
draws the arrows that changed on its next frame
(:class:`tutorial.view.meshcat_overlays.MeshcatOverlays`); a headless App draws
nothing, but the numbers are there all the same, so a status line or a test
can read what would be drawn (:attr:`Arrow.length`, :attr:`Arrow.visible`).
Everything here belongs to the main thread.

Recordings: :meth:`Overlays.snapshot` copies every arrow's state; a list of
snapshots, one per recorded frame, goes to
:func:`tutorial.notebook.replay.record_replay` (``overlay_frames``).
"""

from __future__ import annotations

import numpy as np

OPACITY = 0.5  # half transparent: the model stays visible through the arrow


class Arrow:
    """One arrow: ``origin`` (3,) and ``vector`` (3,) in m, world frame, and ``visible``.

    Made by :meth:`Overlays.arrow`; only the main thread may use it.
    """

    def __init__(self, name: str, color: tuple[float, float, float], opacity: float = OPACITY):
        self.name = name
        self.color = tuple(float(c) for c in color)
        self.opacity = float(opacity)
        self.origin = np.zeros(3)
        self.vector = np.zeros(3)
        self.visible = False
        self.version = 0  # counts changes; a drawer redraws when it differs from what it drew

    def set(self, origin, vector, visible: bool = True) -> None:
        """Place the arrow (main thread).

        Args:
            origin: (3,) where the arrow starts, m, world frame.
            vector: (3,) from the origin to the tip, m, world frame.
            visible: whether to draw it.

        Raises:
            ValueError: ``origin`` or ``vector`` is not 3 finite numbers.
        """
        origin = np.array(origin, dtype=float).reshape(3)
        vector = np.array(vector, dtype=float).reshape(3)
        if not (np.isfinite(origin).all() and np.isfinite(vector).all()):
            raise ValueError(f"arrow {self.name}: origin and vector must be finite, got {origin}, {vector}")
        if visible == self.visible and np.array_equal(origin, self.origin) and np.array_equal(vector, self.vector):
            return
        self.origin, self.vector, self.visible = origin, vector, bool(visible)
        self.version += 1

    @property
    def length(self) -> float:
        """The arrow's length, m (also when hidden)."""
        return float(np.linalg.norm(self.vector))

    def record(self) -> dict:
        """``{"length": m, "visible": bool}``, for status lines and summaries."""
        return {"length": round(self.length, 6), "visible": self.visible}


class Overlays:
    """The overlays of one App, shared by its controllers (main thread)."""

    def __init__(self):
        self.arrows: dict[str, Arrow] = {}

    def arrow(self, name: str, color: tuple[float, float, float], opacity: float = OPACITY) -> Arrow:
        """A new arrow named ``name`` (a meshcat path, e.g. ``Tank/acceleration``), hidden until set.

        Raises:
            ValueError: an arrow of that name exists already.
        """
        if name in self.arrows:
            raise ValueError(f"an overlay arrow named {name!r} exists already")
        arrow = self.arrows[name] = Arrow(name, color, opacity)
        return arrow

    def snapshot(self) -> dict[str, tuple[np.ndarray, np.ndarray, bool]]:
        """Every arrow's state now: ``{name: (origin (3,), vector (3,), visible)}``, copies (main thread).

        Keep one per recorded frame to record the arrows with a run (see the module text).
        """
        return {name: (a.origin.copy(), a.vector.copy(), a.visible) for name, a in self.arrows.items()}
