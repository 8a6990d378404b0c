"""A URDF's joints as transforms, computed as ``robot_state_publisher`` computes them.

``robot_state_publisher`` reads a robot's URDF and, for every
``sensor_msgs/JointState`` it receives, publishes on ``/tf`` the transform
parent link -> child link of each moving joint the message names, stamped
with the message's stamp; the fixed joints' transforms go once on
``/tf_static``.  :class:`UrdfKinematics` does the same arithmetic on a URDF
parsed by ``yourdfpy``:

* ``revolute`` and ``continuous``: origin, then a turn of ``q`` rad about the
  (normalised) axis; ``prismatic``: origin, then ``q`` m along it; ``fixed``:
  the origin; a ``mimic`` joint follows its joint (``multiplier * q + offset``);
* a ``floating`` or ``planar`` joint is not published: no JointState can carry
  it (``robot_state_publisher`` leaves it out too), nor is a moving joint
  the message does not name, nor one whose value is NaN or infinite.

:meth:`UrdfKinematics.link_poses` chains them into every link's pose in the
root link's frame (or the world's, given the root's pose): what a TF client
computes by walking the tree.

Any thread may use an instance: it holds no state that changes.
"""

from __future__ import annotations

import io
import math
from dataclasses import dataclass

import numpy as np

from tutorial.interfaces.tf import Transform

MOVING = ("revolute", "continuous", "prismatic")


@dataclass(frozen=True)
class UrdfJoint:
    """One URDF joint: ``origin`` (4x4, m) places the child in the parent at ``q`` = 0."""

    name: str
    type: str
    parent: str
    child: str
    origin: np.ndarray
    axis: np.ndarray
    mimic: tuple[str, float, float] | None = None  # (joint, multiplier, offset)

    def motion(self, q: float) -> np.ndarray:
        """The child's pose in the parent frame at joint value ``q`` (rad or m), 4x4."""
        if self.type in ("revolute", "continuous"):
            return self.origin @ _rotation(self.axis, q)
        if self.type == "prismatic":
            out = np.eye(4)
            out[:3, 3] = self.axis * q
            return self.origin @ out
        return self.origin


def _rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues' rotation about a unit ``axis`` by ``angle`` rad, 4x4."""
    x, y, z = axis
    c, s = math.cos(angle), math.sin(angle)
    k = 1.0 - c
    out = np.eye(4)
    out[:3, :3] = [
        [c + x * x * k, x * y * k - z * s, x * z * k + y * s],
        [y * x * k + z * s, c + y * y * k, y * z * k - x * s],
        [z * x * k - y * s, z * y * k + x * s, c + z * z * k],
    ]
    return out


