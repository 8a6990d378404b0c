# Frozen from notebooks/09_stock_ros2_tools.ipynb by scripts/freeze_reference.py: the later steps
# stand on this copy, so editing that notebook changes its own step only.

"""What the stock ROS 2 tools need to draw a body: its URDF and its odometry.

Built in ``notebooks/09_stock_ros2_tools.ipynb``: edit it there, then run
``make export``.  ``/<body>/robot_description`` (``std_msgs/String``): the
body's URDF, published once, kept for late joiners.  ``/<body>/odom``
(``nav_msgs/Odometry``): the root link's pose in ``world`` and its velocity
in its own frame, stamped with simulation time, at ``rate`` Hz.
"""

from __future__ import annotations

from tutorial.interfaces.odometry import (
    RootMotion,
    fill_odometry,
    odometry_qos,
    odometry_topic,
)
from tutorial.interfaces.robot_description import (
    robot_description_qos,
    robot_description_topic,
)

from ...core.controller import ControllerConfig, ControllerIO, SimpleController
from ...core.period import PeriodAccumulator
from ...interfaces.timing import stamp_parts
from ...tools.urdf.export import export_body

DEFAULT_RATE = 50.0  # Hz of simulated time: the joint states' rate

__all__ = ["DEFAULT_RATE", "RttRobotModelPublisher"]


class RttRobotModelPublisher(SimpleController):
    """Publishes ``/<body>/robot_description`` once and ``/<body>/odom`` at ``rate`` Hz.

    QoS: :func:`tutorial.interfaces.robot_description.robot_description_qos`
    and :func:`tutorial.interfaces.odometry.odometry_qos`.  When the
    simulation stops it publishes the final odometry once more.
    """

    PARAMETERS = {
        "rate": (
            float,
            DEFAULT_RATE,
            "odometry rate, Hz of simulated time (0: every step)",
        )
    }

    # ---- main thread ------------------------------------------------------
    def configure(self, config: ControllerConfig) -> bool:
        from nav_msgs.msg import Odometry
        from std_msgs.msg import String

        self.node = config.node
        self.rate = config.parameters["rate"]
        if self.rate < 0:
            config.log.error("rate must be >= 0 Hz, got %s", self.rate)
            return False
        # The URDF, from the body's model (the same names as its JointState).
        self.urdf = export_body(config.body)
        source = f"body {config.body_name} of the simulation"
        self.description = self.urdf.description(source=source)
        self.description_topic = robot_description_topic(config.body_name)
        self.description_publisher = config.node.create_publisher(
            String, self.description_topic, robot_description_qos()
        )
        # Published once: the publisher keeps it for everyone who joins later.
        self.description_publisher.publish(String(data=self.description))
        self.topic = odometry_topic(config.body_name)
        self.msg_type = Odometry
        self.publisher = config.node.create_publisher(Odometry, self.topic, odometry_qos())
        self.published = 0
        return True

    def unconfigure(self) -> None:
        from rclpy.duration import Duration

        self.publisher.wait_for_all_acked(Duration(seconds=1))
        self.node.destroy_publisher(self.publisher)
        self.node.destroy_publisher(self.description_publisher)

    # ---- simulation thread --------------------------------------------------
    def initialize(self, io: ControllerIO) -> bool:
        self.data = io.data
        self.accumulator = PeriodAccumulator(io.time_step, self.rate)
        self.motion = RootMotion(io.body.model, self.urdf.root_body)
        self.msg = self.msg_type()  # one message, refilled: publish() copies it
        return True

    def control(self) -> bool:
        if self.accumulator.tick():
            self.publish()
        return True

    def stop(self) -> None:
        self.publish()  # where the body ended

    def publish(self) -> None:
        """Fill the odometry from the simulation state and publish it."""
        stamp = stamp_parts(self.data.time)
        motion = self.motion.read(self.data)
        fill_odometry(self.msg, stamp, self.urdf.root_link, motion)
        self.publisher.publish(self.msg)
        self.published += 1

    def summary(self) -> dict:
        return {
            "description_topic": self.description_topic,
            "links": len(self.urdf.links),
            "topic": self.topic,
            "rate": self.rate,
            "published": self.published,
        }
