# Frozen from notebooks/02_step2_joint_state_publisher.ipynb by scripts/freeze_reference.py: the later steps
# stand on this copy, so editing that notebook changes its own step only.

"""Step 2: publish the body's joint state from the simulation.

Built in ``notebooks/02_step2_joint_state_publisher.ipynb``: edit it there,
then run ``make export``.  Topic ``/<body name>/joint_state``, type
``sensor_msgs/JointState``: one entry per numbered joint with its position
(rad or m), velocity (rad/s or m/s) and effort (N*m or N), stamped with
*simulation* time, at ``rate`` Hz of simulated time.  It also publishes
the state the simulation starts in (from ``start()``) and the state it
ends in (from ``stop()``).
"""

from __future__ import annotations

from ...core.controller import ControllerConfig, ControllerIO, SimpleController
from ...core.period import PeriodAccumulator
from ...interfaces.joint_state import joint_state_qos, joint_state_topic
from ...interfaces.timing import stamp_parts

DEFAULT_RATE = 50.0  # Hz of simulated time

__all__ = ["DEFAULT_RATE", "RttJointStatePublisher"]


class RttJointStatePublisher(SimpleController):
    """Step 2 controller: publishes ``/<body>/joint_state`` at ``rate`` Hz (simulated).

    QoS: :func:`tutorial.interfaces.joint_state.joint_state_qos`.  It
    publishes the state the simulation starts in from ``start()`` and the
    state it ends in from ``stop()``, so a subscriber sees where the body
    is from the first moment to the last, whatever the rate: transient
    local keeps the newest state for one that joins later.
    """

    PARAMETERS = {
        "rate": (
            float,
            DEFAULT_RATE,
            "publish rate, Hz of simulated time (0: every step)",
        )
    }

    # ---- main thread ------------------------------------------------------
    def configure(self, config: ControllerConfig) -> bool:
        from sensor_msgs.msg import JointState

        self.node = config.node
        self.rate = config.parameters["rate"]
        if self.rate < 0:
            config.log.error("rate must be >= 0 Hz, got %s", self.rate)
            return False
        self.topic = joint_state_topic(config.body_name)
        self.msg_type = JointState
        self.publisher = config.node.create_publisher(JointState, self.topic, joint_state_qos())
        self.published = 0
        return True

    def unconfigure(self) -> None:
        # Give the final state time to reach reliable subscribers first.
        from rclpy.duration import Duration

        self.publisher.wait_for_all_acked(Duration(seconds=1))
        self.node.destroy_publisher(self.publisher)

    # ---- simulation thread --------------------------------------------------
    def initialize(self, io: ControllerIO) -> bool:
        self.data = io.data
        # start() sends the first state: the periodic ones begin a period later.
        self.accumulator = PeriodAccumulator(io.time_step, self.rate, first_due=False)
        # Each numbered joint's name, and where its numbers are in MjData:
        # qpos[qpos_adr] is its position, qvel[dof_adr] its velocity.
        self.joints = io.body.joint_infos
        return True

    def start(self) -> bool:
        self.publish()  # the state the simulation starts in, before the first step
        return True

    def control(self) -> bool:
        if self.accumulator.tick():
            self.publish()
        return True

    def stop(self) -> None:
        self.publish()  # the state the simulation ended in

    def publish(self) -> None:
        """Make a JointState of the simulation state now and publish it."""
        data, joints = self.data, self.joints
        msg = self.msg_type()
        msg.header.stamp.sec, msg.header.stamp.nanosec = stamp_parts(data.time)
        msg.name = [j.name for j in joints]
        # rad (hinge) or m (slide); rad/s or m/s; N*m or N, from the actuators
        msg.position = [float(data.qpos[j.qpos_adr]) for j in joints]
        msg.velocity = [float(data.qvel[j.dof_adr]) for j in joints]
        msg.effort = [float(data.qfrc_actuator[j.dof_adr]) for j in joints]
        self.publisher.publish(msg)
        self.published += 1

    def summary(self) -> dict:
        return {"topic": self.topic, "rate": self.rate, "published": self.published}