class UrdfKinematics:
    """The kinematic tree of one URDF.

    Args:
        text: the URDF (XML text).

    Raises:
        ValueError: ``yourdfpy`` cannot parse it, or its joints do not make
            one tree (a link with two parents, no root, a joint naming a
            link that does not exist).

    Attributes:
        name: the robot's name.
        root: the root link (the one link that is no joint's child).
        joints: every joint, parents before children.
        links: every link name.
    """

    def __init__(self, text: str):
        import yourdfpy

        try:
            robot = yourdfpy.URDF.load(
                io.BytesIO(text.encode("utf-8")),
                build_scene_graph=False,
                load_meshes=False,
                filename_handler=yourdfpy.filename_handler_null,
            ).robot
        except Exception as exc:  # noqa: BLE001 - yourdfpy raises many kinds on bad XML
            raise ValueError(f"not a URDF yourdfpy can read: {exc}") from None
        self.name = robot.name
        self.links = [link.name for link in robot.links]
        known = set(self.links)
        parents: dict[str, str] = {}
        joints = []
        for j in robot.joints:
            if j.parent not in known or j.child not in known:
                raise ValueError(f"joint {j.name} joins {j.parent} and {j.child}, and the URDF has no such link")
            if j.child in parents:
                raise ValueError(f"link {j.child} is the child of two joints")
            parents[j.child] = j.parent
            axis = np.array([1.0, 0.0, 0.0]) if j.axis is None else np.asarray(j.axis, dtype=float)
            norm = np.linalg.norm(axis)
            if j.type in MOVING and not (np.isfinite(norm) and norm > 0):
                raise ValueError(f"joint {j.name} has no usable axis ({axis})")
            mimic = None
            if j.mimic is not None:
                mimic = (j.mimic.joint, float(j.mimic.multiplier or 1.0), float(j.mimic.offset or 0.0))
            origin = np.eye(4) if j.origin is None else np.asarray(j.origin, dtype=float)
            joints.append(UrdfJoint(j.name, j.type, j.parent, j.child, origin, axis / (norm or 1.0), mimic))
        roots = [link for link in self.links if link not in parents]
        if len(roots) != 1:
            raise ValueError(f"the URDF's links make {len(roots)} trees, not one (roots: {roots})")
        self.root = roots[0]
        # Parents before children: walk down from the root.
        children: dict[str, list[UrdfJoint]] = {}
        for j in joints:
            children.setdefault(j.parent, []).append(j)
        ordered, todo = [], [self.root]
        while todo:
            for j in children.get(todo.pop(0), []):
                ordered.append(j)
                todo.append(j.child)
        self.joints = ordered
        self.moving = [j for j in ordered if j.type in MOVING]

    def tree_text(self) -> str:
        """The tree as indented text, one link a line, each under the joint that carries it::

        CHASSIS
        ├─ TURRET_Y (revolute) -> TURRET_Y
        │  └─ TURRET_P (revolute) -> TURRET_P
        """
        children: dict[str, list[UrdfJoint]] = {}
        for j in self.joints:
            children.setdefault(j.parent, []).append(j)
        lines = [self.root]

        def walk(link: str, indent: str) -> None:
            below = children.get(link, [])
            for i, j in enumerate(below):
                last = i == len(below) - 1
                lines.append(f"{indent}{'└─' if last else '├─'} {j.name} ({j.type}) -> {j.child}")
                walk(j.child, indent + ("   " if last else "│  "))

        walk(self.root, "")
        return "\n".join(lines)

    def joint_values(self, names, positions) -> dict[str, float]:
        """The value of each moving joint a JointState gives (its ``name`` and ``position``).

        Entries for joints the URDF does not have, or with a non-finite
        position, or past the end of ``positions``, are left out; mimic
        joints follow the joint they mimic.
        """
        values: dict[str, float] = {}
        moving = {j.name for j in self.moving}
        for name, q in zip(names, positions):
            try:
                q = float(q)
            except (TypeError, ValueError):
                continue
            if name in moving and math.isfinite(q):
                values[name] = q
        for j in self.moving:
            if j.mimic is not None and j.mimic[0] in values:
                values[j.name] = j.mimic[1] * values[j.mimic[0]] + j.mimic[2]
        return values

    def static_transforms(self, stamp: tuple[int, int], prefix: str = "") -> list[Transform]:
        """The fixed joints' transforms (what ``/tf_static`` carries), parents first."""
        return [
            Transform.from_matrix(stamp, prefix + j.parent, prefix + j.child, j.origin)
            for j in self.joints
            if j.type == "fixed"
        ]

    def moving_transforms(self, values: dict[str, float], stamp: tuple[int, int], prefix: str = "") -> list[Transform]:
        """The transforms of the moving joints in ``values`` (see :meth:`joint_values`), parents first."""
        return [
            Transform.from_matrix(stamp, prefix + j.parent, prefix + j.child, j.motion(values[j.name]))
            for j in self.moving
            if j.name in values
        ]

    def link_poses(self, values: dict[str, float], root_pose: np.ndarray | None = None) -> dict[str, np.ndarray]:
        """Every link's pose (4x4) in the frame the root is in (the root's frame by default).

        A moving joint missing from ``values`` counts as 0; a floating or
        planar joint as its origin.
        """
        poses = {self.root: np.eye(4) if root_pose is None else np.asarray(root_pose, dtype=float)}
        for j in self.joints:
            poses[j.child] = poses[j.parent] @ j.motion(values.get(j.name, 0.0))
        return poses
