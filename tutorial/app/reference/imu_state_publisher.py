# Frozen from notebooks/04_step4_imu_publisher.ipynb by scripts/freeze_reference.py: the later steps
# stand on this copy, so editing that notebook changes its own step only.

"""Step 4: publish the body's IMU from the simulation, averaged over each period.

Built in ``notebooks/04_step4_imu_publisher.ipynb``: edit it there, then run
``make export``.  The tank carries an accelerometer and a rate gyro
(``model/tank.xml``: the sensors ``ACCEL`` and ``GYRO`` on the site ``IMU``
at the CHASSIS origin, in CHASSIS's axes).  MuJoCo computes every sensor in
every step, into ``MjData.sensordata``.  :class:`RttImuStatePublisher` adds
every step's reading to a sum and, each time a period has passed (Step 2's
exact :class:`PeriodAccumulator`, 20 Hz by default), publishes the mean and
starts over.  One step's reading picked every 50 ms would be a poor sample:
a bump lasts a few steps, and a sample would miss it.

Topic ``/<body name>/imu`` (``/Tank/imu``), type ``sensor_msgs/Imu``:

* ``linear_acceleration``, m/s^2: what an accelerometer measures, gravity's
  reaction included, so a tank at rest reads about +9.80665 on z;
* ``angular_velocity``, rad/s;
* ``orientation`` is unknown (no sensor measures it): all zeros, and
  ``orientation_covariance[0] = -1`` says so (ROS's convention); the other
  covariances are 0, "unknown";
* ``header.stamp``: the simulation time of the step that publishes, the end
  of the period averaged; ``header.frame_id``: see
  :func:`tutorial.interfaces.imu.imu_frame_id`.

The first message, at t = 0, is that step's reading alone.  The tank starts
1 mm above the floor, falling, and an accelerometer in free fall reads 0:
the first message says so.  QoS: :func:`tutorial.interfaces.imu.imu_qos`.
"""

from __future__ import annotations

import numpy as np

from ...core.controller import ControllerConfig, ControllerIO, SimpleController
from ...core.period import PeriodAccumulator
from ...interfaces.imu import find_imu, imu_qos, imu_topic
from ...interfaces.timing import stamp_parts

DEFAULT_RATE = 20.0  # Hz of simulated time

__all__ = ["DEFAULT_RATE", "PeriodMean", "RttImuStatePublisher"]


class PeriodMean:
    """The mean of the readings added since the last :meth:`take`.

    Args:
        size: numbers per reading (3 for a vector).

    Used by one thread only (the simulation thread, in the publisher).
    """

    def __init__(self, size: int = 3):
        self.sum = np.zeros(size)
        self.count = 0

    def add(self, reading) -> None:
        """Add one step's reading, (size,)."""
        self.sum += reading
        self.count += 1

    def take(self) -> np.ndarray:
        """The mean of the readings added, (size,), and start over.

        Raises:
            ZeroDivisionError: nothing was added since the last take.
        """
        if self.count == 0:
            raise ZeroDivisionError("PeriodMean.take: no reading was added")
        mean = self.sum / self.count
        self.sum[:] = 0.0
        self.count = 0
        return mean


class RttImuStatePublisher(SimpleController):
    """Step 4 controller: publishes ``/<body>/imu``, the mean of each ``1/rate`` s.

    QoS: :func:`tutorial.interfaces.imu.imu_qos`.  Refuses to configure on a body
    without an accelerometer and a gyro on one site
    (:func:`tutorial.interfaces.imu.find_imu`).
    """

    PARAMETERS = {
        "rate": (
            float,
            DEFAULT_RATE,
            "Imu publish rate, Hz of simulated time (0: every step)",
        )
    }

    # ---- main thread ------------------------------------------------------
    def configure(self, config: ControllerConfig) -> bool:
        from sensor_msgs.msg import Imu

        self.node = config.node
        self.rate = config.parameters["rate"]
        if self.rate < 0:
            config.log.error("rate must be >= 0 Hz, got %s", self.rate)
            return False
        body = config.body
        try:
            _, _, _, self.frame_id = find_imu(body.model, body.body_ids)
        except LookupError as exc:
            config.log.error("body %s: %s", config.body_name, exc)
            return False
        self.topic = imu_topic(config.body_name)
        self.msg_type = Imu
        self.publisher = config.node.create_publisher(Imu, self.topic, imu_qos())
        self.published = 0
        self._newest = None  # (acceleration, angular velocity) of the newest message
        return True

    def unconfigure(self) -> None:
        self.node.destroy_publisher(self.publisher)

    # ---- simulation thread --------------------------------------------------
    def initialize(self, io: ControllerIO) -> bool:
        self.data = io.data
        self.accel, self.gyro, _, _ = find_imu(io.body.model, io.body.body_ids)
        self.accumulator = PeriodAccumulator(io.time_step, self.rate)
        self.accel_mean = PeriodMean()  # m/s^2
        self.gyro_mean = PeriodMean()  # rad/s
        # One message, reused: publish() copies it.
        msg = self.msg = self.msg_type()
        msg.header.frame_id = self.frame_id
        q = msg.orientation
        q.x = q.y = q.z = q.w = 0.0  # unknown, see orientation_covariance
        msg.orientation_covariance[0] = -1.0
        return True

    def control(self) -> bool:
        # The readings the last mj_step computed: every step's counts.
        sensordata = self.data.sensordata
        self.accel_mean.add(sensordata[self.accel])
        self.gyro_mean.add(sensordata[self.gyro])
        if self.accumulator.tick():
            self.publish()
        return True

    def publish(self) -> None:
        """Publish the means of the steps added, and start over."""
        a, w = self.accel_mean.take(), self.gyro_mean.take()
        msg = self.msg
        msg.header.stamp.sec, msg.header.stamp.nanosec = stamp_parts(self.data.time)
        acc, vel = msg.linear_acceleration, msg.angular_velocity
        acc.x, acc.y, acc.z = float(a[0]), float(a[1]), float(a[2])  # m/s^2
        vel.x, vel.y, vel.z = float(w[0]), float(w[1]), float(w[2])  # rad/s
        self.publisher.publish(msg)
        self.published += 1
        self._newest = (a, w)

    # ---- main thread, after the run -----------------------------------------
    def summary(self) -> dict:
        record = {
            "topic": self.topic,
            "rate": self.rate,
            "frame_id": self.frame_id,
            "published": self.published,
        }
        if self._newest is not None:
            a, w = self._newest
            record["last_linear_acceleration"] = [round(float(v), 6) for v in a]
            record["last_angular_velocity"] = [round(float(v), 6) for v in w]
        return record
