"""Draw a MuJoCo model in meshcat and move it from an ``MjData``.

:class:`Scene` builds one meshcat object per visible geom, grouped under
its body, once; afterwards a frame sends only the bodies whose world pose
changed since the last frame (one ``set_transform`` each).  Static geoms
(the room) are drawn once and never sent again.

A body without joints rides in the frame of the body it is welded to (the
tank's tracks in the chassis'), so a frame sends one transform for each part
that moves on its own: three for a tank, not five.

A frame's transforms go out through one *sink*: an object with
``send_transforms([(meshcat path, 4x4 pose), ...])``.  By default it is
meshcat's own ``Visualizer`` (:class:`VisualizerSink`: one ``set_transform``
per body); the :class:`tutorial.app.app.App` gives the scene a faster one
that its view can serve (``App.frame_sink``): a frame as one message to a
notebook's widget, or, for ``rtt-run``'s own meshcat server, to that server
(:mod:`tutorial.tools.standalone.sinks`).

Geoms in group 3 and above are hidden, as in MuJoCo's own viewer (the tank's
road wheels live there, inside the track covers).

meshcat's connection is not thread-safe: a Scene belongs to the thread that
created its visualizer, and only that thread may call its methods.
"""

from __future__ import annotations

import mujoco
import numpy as np

HIDDEN_GEOM_GROUP = 3
POSE_TOLERANCE = 1e-7  # m, and rotation-matrix entries: a body that moved less is not sent again
_PLANE_EXTENT = 20.0  # m, drawn size of an infinite plane
# meshcat cylinders run along their local Y axis, MuJoCo's along Z.
_Y_TO_Z = np.array([[1, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 0], [0, 0, 0, 1]], dtype=float)


def _pose(pos, mat) -> np.ndarray:
    t = np.eye(4)
    t[:3, :3] = np.asarray(mat).reshape(3, 3)
    t[:3, 3] = pos
    return t


def _local_pose(pos, quat) -> np.ndarray:
    mat = np.zeros(9)
    mujoco.mju_quat2Mat(mat, np.asarray(quat, dtype=float))
    return _pose(pos, mat)


def _color(rgba) -> tuple[int, float]:
    r, g, b, a = (float(x) for x in rgba)
    return (int(r * 255) << 16) | (int(g * 255) << 8) | int(b * 255), a


class VisualizerSink:
    """meshcat's own way to move bodies: one ``set_transform`` command per body, through ``vis``'s window.

    Args:
        vis: a ``meshcat.Visualizer``, owned by the thread that owns the Scene.
    """

    def __init__(self, vis):
        self.vis = vis

    def send_transforms(self, transforms: list) -> None:
        """``[(meshcat path, 4x4 pose), ...]`` (translation in m): ``vis[path].set_transform(pose)`` for each."""
        from meshcat.commands import SetTransform

        for path, matrix in transforms:
            self.vis.window.send(SetTransform(matrix, path))


