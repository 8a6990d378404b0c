"""Overlays drawn in meshcat: the arrows of :mod:`tutorial.core.overlays`, live and in recordings.

:class:`MeshcatOverlays` draws an App's arrows that changed on its next
frame; :func:`draw_arrow_snapshot` and :func:`add_arrow_clips` put them in
a recording.

An arrow is a half-transparent cylinder shaft (radius 0.01 m) with a cone
head (radius 0.03 m, 0.04 m long) whose tip is ``origin + vector``; both
are in the world frame, in m.  It is drawn over the model, not hidden by it:
an arrow from the tank's IMU starts inside the hull.  Everything here
belongs to the main thread.

Recordings: :meth:`Overlays.snapshot` copies every arrow's state; a list
of snapshots, one per recorded frame, goes to
:func:`tutorial.notebook.replay.record_replay` (``overlay_frames``), which
draws the arrows into the recorded page and animates them with
:func:`add_arrow_clips`, as it animates the bodies.
"""

from __future__ import annotations

import numpy as np

from tutorial.core.overlays import Arrow, Overlays

SHAFT_RADIUS = 0.01  # m
HEAD_RADIUS = 0.03  # m
HEAD_LENGTH = 0.04  # m
_MIN_SCALE = 1e-6  # a zero scale makes a singular transform: use this instead


def _basis_along(direction: np.ndarray) -> np.ndarray:
    """A rotation matrix (3, 3) whose Y column is the unit vector ``direction``."""
    y = direction
    helper = np.array([1.0, 0.0, 0.0]) if abs(y[0]) < 0.9 else np.array([0.0, 0.0, 1.0])
    x = np.cross(y, helper)
    x /= np.linalg.norm(x)
    return np.column_stack((x, y, np.cross(x, y)))


def arrow_poses(origin, vector) -> tuple[tuple[np.ndarray, np.ndarray, float], ...]:
    """Where an arrow's shaft and head go: ``((position (3,), rotation (3, 3), y scale), ...)``, shaft first.

    The shaft is a cylinder of height 1 and the head a cone of height
    :data:`HEAD_LENGTH`, both along meshcat's Y axis and centred on their
    origin; each is scaled along its Y only.  The shaft is scaled to
    length; the head keeps its size unless the arrow is shorter than it,
    when it alone shrinks to the arrow's length.  A zero vector points up.
    """
    origin = np.asarray(origin, dtype=float)
    vector = np.asarray(vector, dtype=float)
    length = float(np.linalg.norm(vector))
    rotation = _basis_along(vector / length if length > 0 else np.array([0.0, 0.0, 1.0]))
    head = min(HEAD_LENGTH, length)
    shaft = length - head
    return (
        (origin + rotation[:, 1] * (shaft / 2), rotation, max(shaft, _MIN_SCALE)),
        (origin + rotation[:, 1] * (shaft + head / 2), rotation, max(head / HEAD_LENGTH, _MIN_SCALE)),
    )


def arrow_transforms(origin, vector) -> tuple[np.ndarray, np.ndarray]:
    """The 4x4 world transforms of an arrow's shaft and head (see :func:`arrow_poses`)."""
    transforms = []
    for position, rotation, y_scale in arrow_poses(origin, vector):
        t = np.eye(4)
        t[:3, :3] = rotation @ np.diag([1.0, y_scale, 1.0])
        t[:3, 3] = position
        transforms.append(t)
    return transforms[0], transforms[1]


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
        _create_arrow(self.vis[f"{self.root}/{arrow.name}"], arrow)
        self.commands += 2


def _create_arrow(path, arrow: Arrow) -> None:
    """Send the shaft and head objects of ``arrow`` to the meshcat ``path``."""
    import meshcat.geometry as g

    r, gr, b = (int(round(c * 255)) for c in arrow.color)
    # depthTest off: drawn over the model, so the part inside the hull shows too
    # (three.js material properties; meshcat passes extra ones through).
    material = g.MeshLambertMaterial(
        color=(r << 16) | (gr << 8) | b, opacity=arrow.opacity, transparent=arrow.opacity < 1.0, depthTest=False
    )
    path["shaft"].set_object(g.Cylinder(1.0, SHAFT_RADIUS), material)
    path["head"].set_object(g.Cylinder(HEAD_LENGTH, radiusTop=0.0, radiusBottom=HEAD_RADIUS), material)


