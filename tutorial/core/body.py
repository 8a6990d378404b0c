"""A body's view of a MuJoCo model: its links, numbered joints and actuators.

Choreonoid gives a controller a ``Body`` whose joints have ``q`` (position),
``dq`` (velocity) and ``u`` (torque).  :class:`Body` is that view over one
model inside the world built by :mod:`tutorial.core.world`: it reads and writes the
``MjData`` it was given and nothing else, so whoever owns that ``MjData``
(the simulation thread, or the viewer's main thread) owns the Body too.

What a body owns comes from the kinematic tree, not from names alone: its
*roots* are the world's top-level bodies that :func:`tutorial.core.world.build_world`
attached for it (named ``<name>/...``), and it owns every body in their
subtrees, named or not, with every joint, geom and site on them; also the
geoms and sites its model fixed to the world, and every actuator whose
transmission acts on something it owns (a joint, a tendon over its joints,
sites or geoms, a site, a body).

Numbered joints are the body's hinge and slide joints, in model order, except
those in joint group 3 (drive mechanisms such as the road wheels inside a
track).  Ball and free joints are not numbered: a JointState carries one
number per joint, and a ball joint needs four (a quaternion); the free joint
is the body's root pose, not a joint of the robot.  Every other joint the
body owns is listed in ``skipped_joints`` with the reason.

Joint names are the model's names without the ``<name>/`` prefix.  A joint
the model file leaves unnamed is named by ``build_world`` after its id in
the file: ``joint<i>``, ``i`` being its index when MuJoCo loads the file on
its own (``_1``, ``_2``, ... appended if the model already has that name;
see :func:`tutorial.core.world.name_unnamed_elements`).  A name is never empty:
a joint without one (a world not made by ``build_world``) is skipped.

Over 400 lines, and one job: Choreonoid's ``Body`` for one model of the world
(what it owns, its numbered joints and their names, its root's pose and where
it sits in ``qpos``), which controllers, checks and views all read the same way.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

MECHANISM_JOINT_GROUP = 3
NUMBERED_JOINT_TYPES = {int(mujoco.mjtJoint.mjJNT_HINGE): "hinge", int(mujoco.mjtJoint.mjJNT_SLIDE): "slide"}

# Actuator transmissions, by what they act on (MuJoCo's mjtTrn), and tendon wrap
# objects by the Body attribute that owns them (mjtWrap); all as ints.
_TRN_JOINT = int(mujoco.mjtTrn.mjTRN_JOINT)
_TRN_ON_JOINT = (_TRN_JOINT, int(mujoco.mjtTrn.mjTRN_JOINTINPARENT))
_TRN_ON_SITE = (int(mujoco.mjtTrn.mjTRN_SITE), int(mujoco.mjtTrn.mjTRN_SLIDERCRANK))
_TRN_ON_BODY = int(mujoco.mjtTrn.mjTRN_BODY)
_TRN_ON_TENDON = int(mujoco.mjtTrn.mjTRN_TENDON)
_BIAS_NONE = int(mujoco.mjtBias.mjBIAS_NONE)
_WRAP_OWNER = {
    int(mujoco.mjtWrap.mjWRAP_JOINT): "joint_ids",
    int(mujoco.mjtWrap.mjWRAP_SITE): "site_ids",
    int(mujoco.mjtWrap.mjWRAP_SPHERE): "geom_ids",
    int(mujoco.mjtWrap.mjWRAP_CYLINDER): "geom_ids",
}


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
        model: the world's compiled model, from :func:`tutorial.core.world.build_world`.
        data: the ``MjData`` to read and write; its owner thread owns this Body.
        name: the model's name in the world (``Tank``), the prefix of its elements.
        mimic: a joint coupled to another by a joint equality constraint (what
            MuJoCo makes of a URDF ``<mimic>``: a gripper's second finger)
            follows its leader in :meth:`notify_kinematic_state_change`, and
            is not numbered (a JointState does not carry it).  For a model
            that is drawn, not simulated: a simulation enforces the constraint.

    Attributes:
        root_ids: the model's top-level bodies (children of the world body), ids in order.
        root_id: the first of them, the root link whose pose :meth:`root_pose`
            gives; 0 (the world body) for a model of static geoms only (a room).
        body_ids, joint_ids, geom_ids, site_ids, actuator_ids: frozensets of
            the MuJoCo ids the body owns (see the module text).
        joint_infos: the numbered joints' static facts, in model order.
        skipped_joints: joint name -> why it is not numbered, for every other
            joint the body owns.
        followers: with ``mimic``, ``(follower qpos address, leader qpos address,
            polynomial coefficients (5,), follower's and leader's reference
            positions)`` per following joint.
        following: the names of those following joints (with ``mimic``; else
            empty).  A publisher may send them too (``joint_state_publisher``
            does): a viewer neither applies nor rejects them.

    Raises:
        KeyError: the world has no model named ``name``: no top-level body and
            no world geom or site is named ``name/...``.
    """

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, name: str, mimic: bool = False):
        self.model = model
        self.data = data
        self.name = name
        self.prefix = f"{name}/"
        self.kinematic_state_changes = 0  # notify_kinematic_state_change() calls: the app redraws when it grows
        m = model
        self.root_ids = tuple(
            b for b in range(1, m.nbody) if m.body_parentid[b] == 0 and self._prefixed(mujoco.mjtObj.mjOBJ_BODY, b)
        )
        roots = set(self.root_ids)
        # body_rootid: the top-level ancestor of each body, so a subtree is one comparison.
        self.body_ids = frozenset(b for b in range(1, m.nbody) if int(m.body_rootid[b]) in roots)
        self.joint_ids = frozenset(j for j in range(m.njnt) if int(m.jnt_bodyid[j]) in self.body_ids)
        self.geom_ids = self._on_bodies_or_world(m.ngeom, m.geom_bodyid, mujoco.mjtObj.mjOBJ_GEOM)
        self.site_ids = self._on_bodies_or_world(m.nsite, m.site_bodyid, mujoco.mjtObj.mjOBJ_SITE)
        if not self.body_ids and not self.geom_ids and not self.site_ids:
            raise KeyError(
                f"the world has no model named {name!r}: no top-level body, geom or site is named '{name}/...'"
            )
        self.actuator_ids = frozenset(a for a in range(m.nu) if self._acts_on_own(a))
        # A model of static geoms only (a room) has no link: its root is the world body.
        self.root_id = self.root_ids[0] if self.root_ids else 0
        self.joint_infos, self.skipped_joints = self._sort_joints()
        self.followers = self._followers() if mimic else []
        self.following: frozenset[str] = frozenset()
        if self.followers:
            following = {int(m.jnt_qposadr[j]) for j in self.joint_ids} & {f[0] for f in self.followers}
            for info in [i for i in self.joint_infos if i.qpos_adr in following]:
                self.skipped_joints[info.name] = "follows another joint (a URDF mimic joint)"
            self.following = frozenset(i.name for i in self.joint_infos if i.qpos_adr in following)
            self.joint_infos = [i for i in self.joint_infos if i.qpos_adr not in following]
        self.joints = [Joint(info, data) for info in self.joint_infos]
        self._by_name = {j.name: j for j in self.joints}

    # ---- ownership ----------------------------------------------------------
    def _prefixed(self, obj: mujoco.mjtObj, i: int) -> bool:
        return _name(self.model, obj, i).startswith(self.prefix)

    def _on_bodies_or_world(self, count: int, body_of, obj: mujoco.mjtObj) -> frozenset:
        """Elements on the body's links, and those its model fixed to the world (named ``<name>/...``)."""
        return frozenset(
            i for i in range(count) if int(body_of[i]) in self.body_ids or (body_of[i] == 0 and self._prefixed(obj, i))
        )

    def _acts_on_own(self, a: int) -> bool:
        """Whether actuator ``a``'s transmission acts on something this body owns."""
        m = self.model
        kind, target = int(m.actuator_trntype[a]), int(m.actuator_trnid[a, 0])
        if kind in _TRN_ON_JOINT:
            return target in self.joint_ids
        if kind in _TRN_ON_SITE:
            return target in self.site_ids
        if kind == _TRN_ON_BODY:
            return target in self.body_ids
        if kind == _TRN_ON_TENDON:  # a tendon of this model wraps only this model's elements
            first, count = int(m.tendon_adr[target]), int(m.tendon_num[target])
            for w in range(first, first + count):
                owner = _WRAP_OWNER.get(int(m.wrap_type[w]))  # None: a pulley, which owns nothing
                if owner is not None and int(m.wrap_objid[w]) in getattr(self, owner):
                    return True
            return False
        return self._prefixed(mujoco.mjtObj.mjOBJ_ACTUATOR, a)  # any other transmission: by its name

    # ---- static structure -------------------------------------------------
    def _joint_name(self, j: int) -> str:
        """The joint's name inside the body: the model's name without the prefix ("" if none)."""
        full = _name(self.model, mujoco.mjtObj.mjOBJ_JOINT, j)
        return full[len(self.prefix) :] if full.startswith(self.prefix) else full

    def _sort_joints(self) -> tuple[list[JointInfo], dict[str, str]]:
        """The numbered joints' infos, and every other owned joint's reason (see the module text)."""
        m = self.model
        motors = {}
        for a in sorted(self.actuator_ids):
            if int(m.actuator_trntype[a]) == _TRN_JOINT and int(m.actuator_biastype[a]) == _BIAS_NONE:
                motors.setdefault(int(m.actuator_trnid[a, 0]), a)
        why_not = {
            int(mujoco.mjtJoint.mjJNT_FREE): "free joint: the body's root pose, not a robot joint",
            int(mujoco.mjtJoint.mjJNT_BALL): "ball joint: a quaternion, JointState carries one number per joint",
        }
        infos: list[JointInfo] = []
        skipped: dict[str, str] = {}
        numbered: set[str] = set()
        for j in sorted(self.joint_ids):
            name = self._joint_name(j)
            kind = NUMBERED_JOINT_TYPES.get(int(m.jnt_type[j]))
            if not name:  # only in a world not made by build_world, which names every joint
                skipped[f"(unnamed joint {j})"] = "unnamed: no name to publish it under"
                continue
            if kind is None:
                skipped[name] = why_not[int(m.jnt_type[j])]
                continue
            if m.jnt_group[j] == MECHANISM_JOINT_GROUP:
                skipped[name] = "joint group 3: drive mechanism"
                continue
            if name in numbered:
                skipped[f"{name} (joint {j})"] = "its name is taken by another numbered joint of the body"
                continue
            numbered.add(name)
            limited = bool(m.jnt_limited[j])
            lo, hi = (float(m.jnt_range[j, 0]), float(m.jnt_range[j, 1])) if limited else (-np.inf, np.inf)
            motor = motors.get(j, -1)
            infos.append(
                JointInfo(
                    name=name,
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
        return infos, skipped

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

        MuJoCo's link poses (``MjData.xpos``, ``xquat``) are those of the last
        kinematics: after ``mj_forward`` or ``mj_kinematics``, of the current
        ``qpos``; after ``mj_step``, of the ``qpos`` the step started from.  So
        in a controller's ``control()``, which runs before each step, the pose
        is one time step (1 ms in the tank's world) older than ``qpos`` and
        ``io.current_time`` from the second call on, as the sensors' readings
        are (the first call follows the simulator's ``mj_forward``).
        """
        return self.data.xpos[self.root_id].copy(), self.data.xquat[self.root_id].copy()

    @property
    def root_qpos_address(self) -> int | None:
        """Where the root link's free joint starts in ``qpos``: its position (3,), m, then its orientation (4,),
        w x y z; None when the root has no free joint (it is fixed in the world).  Any thread (the model only)."""
        m, joint = self.model, self.model.body_jntadr[self.root_id]
        if joint < 0 or m.jnt_type[joint] != mujoco.mjtJoint.mjJNT_FREE:
            return None
        return int(m.jnt_qposadr[joint])

    def joint_positions(self) -> dict[str, float]:
        """Numbered joint positions by name, rad or m."""
        return {j.name: j.q for j in self.joints}

    def notify_kinematic_state_change(self) -> None:
        """Recompute link poses from ``qpos`` (forward kinematics).

        Choreonoid's ``notifyKinematicStateChange(true)`` does this and tells
        the views to redraw.  Here it counts the change in
        :attr:`kinematic_state_changes`, and a viewer's :class:`tutorial.app.app.App`
        draws a frame soon after (:meth:`tutorial.app.app.App.next_frame_due`).
        Only the owner thread of the data may call it.
        """
        for follower, leader, coef, q1_ref, q2_ref in self.followers:  # mimic joints first (see mimic)
            x = self.data.qpos[leader] - q2_ref
            self.data.qpos[follower] = q1_ref + coef[0] + x * (coef[1] + x * (coef[2] + x * (coef[3] + x * coef[4])))
        mujoco.mj_kinematics(self.model, self.data)
        self.kinematic_state_changes += 1

    def _followers(self) -> list:
        """The body's joint equality constraints between two hinge or slide joints (see ``mimic``)."""
        m, out = self.model, []
        for e in range(m.neq):
            if m.eq_type[e] != mujoco.mjtEq.mjEQ_JOINT or m.eq_obj2id[e] < 0:
                continue
            j1, j2 = int(m.eq_obj1id[e]), int(m.eq_obj2id[e])
            if j1 not in self.joint_ids or j2 not in self.joint_ids:
                continue
            a1, a2 = int(m.jnt_qposadr[j1]), int(m.jnt_qposadr[j2])
            out.append((a1, a2, m.eq_data[e][:5].copy(), float(m.qpos0[a1]), float(m.qpos0[a2])))
        return out


def _name(model: mujoco.MjModel, obj: mujoco.mjtObj, i: int) -> str:
    return mujoco.mj_id2name(model, obj, i) or ""
