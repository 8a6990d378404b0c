"""Step 2: publish the body's joint state from the simulation.

``control()`` runs every step (1 ms), but a subscriber needs far fewer
states.  An accumulator adds the step to a clock and publishes each time a
period has passed, carrying the remainder over, so the rate holds exactly on
average.  It counts in integer nanoseconds, so the comparison with the
period is exact by construction: no floating-point rounding to reason about
(0.001 added twenty times is not exactly 0.02 in binary floating point).

Topic ``/<body name>/joint_state`` (``/Tank/joint_state``), type
``sensor_msgs/JointState``: one entry per numbered joint (see
:mod:`tutorial.body`) with position (rad or m), velocity (rad/s or m/s) and
effort (N*m or N), stamped with *simulation* time.

QoS: reliable, keep last 1, volatile.  Only the newest state matters to a
viewer (an older one is already out of date), but it should arrive: with
"reliable", the last state before the simulation stops reaches the viewer
instead of being lost on a busy link.
"""

from __future__ import annotations

from array import array

from tutorial.controller import ControllerConfig, ControllerIO, SimpleController

DEFAULT_RATE = 50.0  # Hz


def joint_state_topic(body_name: str) -> str:
    """``/<body name>/joint_state``: the topic is named after the body, so any model works."""
    return f"/{body_name}/joint_state"


def joint_state_qos():
    """Reliable, keep last 1, volatile (see the module text for why)."""
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

    return QoSProfile(depth=1, history=HistoryPolicy.KEEP_LAST, reliability=ReliabilityPolicy.RELIABLE,
                      durability=DurabilityPolicy.VOLATILE)


class PeriodAccumulator:
    """Decides, step by step, when a periodic output is due.

    Args:
        time_step: the simulation step, s.
        rate: outputs per simulated second, Hz; a rate at or above one per
            step (or 0) means every step.

    ``tick()`` is called once per step and returns True when an output is
    due; the first step is always due.  Exact for any step and rate that are
    whole numbers of nanoseconds.  Used by one thread only.
    """

    def __init__(self, time_step: float, rate: float):
        self.step_ns = max(1, round(time_step * 1e9))
        self.period_ns = self.step_ns if rate <= 0 else max(self.step_ns, round(1e9 / rate))
        self.elapsed_ns = self.period_ns  # due at once

    def tick(self) -> bool:
        if self.elapsed_ns >= self.period_ns:
            self.elapsed_ns -= self.period_ns
            self.elapsed_ns += self.step_ns
            return True
        self.elapsed_ns += self.step_ns
        return False


class RttJointStatePublisher(SimpleController):
    """Step 2 controller: publishes ``/<body>/joint_state`` at ``rate`` Hz of simulated time."""

    PARAMETERS = {"rate": (float, DEFAULT_RATE, "JointState publish rate, Hz of simulated time (0: every step)")}

    def configure(self, config: ControllerConfig) -> bool:
        from sensor_msgs.msg import JointState

        self.node = config.node
        self.rate = config.parameters["rate"]
        if self.rate < 0:
            config.log.error("rate must be >= 0, got %s", self.rate)
            return False
        self.topic = joint_state_topic(config.body_name)
        self.msg_type = JointState
        self.publisher = config.node.create_publisher(JointState, self.topic, joint_state_qos())
        self.published = 0
        return True

    def initialize(self, io: ControllerIO) -> bool:
        self.io = io
        self.data = io.data
        self.joints = io.body.joint_infos
        self.accumulator = PeriodAccumulator(io.time_step, self.rate)
        # One message, reused, with its three arrays allocated once and refilled
        # in place: the names never change, and rclpy copies the message inside
        # publish(), so refilling it afterwards is safe.  The values are read
        # through memoryviews of the MjData arrays (see tutorial.body.Joint).
        n = len(self.joints)
        self.msg = self.msg_type()
        self.msg.name = [j.name for j in self.joints]
        self.msg.position, self.msg.velocity, self.msg.effort = (array("d", bytes(8 * n)) for _ in range(3))
        self.stamp = self.msg.header.stamp
        self.sources = (memoryview(io.data.qpos), memoryview(io.data.qvel), memoryview(io.data.qfrc_actuator))
        self.addresses = [(i, j.qpos_adr, j.dof_adr) for i, j in enumerate(self.joints)]
        return True

    def control(self) -> bool:
        if self.accumulator.tick():
            self.publish()
        return True

    def stop(self) -> None:
        # The state the simulation ended in: subscribers see where it stopped.
        self.publish()

    def publish(self) -> None:
        """Fill the JointState from the current simulation state and publish it (simulation thread)."""
        t = self.data.time
        sec = int(t)
        self.stamp.sec = sec
        self.stamp.nanosec = min(999_999_999, int(round((t - sec) * 1e9)))
        msg = self.msg
        position, velocity, effort = msg.position, msg.velocity, msg.effort
        qpos, qvel, qfrc = self.sources
        for i, qpos_adr, dof_adr in self.addresses:
            position[i] = qpos[qpos_adr]  # rad (hinge) or m (slide)
            velocity[i] = qvel[dof_adr]  # rad/s or m/s
            effort[i] = qfrc[dof_adr]  # N*m or N, from the actuators
        self.publisher.publish(msg)
        self.published += 1

    def unconfigure(self) -> None:
        # Give the final state time to reach reliable subscribers before the publisher goes.
        self.publisher.wait_for_all_acked(_duration(1.0))
        self.node.destroy_publisher(self.publisher)

    def summary(self) -> dict:
        return {"topic": self.topic, "rate": self.rate, "published": self.published}


def _duration(seconds: float):
    from rclpy.duration import Duration

    return Duration(nanoseconds=int(seconds * 1e9))