def _quaternion_xyzw(rotation: np.ndarray) -> np.ndarray:
    """A rotation matrix (3, 3) as a unit quaternion in three.js's order x, y, z, w."""
    import mujoco

    wxyz = np.empty(4)
    mujoco.mju_mat2Quat(wxyz, np.ascontiguousarray(rotation, dtype=float).reshape(9))
    return wxyz[[1, 2, 3, 0]]


def draw_arrow_snapshot(vis, overlays: Overlays, snapshot: dict, root: str = "rtt_overlays") -> None:
    """Draw ``overlays``' arrows into ``vis`` as they were in ``snapshot`` (:meth:`Overlays.snapshot`).

    For a recorded page (a :class:`tutorial.notebook.replay.SceneRecorder`'s
    visualizer): the objects, their first poses and visibility.  An arrow
    missing from the snapshot is drawn hidden.  The caller's thread owns ``vis``.
    """
    for name, arrow in overlays.arrows.items():
        path = vis[f"{root}/{name}"]
        _create_arrow(path, arrow)
        origin, vector, visible = snapshot.get(name, (arrow.origin, arrow.vector, False))
        for part, t in zip(("shaft", "head"), arrow_transforms(origin, vector)):
            path[part].set_transform(t)
        path.set_property("visible", bool(visible))


def add_arrow_clips(
    vis, overlays: Overlays, snapshots, animation, fps: float, root: str = "rtt_overlays", decimals: int = 4
) -> None:
    """Add to ``animation`` the clips that move ``overlays``' arrows through ``snapshots``, one per frame.

    Args:
        vis: the visualizer the arrows were drawn in (:func:`draw_arrow_snapshot`).
        overlays: the arrows (their names).
        snapshots: one :meth:`Overlays.snapshot` per frame of ``animation``, ``1/fps`` s apart.
        animation: a ``meshcat.animation.Animation``; gets a clip per shaft and head
            (position, quaternion, scale along Y) and one per arrow (``visible``).
        fps: frames per second of the animation.
        decimals: values are rounded to this many decimals, so identical runs give identical pages.
    """
    from meshcat.animation import AnimationClip

    for name, arrow in overlays.arrows.items():
        shown = []  # per frame: visible
        poses = []  # per frame, per part (shaft, head): position x y z, quaternion x y z w, Y scale
        for snapshot in snapshots:
            origin, vector, visible = snapshot.get(name, (arrow.origin, arrow.vector, False))
            shown.append(bool(visible))
            poses.append(
                [
                    [*position, *_quaternion_xyzw(rotation), y_scale]
                    for position, rotation, y_scale in arrow_poses(origin, vector)
                ]
            )
        poses = np.round(np.array(poses), decimals) + 0.0  # (frames, 2, 8); + 0.0: no -0.0
        poses[..., 7] = np.maximum(poses[..., 7], 10.0**-decimals)  # never a zero scale
        path = vis[f"{root}/{name}"]
        clip = animation.clips[path.path] = AnimationClip(fps=fps)
        for frame in key_frames(np.array(shown)[:, None]):
            clip.set_property(int(frame), "visible", "boolean", shown[frame])
        for k, part in enumerate(("shaft", "head")):
            clip = animation.clips[path[part].path] = AnimationClip(fps=fps)
            for frame in key_frames(poses[:, k]):
                p = poses[frame, k]
                clip.set_property(int(frame), "position", "vector3", p[:3].tolist())
                clip.set_property(int(frame), "quaternion", "quaternion", p[3:7].tolist())
                clip.set_property(int(frame), "scale", "vector3", [1.0, float(p[7]), 1.0])


def key_frames(track: np.ndarray) -> np.ndarray:
    """Indices of the frames (rows of ``track``, (n, k)) that differ from a neighbour, and the first and last.

    The frames in the middle of a hold add nothing to an animation: it holds between two equal keys
    (the arrows' animations here, and the recordings of :mod:`tutorial.notebook.replay`).  Any thread.
    """
    n = len(track)
    changed = np.any(track[1:] != track[:-1], axis=1)
    keep = np.zeros(n, dtype=bool)
    keep[[0, n - 1]] = True
    keep[1:] |= changed
    keep[:-1] |= changed
    return np.flatnonzero(keep)
