"""``/<body>/odom`` (``nav_msgs/Odometry``): where the body's root link is, and how it moves.

JointState says how the body's joints are set; it does not say where the
body is.  The odometry does: the pose of the body's URDF root link (the
tank's ``CHASSIS``) in the world, and its velocity, stamped with simulation
time.  With the joint states and the robot description it is all a TF tree
needs (:mod:`tutorial.tools.bag.record_tf`).

Frames and units (REP 103, REP 105):

* ``header.frame_id`` :data:`WORLD_FRAME` (``world``): the simulation's
  world, x and y on the floor, z up.  REP 105's ``odom`` is a world-fixed
  frame in which a robot's pose moves continuously, and ``map`` one in which
  it does not drift; the simulation's world is both (its poses are exact),
  and is called ``world`` here, as in Gazebo's ground-truth odometry;
* ``child_frame_id``: the root link, named as in the URDF (REP 105 calls
  that frame ``base_link``; here it keeps the model's name);
* ``pose``: position in m, orientation a unit quaternion (x, y, z, w);
* ``twist``: in the *child* frame, as ``nav_msgs/Odometry`` defines it:
  linear m/s, angular rad/s, both at the root link's origin (x forward,
  y left, z up for the tank);
* covariances: all 0 (exact: the simulation knows its state).

Topic :func:`odometry_topic`; QoS :func:`odometry_qos`.  A viewer reads the
root link's pose from a received message with :func:`read_root_pose`.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

WORLD_FRAME = "world"


def odometry_topic(body_name: str) -> str:
    """``/<body name>/odom``, e.g. ``/Tank/odom``."""
    return f"/{body_name}/odom"


def odometry_qos():
    """The odometry's QoS: reliable, keep last 1, transient local, as the joint state's.

    The two are read together (a TF tree needs both), so they are published
    alike: the newest only; reliable, so the final pose arrives; transient
    local, so a recorder or monitor that joins a paused simulation still
    gets where the body is.  A volatile subscriber (most of the ROS world)
    matches it too.
    """
    from tutorial.interfaces.joint_state import joint_state_qos

    return joint_state_qos()


class RootMotion:
    """Reads the root link's pose and velocity from an ``MjData`` (its owner thread only).

    Args:
        model: the world's ``MjModel``.
        root_body: the MuJoCo id of the root link's body, or None when the
            root link stands for the world frame the model is placed in
            (``tutorial.tools.urdf.export.ROOT_WORLD``: its pose is the identity).

    The pose and velocity come from ``qpos``/``qvel`` directly (a free
    joint's numbers; the model's placement for a body welded to the world),
    not from ``xpos``, which MuJoCo computes one step late: so the odometry
    and the joint states of one step describe the same instant.
    """

    def __init__(self, model: mujoco.MjModel, root_body: int | None):
        self.free_qpos = self.free_dof = None
        self.fixed_pose = (np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]))
        if root_body is None:
            return
        first = int(model.body_jntadr[root_body]) if model.body_jntnum[root_body] else -1
        if first >= 0 and model.jnt_type[first] == mujoco.mjtJoint.mjJNT_FREE:
            self.free_qpos, self.free_dof = int(model.jnt_qposadr[first]), int(model.jnt_dofadr[first])
        else:  # welded to the world: where the model placed it
            self.fixed_pose = (np.array(model.body_pos[root_body]), np.array(model.body_quat[root_body]))

    def read(self, data: mujoco.MjData) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(position (3,) m, quaternion (4,) w x y z, linear (3,) m/s, angular (3,) rad/s)``.

        Velocities are in the root link's frame (see the module text).
        """
        if self.free_qpos is None:
            position, quat = self.fixed_pose
            return position.copy(), quat.copy(), np.zeros(3), np.zeros(3)
        a, d = self.free_qpos, self.free_dof
        position = np.array(data.qpos[a : a + 3])
        quat = np.array(data.qpos[a + 3 : a + 7])
        quat /= np.linalg.norm(quat)
        # A free joint's qvel: linear velocity in the world frame, angular in the body's.
        rotation = np.zeros(9)
        mujoco.mju_quat2Mat(rotation, quat)
        linear = rotation.reshape(3, 3).T @ np.array(data.qvel[d : d + 3])
        return position, quat, linear, np.array(data.qvel[d + 3 : d + 6])


def fill_odometry(msg, stamp: tuple[int, int], child_frame: str, motion) -> None:
    """Write one :meth:`RootMotion.read` result into a ``nav_msgs/Odometry`` (any thread that owns ``msg``).

    Args:
        msg: the message to fill (its covariances are left as they are: 0).
        stamp: ``(sec, nanosec)`` of simulation time.
        child_frame: the root link's name.
        motion: ``(position, quaternion w x y z, linear, angular)``.
    """
    position, (w, x, y, z), linear, angular = motion
    msg.header.stamp.sec, msg.header.stamp.nanosec = stamp
    msg.header.frame_id = WORLD_FRAME
    msg.child_frame_id = child_frame
    p, o = msg.pose.pose.position, msg.pose.pose.orientation
    p.x, p.y, p.z = (float(v) for v in position)
    o.x, o.y, o.z, o.w = float(x), float(y), float(z), float(w)  # ROS's order: x, y, z, w
    v, a = msg.twist.twist.linear, msg.twist.twist.angular
    v.x, v.y, v.z = (float(c) for c in linear)
    a.x, a.y, a.z = (float(c) for c in angular)


REJECTIONS = ("wrong_frame", "not_finite", "too_far", "not_a_unit_quaternion")
QUATERNION_TOLERANCE = 0.01  # how far |q| may be from 1 before a pose is refused, not renormalised
POSITION_LIMIT = 1e6  # m: a root farther from the frame's origin than 1,000 km is no robot's pose


def read_root_pose(msg, root_link: str) -> tuple[np.ndarray, np.ndarray] | str:
    """The root link's pose a received ``nav_msgs/Odometry`` gives, or why it gives none.

    Received data is never trusted: a viewer places the robot only by a pose
    that is one.

    Args:
        msg: the message (any object with its fields).
        root_link: the name of the model's root link (``CHASSIS``, ``base``).

    Returns:
        ``(position (3,) m, quaternion (4,) w x y z of norm 1)``, the pose of
        the root link in the odometry's frame; or one of :data:`REJECTIONS`:
        ``wrong_frame`` (``child_frame_id`` names another frame than the root
        link; an empty one is taken as the root link), ``not_finite`` (a NaN
        or an infinity in the pose), ``too_far`` (a coordinate beyond
        :data:`POSITION_LIMIT`), ``not_a_unit_quaternion`` (its norm is more
        than :data:`QUATERNION_TOLERANCE` from 1; a pose a little off is
        renormalised).  The twist is not read.  Any thread.
    """
    if msg.child_frame_id not in ("", root_link):
        return "wrong_frame"
    p, o = msg.pose.pose.position, msg.pose.pose.orientation
    position = np.array([p.x, p.y, p.z], dtype=float)
    quat = np.array([o.w, o.x, o.y, o.z], dtype=float)  # MuJoCo's order: w first
    if not (np.isfinite(position).all() and np.isfinite(quat).all()):
        return "not_finite"
    if np.abs(position).max() > POSITION_LIMIT:
        return "too_far"
    norm = math.hypot(*quat)  # no overflow on a huge quaternion: inf, refused below
    if abs(norm - 1.0) > QUATERNION_TOLERANCE:
        return "not_a_unit_quaternion"
    return position, quat / norm
