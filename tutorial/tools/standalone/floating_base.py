"""A viewer's floating base: a robot's root link placed where its odometry says.

A JointState says how a robot's joints are set, not where the robot is.  A
robot that moves about (the tank, a quadruped) publishes that as
``nav_msgs/Odometry``: the pose of its root link in a world-fixed frame.  A
viewer project names the topic next to the model::

    models:
      - name: Go2
        description: /Go2/robot_description
        odometry: /Go2/odom

and the App gives the model's root link a free joint
(:func:`tutorial.core.world.build_world`) and attaches a :class:`FloatingBase`
to it.  Without ``odometry`` the root stays where the project places it.

The hand-off is Step 3's: the subscription's callback (spin thread) only
posts the message; the main thread checks it
(:func:`tutorial.interfaces.odometry.read_root_pose`), sets the free joint's
``qpos`` and recomputes the link poses, and the view redraws.  The
odometry's frame (``header.frame_id``: ``world``, ``odom`` or ``map``) is
taken as the viewer's world.
"""

from __future__ import annotations

from collections import Counter

import mujoco

from tutorial.core.controller import ControllerConfig, SimpleController
from tutorial.interfaces.odometry import RootMotion, read_root_pose


class FloatingBase(SimpleController):
    """Places a body's root link by the ``nav_msgs/Odometry`` on ``topic``; the App attaches it.

    QoS: reliable, keep last 1, volatile, as the joint-state viewer's
    (:func:`tutorial.interfaces.joint_state.joint_state_viewer_qos`): it
    matches reliable publishers whether they keep their last message or not,
    and the final pose arrives.  A best-effort publisher (sensor-data QoS)
    does not match.  As the Step 3 monitor does for joint states, a second,
    transient-local subscription takes the newest pose a publisher kept
    from before the viewer started (a paused or finished simulation's): it
    is shown if no live pose has come, then dropped.  Poses are applied in
    the order they arrive; their stamps are not compared.

    Args:
        topic: the odometry topic, e.g. ``/Go2/odom``.
    """

    def __init__(self, topic: str):
        self.topic = topic

    # ---- main thread ------------------------------------------------------
    def configure(self, config: ControllerConfig) -> bool:
        from nav_msgs.msg import Odometry

        from tutorial.interfaces.joint_state import joint_state_viewer_qos
        from tutorial.interfaces.odometry import odometry_qos

        self.config = config
        self.body = body = config.body
        model = body.model
        self.root_link = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, body.root_id).removeprefix(body.prefix)
        # Where the root's free joint keeps its pose in qpos: the odometry publisher's RootMotion reads it there.
        self.qpos_adr = RootMotion(model, body.root_id).free_qpos
        if self.qpos_adr is None:
            config.log.error(
                "%s: the root link %s of %s has no free joint to place", self.topic, self.root_link, body.name
            )
            return False
        self.applied = 0
        self.rejected: Counter = Counter()
        self.subscription = config.node.create_subscription(
            Odometry, self.topic, self.on_odometry, joint_state_viewer_qos()
        )
        # Transient local: matches transient-local publishers only, which hand it the pose they kept.
        self.late_subscription = config.node.create_subscription(
            Odometry, self.topic, self.on_late_pose, odometry_qos()
        )
        return True

    def unconfigure(self) -> None:
        self.drop_late_subscription()
        self.config.node.destroy_subscription(self.subscription)

    # ---- spin thread --------------------------------------------------------
    def on_odometry(self, msg) -> None:
        """Subscription callback (spin thread): hand the message over, touch nothing."""
        self.config.call_later(self.update_root_pose, msg)

    def on_late_pose(self, msg) -> None:
        self.config.call_later(self.show_late_pose, msg)

    # ---- main thread ------------------------------------------------------
    def show_late_pose(self, msg) -> None:
        """The newest pose from before the viewer started: applied if no live pose came, then no more."""
        if self.applied == 0 and self.late_subscription is not None:
            self.update_root_pose(msg)
        self.drop_late_subscription()

    def drop_late_subscription(self) -> None:
        if getattr(self, "late_subscription", None) is not None:
            self.config.node.destroy_subscription(self.late_subscription)
            self.late_subscription = None

    def update_root_pose(self, msg) -> None:
        """Place the root link by one message, or count why not (main thread)."""
        pose = read_root_pose(msg, self.root_link)
        if isinstance(pose, str):
            self.rejected[pose] += 1
            if self.rejected[pose] == 1:  # said once per reason, then counted
                text = f"{self.topic}: pose refused ({pose}): the root link is {self.root_link!r}"
                if pose == "wrong_frame":
                    text += f", the message names {msg.child_frame_id!r}"
                node = self.config.node.get_fully_qualified_name()
                self.config.output(
                    {
                        "event": "warning",
                        "node": node,
                        "topic": self.topic,
                        "reason": pose,
                        "message": text,
                        "line": f"[{node}] {text}",
                    }
                )
            return
        position, quat = pose
        a = self.qpos_adr
        self.body.data.qpos[a : a + 3] = position
        self.body.data.qpos[a + 3 : a + 7] = quat
        self.body.notify_kinematic_state_change()
        self.applied += 1
        self.drop_late_subscription()  # a pose is shown: the kept one is no longer needed

    def summary(self) -> dict:
        a = self.qpos_adr
        qpos = self.body.data.qpos
        return {
            "topic": self.topic,
            "root_link": self.root_link,
            "applied": self.applied,
            "rejected": dict(sorted(self.rejected.items())),
            "position": [round(float(v), 9) for v in qpos[a : a + 3]],
            "orientation_wxyz": [round(float(v), 9) for v in qpos[a + 3 : a + 7]],
        }
