"""A body's view of a MuJoCo model: its links, numbered joints and actuators.

Choreonoid gives a controller a ``Body`` whose joints have ``q`` (position),
``dq`` (velocity) and ``u`` (torque).  :class:`Body` is that view over one
model inside the world built by :mod:`tutorial.world`: it reads and writes the
``MjData`` it was given and nothing else, so whoever owns that ``MjData``
(the simulation thread, or the viewer's main thread) owns the Body too.

Numbered joints are the body's hinge and slide joints, in model order, except
those in joint group 3 (drive mechanisms such as the road wheels inside a
track).  Ball and free joints are not numbered: a JointState carries one
number per joint, and a ball joint needs four (a quaternion); the free joint
is the body's root pose, not a joint of the robot.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

MECHANISM_JOINT_GROUP = 3
NUMBERED_JOINT_TYPES = {int(mujoco.mjtJoint.mjJNT_HINGE): "hinge", int(mujoco.mjtJoint.mjJNT_SLIDE): "slide"}


@dataclass(frozen=True)
class JointInfo:
    """Static facts of one numbered joint (any thread may read them).

    Attributes:
        name: name inside the body, e.g. ``TURRET_Y``.
        index: position in the body's numbered-joint list (Choreonoid's joint id).
        joint_id: MuJoCo joint id in the world model.
        kind: ``hinge`` (rad) or ``slide`` (m).
        qpos_adr: address in ``MjData.qpos``.
        dof_adr: address in ``MjData.qvel``.
        limited: whether ``lower``/``upper`` apply.
        lower: lower limit (rad or m), ``-inf`` when unlimited.
        upper: upper limit (rad or m), ``+inf`` when unlimited.
        motor: id of the actuator that applies a force/torque to it, or -1.
        gear: that actuator's gear (force = ctrl * gear).
    """

    name: str
    index: int
    joint_id: int
    kind: str
    qpos_adr: int
    dof_adr: int
    limited: bool
    lower: float
    upper: float
    motor: int
    gear: float


class Joint:
    """One numbered joint read and written through an ``MjData``.

    ``q`` is the position (rad or m), ``dq`` the velocity (rad/s or m/s) and
    ``u`` the commanded torque or force (N*m or N) of its motor actuator.
    Only the thread that owns the ``MjData`` may use it.
    """

    # The MjData arrays are fixed buffers, so each is wrapped once in a
    # memoryview.  Reading or writing one element through a memoryview gives a
    # plain Python float and costs about half as much as indexing the numpy
    # array; controllers do it several times in every 1 ms step.
    __slots__ = ("info", "_qpos", "_qvel", "_ctrl", "_force", "_qadr", "_vadr", "_motor", "_gear")

    def __init__(self, info: JointInfo, data: mujoco.MjData):
        self.info = info
        self._qpos, self._qvel = memoryview(data.qpos), memoryview(data.qvel)
        self._ctrl, self._force = memoryview(data.ctrl), memoryview(data.actuator_force)
        self._qadr, self._vadr, self._motor, self._gear = info.qpos_adr, info.dof_adr, info.motor, info.gear

    @property
    def name(self) -> str:
        return self.info.name

    @property
    def q(self) -> float:
        return self._qpos[self._qadr]

    @q.setter
    def q(self, value: float) -> None:
        self._qpos[self._qadr] = value  # TypeError unless a number

    @property
    def dq(self) -> float:
        return self._qvel[self._vadr]

    @property
    def u(self) -> float:
        """Torque (N*m) or force (N) from the motor; 0 when the joint has none."""
        if self._motor < 0:
            return 0.0
        return self._force[self._motor]

    @u.setter
    def u(self, value: float) -> None:
        if self._motor < 0:
            raise AttributeError(f"joint {self.info.name} has no motor actuator to take a torque")
        self._ctrl[self._motor] = value / self._gear


class Track:
    """A continuous track driven by its surface velocity (Choreonoid's ``dq_target``).

    Backed by a velocity actuator named after the track whose control value is
    the track surface velocity in m/s (see ``model/tank.xml``).
    Only the thread that owns the ``MjData`` may use it.
    """

    __slots__ = ("name", "actuator_id", "_ctrl")

    def __init__(self, name: str, actuator_id: int, data: mujoco.MjData):
        self.name = name
        self.actuator_id = actuator_id
        self._ctrl = memoryview(data.ctrl)  # as in Joint

    @property
    def dq_target(self) -> float:
        """Commanded surface velocity, m/s (forward positive)."""
        return self._ctrl[self.actuator_id]

    @dq_target.setter
    def dq_target(self, value: float) -> None:
        self._ctrl[self.actuator_id] = value


class Body:
    """One model of the world (e.g. ``Tank``) seen through one ``MjData``.

    Args:
        model: the world's compiled model.
        data: the ``MjData`` to read and write; its owner thread owns this Body.
        name: the body name used as the element prefix (``Tank``).

    Raises:
        KeyError: the world has no bodies or geoms under ``name/``.
    """

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, name: str):
        self.model = model
        self.data = data
        self.name = name
        self.prefix = f"{name}/"
        body_ids = [i for i in range(model.nbody) if _name(model, mujoco.mjtObj.mjOBJ_BODY, i).startswith(self.prefix)]
        geom_ids = [i for i in range(model.ngeom) if _name(model, mujoco.mjtObj.mjOBJ_GEOM, i).startswith(self.prefix)]
        if not body_ids and not geom_ids:
            raise KeyError(f"the world has no model named {name!r}")
        self.body_ids = frozenset(body_ids)
        # A model of static geoms only (a room) has no link: its root is the world body.
        self.root_id = body_ids[0] if body_ids else 0
        self.joint_infos = self._numbered_joints()
        self.joints = [Joint(info, data) for info in self.joint_infos]
        self._by_name = {j.name: j for j in self.joints}
        self.skipped_joints = self._skipped_joints()

    # ---- static structure -------------------------------------------------
    def _numbered_joints(self) -> list[JointInfo]:
        m = self.model
        motors = {}
        for a in range(m.nu):
            if m.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_JOINT and m.actuator_biastype[a] == mujoco.mjtBias.mjBIAS_NONE:
                motors.setdefault(int(m.actuator_trnid[a, 0]), a)
        infos = []
        for j in range(m.njnt):
            if m.jnt_bodyid[j] not in self.body_ids:
                continue
            kind = NUMBERED_JOINT_TYPES.get(int(m.jnt_type[j]))
            if kind is None or m.jnt_group[j] == MECHANISM_JOINT_GROUP:
                continue
            limited = bool(m.jnt_limited[j])
            lo, hi = (float(m.jnt_range[j, 0]), float(m.jnt_range[j, 1])) if limited else (-np.inf, np.inf)
            motor = motors.get(j, -1)
            infos.append(
                JointInfo(
                    name=_name(m, mujoco.mjtObj.mjOBJ_JOINT, j)[len(self.prefix):],
                    index=len(infos),
                    joint_id=j,
                    kind=kind,
                    qpos_adr=int(m.jnt_qposadr[j]),
                    dof_adr=int(m.jnt_dofadr[j]),
                    limited=limited,
                    lower=lo,
                    upper=hi,
                    motor=motor,
                    gear=float(m.actuator_gear[motor, 0]) if motor >= 0 else 1.0,
                )
            )
        return infos

    def _skipped_joints(self) -> dict[str, str]:
        m = self.model
        numbered = {info.joint_id for info in self.joint_infos}
        why = {
            int(mujoco.mjtJoint.mjJNT_FREE): "free joint: the body's root pose, not a robot joint",
            int(mujoco.mjtJoint.mjJNT_BALL): "ball joint: a quaternion, JointState carries one number per joint",
        }
        skipped = {}
        for j in range(m.njnt):
            if m.jnt_bodyid[j] in self.body_ids and j not in numbered:
                reason = why.get(int(m.jnt_type[j]), "joint group 3: drive mechanism")
                skipped[_name(m, mujoco.mjtObj.mjOBJ_JOINT, j)[len(self.prefix):]] = reason
        return skipped

    @property
    def num_joints(self) -> int:
        return len(self.joints)

    @property
    def joint_names(self) -> list[str]:
        return [j.name for j in self.joints]

    def joint(self, key: int | str) -> Joint:
        """A numbered joint by index or name.

        Raises:
            KeyError: no numbered joint has that name.
            IndexError: the index is out of range.
        """
        if isinstance(key, str):
            try:
                return self._by_name[key]
            except KeyError:
                raise KeyError(f"body {self.name} has no numbered joint {key!r}; it has {self.joint_names}") from None
        return self.joints[key]

    def track(self, name: str) -> Track:
        """The track driven by the velocity actuator ``<body>/<name>``.

        Raises:
            KeyError: no actuator of that name.
        """
        a = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_ACTUATOR, self.prefix + name)
        if a < 0:
            raise KeyError(f"body {self.name} has no track actuator {name!r}")
        return Track(name, a, self.data)

    # ---- state ------------------------------------------------------------
    def root_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """Root link position (3,) in m and orientation quaternion (4,) w,x,y,z.

        Valid after ``mj_step`` or ``mj_kinematics`` on the data.
        """
        return self.data.xpos[self.root_id].copy(), self.data.xquat[self.root_id].copy()

    def joint_positions(self) -> dict[str, float]:
        """Numbered joint positions by name, rad or m."""
        return {j.name: j.q for j in self.joints}

    def notify_kinematic_state_change(self) -> None:
        """Recompute link poses from ``qpos`` (forward kinematics).

        Choreonoid's ``notifyKinematicStateChange(true)`` does this and tells
        the views to redraw; :class:`tutorial.scene.Scene` redraws on its next frame.
        Only the owner thread of the data may call it.
        """
        mujoco.mj_kinematics(self.model, self.data)


def _name(model: mujoco.MjModel, obj: mujoco.mjtObj, i: int) -> str:
    return mujoco.mj_id2name(model, obj, i) or ""