class Scene:
    """A model drawn in one meshcat visualizer.

    Args:
        vis: a ``meshcat.Visualizer``; this Scene's thread must own it.
        model: the ``MjModel`` to draw.
        root: meshcat path under which everything is drawn.
        sink: where each frame's transforms go (``send_transforms``); by default
            ``vis`` itself, one command per body (:class:`VisualizerSink`).

    Call :meth:`build` once, then :meth:`update` each frame.
    """

    def __init__(self, vis, model: mujoco.MjModel, root: str = "rtt", sink=None):
        self.vis = vis
        self.model = model
        self.root = root
        # The bodies whose frames a frame sends: each body that moves on its own (see frame_body).
        self.moving_bodies: list[int] = []
        # The pose last sent for each moving body, one row each: position (3) and rotation matrix (9).
        self._sent = np.empty((0, 12))
        self._paths: list = []  # the meshcat path of each moving body, made once in build()
        self.frames = 0
        self.transforms_sent = 0
        self.sink = VisualizerSink(vis) if sink is None else sink

    def body_path(self, body_id: int) -> str:
        """The meshcat path of a body's frame, e.g. ``rtt/Tank/TURRET_Y``."""
        name = mujoco.mj_id2name(self.model, mujoco.mjtObj.mjOBJ_BODY, body_id) or f"body{body_id}"
        return f"{self.root}/{name}"

    def frame_body(self, body_id: int) -> int:
        """The body whose meshcat frame carries ``body_id``'s geoms: 0 (the world) for a static one.

        This is MuJoCo's ``body_weldid``: a body without joints is welded to
        its parent, so it is drawn in the frame of the nearest body up its
        chain that moves on its own (one with a joint, or a mocap body), and
        one ``set_transform`` moves them all (the tank's tracks ride in the
        chassis' frame).
        """
        return int(self.model.body_weldid[body_id])

    def _offset(self, body_id: int, frame: int) -> np.ndarray:
        """``body_id``'s fixed pose in ``frame``'s (4x4): its model offsets, composed up to the frame body."""
        m = self.model
        t = np.eye(4)
        b = body_id
        while b != frame:
            t = _local_pose(m.body_pos[b], m.body_quat[b]) @ t
            b = int(m.body_parentid[b])
        return t

    def build(self, data: mujoco.MjData, grid: bool = False) -> None:
        """Create every visible geom; static ones are placed from ``data`` now.

        ``data`` must hold current poses (after ``mj_kinematics`` or ``mj_step``).
        ``grid``: draw a grid on the ground (z = 0, 10 m square, 0.5 m cells),
        for a world with no floor of its own (a robot drawn from its
        description).
        """
        import meshcat.geometry as g

        m = self.model
        self.vis[self.root].delete()
        self.vis["/Grid"].set_property("visible", False)  # meshcat's own: it stays put when the camera is aimed
        if grid:
            self.vis[f"{self.root}/ground"].set_object(_ground_grid(g))
        self.vis["/Axes"].set_property("visible", False)
        moving = set()
        for gid in range(m.ngeom):
            if m.geom_group[gid] >= HIDDEN_GEOM_GROUP:
                continue
            body = int(m.geom_bodyid[gid])
            frame = self.frame_body(body)
            objects = self._geometry(g, gid)
            if not objects:
                continue
            rgba = m.mat_rgba[m.geom_matid[gid]] if m.geom_matid[gid] >= 0 else m.geom_rgba[gid]
            color, alpha = _color(rgba)
            material = g.MeshLambertMaterial(color=color, opacity=alpha, transparent=alpha < 1.0)
            if frame == 0:  # welded to the world: never moves
                base, parent = _pose(data.geom_xpos[gid], data.geom_xmat[gid]), f"{self.root}/static"
            else:
                base = self._offset(body, frame) @ _local_pose(m.geom_pos[gid], m.geom_quat[gid])
                parent = self.body_path(frame)
                moving.add(frame)
            for k, (geometry, local) in enumerate(objects):
                path = f"{parent}/geom{gid}" + (f"_{k}" if len(objects) > 1 else "")
                self.vis[path].set_object(geometry, material)
                self.vis[path].set_transform(base @ local)
        self.moving_bodies = sorted(moving)
        self._paths = [self.vis[self.body_path(b)].path for b in self.moving_bodies]
        self._sent = np.full((len(self.moving_bodies), 12), np.nan)  # NaN: never sent
        self.update(data)

    def _geometry(self, g, gid: int) -> list:
        """meshcat geometry objects with their poses in the geom frame."""
        m = self.model
        kind = m.geom_type[gid]
        size = m.geom_size[gid]
        eye = np.eye(4)
        if kind == mujoco.mjtGeom.mjGEOM_BOX:
            return [(g.Box(2 * size), eye)]
        if kind == mujoco.mjtGeom.mjGEOM_SPHERE:
            return [(g.Sphere(size[0]), eye)]
        if kind == mujoco.mjtGeom.mjGEOM_ELLIPSOID:
            return [(g.Ellipsoid(size[:3]), eye)]
        if kind == mujoco.mjtGeom.mjGEOM_CYLINDER:
            return [(g.Cylinder(2 * size[1], size[0]), _Y_TO_Z)]
        if kind == mujoco.mjtGeom.mjGEOM_CAPSULE:
            r, h = size[0], size[1]
            ends = [np.eye(4), np.eye(4)]
            ends[0][2, 3], ends[1][2, 3] = h, -h
            return [(g.Cylinder(2 * h, r), _Y_TO_Z), (g.Sphere(r), ends[0]), (g.Sphere(r), ends[1])]
        if kind == mujoco.mjtGeom.mjGEOM_PLANE:
            sx = size[0] if size[0] > 0 else _PLANE_EXTENT / 2
            sy = size[1] if size[1] > 0 else _PLANE_EXTENT / 2
            t = np.eye(4)
            t[2, 3] = -0.001
            return [(g.Box([2 * sx, 2 * sy, 0.002]), t)]
        if kind == mujoco.mjtGeom.mjGEOM_MESH:
            mid = m.geom_dataid[gid]
            v0, nv = m.mesh_vertadr[mid], m.mesh_vertnum[mid]
            f0, nf = m.mesh_faceadr[mid], m.mesh_facenum[mid]
            verts = np.array(m.mesh_vert[v0 : v0 + nv])
            faces = np.array(m.mesh_face[f0 : f0 + nf])
            return [(g.TriangularMeshGeometry(verts, faces), eye)]
        return []  # heightfields, SDFs: not drawn

    def update(self, data: mujoco.MjData) -> int:
        """Send the poses of the bodies that moved; returns how many were sent.

        ``data`` must hold current link poses (after ``mj_step`` or ``mj_kinematics``).
        """
        # One vectorised comparison for all moving bodies: a body is sent when any
        # of its 12 numbers differs from what was last sent by more than the
        # tolerance (NaN never compares equal, so a body never sent is sent).
        ids = self.moving_bodies
        now = np.concatenate((data.xpos[ids], data.xmat[ids]), axis=1)  # (bodies, 12)
        changed = np.flatnonzero(~(np.abs(now - self._sent) <= POSE_TOLERANCE).all(axis=1))
        self._sent[changed] = now[changed]
        if len(changed):
            self.sink.send_transforms([(self._paths[i], _pose(now[i, :3], now[i, 3:])) for i in changed])
        sent = len(changed)
        self.frames += 1
        self.transforms_sent += sent
        return sent

    def close(self) -> None:
        """Close the sink, if it has anything to close (the owner thread, once drawing is over)."""
        close = getattr(self.sink, "close", None)
        if close is not None:
            close()

    def set_camera(self, position, target=(0.0, 0.0, 0.0)) -> None:
        """Place meshcat's default camera at ``position`` (m, world frame, Z up) looking at ``target``.

        meshcat's camera always looks at the origin of the page's world, and
        turns about it when dragged.  So the drawing is shifted instead: the
        visualizer's root (everything drawn through it, the scene and any
        overlays) moves by ``-target``, which puts ``target`` at the origin.
        """
        x, y, z = (float(p) - float(t) for p, t in zip(position, target))
        self.vis.set_transform(_pose(-np.asarray(target, dtype=float), np.eye(3)))
        self.vis["/Cameras/default"].set_transform(np.eye(4))
        # meshcat's camera frame is Y-up: world (x, y, z) -> (x, z, -y)
        self.vis["/Cameras/default/rotated/<object>"].set_property("position", [x, z, -y])


