"""Overlays: shapes a controller draws over the 3D view (arrows, for now).

The viewer's meshcat scene belongs to the main thread, and controllers do
not talk to meshcat themselves.  A controller gets ``config.overlays`` in
``configure`` and asks it for an arrow once::

    arrow = config.overlays.arrow("Tank/acceleration", color=(1.0, 0.2, 0.2))
    arrow.set(origin, vector, visible=True)     # main thread, whenever it changes

:meth:`Arrow.set` only stores numbers.  The App draws the arrows that changed
on its next frame (:class:`MeshcatOverlays`); a headless App draws nothing,
but the numbers are there all the same, so a status line or a test can read
what would be drawn (:attr:`Arrow.length`, :attr:`Arrow.visible`).

An arrow is a half-transparent cylinder shaft (radius 0.01 m) with a cone
head (radius 0.03 m, 0.04 m long) whose tip is ``origin + vector``; both
are in the world frame, in m.  It is drawn over the model, not hidden by it:
an arrow from the tank's IMU starts inside the hull.  Everything here
belongs to the main thread.
"""

from __future__ import annotations

import numpy as np

SHAFT_RADIUS = 0.01  # m
HEAD_RADIUS = 0.03  # m
HEAD_LENGTH = 0.04  # m
OPACITY = 0.5  # half transparent: the model stays visible through the arrow
_MIN_SCALE = 1e-6  # a zero scale makes a singular transform: use this instead


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


def _basis_along(direction: np.ndarray) -> np.ndarray:
    """A rotation matrix (3, 3) whose Y column is the unit vector ``direction``."""
    y = direction
    helper = np.array([1.0, 0.0, 0.0]) if abs(y[0]) < 0.9 else np.array([0.0, 0.0, 1.0])
    x = np.cross(y, helper)
    x /= np.linalg.norm(x)
    return np.column_stack((x, y, np.cross(x, y)))


def arrow_transforms(origin, vector) -> tuple[np.ndarray, np.ndarray]:
    """The 4x4 world transforms of an arrow's shaft and head.

    The shaft is a cylinder of height 1 and the head a cone of height
    :data:`HEAD_LENGTH`, both along meshcat's Y axis and centred on their
    origin; the shaft is scaled to length.  The head keeps its size unless
    the arrow is shorter than it, when it alone shrinks to the arrow's
    length.  A zero vector points up.
    """
    origin = np.asarray(origin, dtype=float)
    vector = np.asarray(vector, dtype=float)
    length = float(np.linalg.norm(vector))
    rotation = _basis_along(vector / length if length > 0 else np.array([0.0, 0.0, 1.0]))
    head = min(HEAD_LENGTH, length)
    shaft = length - head
    shaft_t = np.eye(4)
    shaft_t[:3, :3] = rotation @ np.diag([1.0, max(shaft, _MIN_SCALE), 1.0])
    shaft_t[:3, 3] = origin + rotation[:, 1] * (shaft / 2)
    head_t = np.eye(4)
    head_t[:3, :3] = rotation @ np.diag([1.0, max(head / HEAD_LENGTH, _MIN_SCALE), 1.0])
    head_t[:3, 3] = origin + rotation[:, 1] * (shaft + head / 2)
    return shaft_t, head_t


class MeshcatOverlays:
    """Draws an :class:`Overlays` in a meshcat visualizer, under ``root``.

    Args:
        vis: a ``meshcat.Visualizer``; the thread that owns it owns this.
        overlays: what to draw.
        root: meshcat path of the overlays.

    Call :meth:`update` once per frame: it sends only the arrows that
    changed since it last drew them.  Whatever was under ``root`` before
    (a previous run's arrows, in a notebook's visualizer) is deleted.
    """

    def __init__(self, vis, overlays: Overlays, root: str = "rtt_overlays"):
        self.vis = vis
        self.overlays = overlays
        self.root = root
        vis[root].delete()
        self._drawn: dict[str, tuple[int, bool]] = {}  # name -> (version drawn, visible drawn)
        self.commands = 0  # meshcat commands sent, for measuring

    def update(self) -> int:
        """Send the arrows that changed; returns how many (owner thread)."""
        changed = 0
        for name, arrow in self.overlays.arrows.items():
            drawn = self._drawn.get(name)
            if drawn is None:
                self._create(arrow)
                drawn = (-1, None)
            if drawn[0] == arrow.version:
                continue
            path = self.vis[f"{self.root}/{name}"]
            if arrow.visible:
                shaft, head = arrow_transforms(arrow.origin, arrow.vector)
                path["shaft"].set_transform(shaft)
                path["head"].set_transform(head)
                self.commands += 2
            if arrow.visible != drawn[1]:
                path.set_property("visible", arrow.visible)
                self.commands += 1
            self._drawn[name] = (arrow.version, arrow.visible)
            changed += 1
        return changed

    def _create(self, arrow: Arrow) -> None:
        import meshcat.geometry as g

        r, gr, b = (int(round(c * 255)) for c in arrow.color)
        # depthTest off: drawn over the model, so the part inside the hull shows too
        # (three.js material properties; meshcat passes extra ones through).
        material = g.MeshLambertMaterial(color=(r << 16) | (gr << 8) | b, opacity=arrow.opacity,
                                         transparent=arrow.opacity < 1.0, depthTest=False)
        path = self.vis[f"{self.root}/{arrow.name}"]
        path["shaft"].set_object(g.Cylinder(1.0, SHAFT_RADIUS), material)
        path["head"].set_object(g.Cylinder(HEAD_LENGTH, radiusTop=0.0, radiusBottom=HEAD_RADIUS), material)
        self.commands += 2