def _ground_grid(g, half: float = 5.0, cell: float = 0.5):
    """Grid lines on z = 0, ``2 * half`` m square, ``cell`` m apart: a ground that moves with the drawing.

    Each line is drawn as one segment a cell: a 10 m segment that passes
    under a close camera was left out whole by the browser (SwiftShader).
    """
    ticks = np.arange(-half, half + cell / 2, cell)
    ends = []
    for t in ticks:
        for a, b in zip(ticks[:-1], ticks[1:]):
            ends += [(t, a, 0.0), (t, b, 0.0), (a, t, 0.0), (b, t, 0.0)]
    return g.LineSegments(g.PointsGeometry(np.array(ends, dtype=np.float32).T), g.LineBasicMaterial(color=0x8A94A8))


def look_at_geoms(model: mujoco.MjModel, data: mujoco.MjData, geom_ids, direction=(-1.1, -1.2, 0.8)):
    """A camera ``(position, target)``, m, that shows the visible geoms of ``geom_ids`` whole; None if there are none.

    The target is the centre of their bounding box (each geom grown by its
    bounding sphere, ``geom_rbound``, placed where ``data`` has it); the
    camera looks at it from ``direction``, far enough that the box's
    half-diagonal fits meshcat's 75-degree field of view, and never nearer
    than ``|direction|`` (the tank's close-up).  Planes (infinite) are left out;
    a pane narrower than it is tall may still cut the robot's sides (only the
    vertical field of view is used).
    """
    ids = [
        g
        for g in geom_ids
        if model.geom_group[g] < HIDDEN_GEOM_GROUP and model.geom_type[g] != mujoco.mjtGeom.mjGEOM_PLANE
    ]
    if not ids:
        return None
    centres, radii = data.geom_xpos[ids], model.geom_rbound[ids][:, None]
    low, high = (centres - radii).min(axis=0), (centres + radii).max(axis=0)
    target = (low + high) / 2
    if not np.all(np.isfinite(target)):
        return None  # a pose not yet known (NaN): the caller's close-up instead
    along = np.asarray(direction, dtype=float)
    distance = max(float(np.linalg.norm(along)), 1.8 * float(np.linalg.norm(high - low)) / 2)  # 1/sin(37.5 deg) ~ 1.64
    return target + along / np.linalg.norm(along) * distance, target
