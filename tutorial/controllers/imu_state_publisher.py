"""Step 4: publish the body's IMU, averaged over each period, from the simulation.

The tank carries an accelerometer and a rate gyro (``model/tank.xml``: the
sensors ``ACCEL`` and ``GYRO`` on the site ``IMU`` at the CHASSIS origin, in
CHASSIS's axes).  MuJoCo computes every sensor in every step, into
``MjData.sensordata``.  A message every 1 ms step would be far too many, and
one step's reading alone would be a poor sample: a bump lasts a few steps,
so a reading picked every 50 ms could miss it.  So ``control()`` adds every
step's reading to a sum and counts the steps, and each time a period has
passed it publishes the mean and starts over.  When a period is due comes
from Step 2's exact :class:`PeriodAccumulator`, whose first step is due at
once: the first message, at t = 0, is that step's reading alone.  The tank
starts 1 mm above the floor, falling, and an accelerometer in free fall
reads 0: the first message says so.

Topic ``/<body name>/imu`` (``/Tank/imu``), type ``sensor_msgs/Imu``:

* ``linear_acceleration``, m/s^2: what an accelerometer measures, gravity's
  reaction included, so a tank at rest reads about +9.80665 on z.
* ``angular_velocity``, rad/s.
* ``orientation`` is unknown (no sensor measures it): all zeros, and
  ``orientation_covariance[0] = -1`` says so (ROS's convention).  Zeros
  cannot be mistaken for a real orientation, as the identity could.
  The other covariances are all 0: "unknown".
* ``header.stamp``: the *simulation* time of the step that publishes, the
  end of the period averaged.  ``header.frame_id``: the link the IMU sits on,
  ``CHASSIS``, when the sensors' site has that link's origin and axes (it
  has, in the tank), else the site's own name.  The frame is named as in
  the model, like Step 6's camera frame ``Kinect``; the topic's ``/Tank/``
  already says whose it is.

QoS: reliable, keep last 1, volatile.  Only the newest reading matters to a
display, but a collision shows in only one or two messages, and a viewer
that lost them would miss it.  A reliable publisher also serves subscribers
that ask for best effort (ROS's "sensor data" profile), while a best-effort
publisher would not serve reliable ones (what a subscription created with
a plain queue depth asks for).
"""

from __future__ import annotations

import mujoco
import numpy as np

from tutorial.controller import ControllerConfig, ControllerIO, SimpleController
from tutorial.controllers.joint_state_publisher import PeriodAccumulator

DEFAULT_RATE = 20.0  # Hz


def imu_topic(body_name: str) -> str:
    """``/<body name>/imu``, e.g. ``/Tank/imu``."""
    return f"/{body_name}/imu"


def imu_qos():
    """Reliable, keep last 1, volatile (see the module text for why)."""
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

    return QoSProfile(depth=1, history=HistoryPolicy.KEEP_LAST,
                      reliability=ReliabilityPolicy.RELIABLE,
                      durability=DurabilityPolicy.VOLATILE)


def find_imu(model: mujoco.MjModel, body_ids) -> tuple[slice, slice, int, str]:
    """The body's accelerometer and gyro, found by type, as Choreonoid does.

    Args:
        model: the world's model.
        body_ids: ids of the body's links (``Body.body_ids``).

    Returns:
        ``(accel, gyro, site, frame_id)``: the slices of ``sensordata``
        holding the accelerometer (m/s^2) and the gyro (rad/s), 3 numbers
        each; the id of the site they sit on; the frame they measure in.

    Raises:
        LookupError: the body has no accelerometer or no gyro on a site, or
            the two sit on different sites (then they measure in different
            frames, and one message cannot carry both).
    """
    kinds = mujoco.mjtSensor
    accel, site = _sensor_on_site(model, body_ids, kinds.mjSENS_ACCELEROMETER)
    gyro, gyro_site = _sensor_on_site(model, body_ids, kinds.mjSENS_GYRO)
    if site != gyro_site:
        raise LookupError("the accelerometer and the gyro sit on different sites")
    return accel, gyro, site, imu_frame_id(model, site)


def _sensor_on_site(model, body_ids, kind) -> tuple[slice, int]:
    """The first sensor of type ``kind`` on a site of the body: its slice, its site."""
    for s in range(model.nsensor):
        site = int(model.sensor_objid[s])
        if (model.sensor_type[s] == kind
                and model.sensor_objtype[s] == mujoco.mjtObj.mjOBJ_SITE
                and int(model.site_bodyid[site]) in body_ids):
            adr = int(model.sensor_adr[s])
            return slice(adr, adr + 3), site
    kind_name = kind.name.removeprefix("mjSENS_").lower()  # "accelerometer", "gyro"
    raise LookupError(f"the body has no {kind_name} on a site")


def imu_frame_id(model: mujoco.MjModel, site: int) -> str:
    """The link's name (``CHASSIS``) if the site has the link's origin and axes,
    else the site's own name."""
    on_link_frame = (np.allclose(model.site_pos[site], 0)
                     and np.allclose(model.site_quat[site], [1, 0, 0, 0]))
    if on_link_frame:
        link = int(model.site_bodyid[site])
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, link)
    else:
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_SITE, site)
    return name.split("/", 1)[-1]  # the world's name is "Tank/CHASSIS"


def ros_time(t: float):
    """A ``builtin_interfaces/Time`` for ``t`` s (rclpy splits it into sec, nanosec)."""
    from rclpy.time import Time

    return Time(nanoseconds=round(t * 1e9)).to_msg()


class RttImuStatePublisher(SimpleController):
    """Step 4 controller: publishes ``/<body>/imu``, the mean of each ``1/rate`` s."""

    PARAMETERS = {"rate": (float, DEFAULT_RATE,
                           "Imu publish rate, Hz of simulated time (0: every step)")}

    def configure(self, config: ControllerConfig) -> bool:
        from sensor_msgs.msg import Imu

        self.node = config.node
        self.rate = config.parameters["rate"]
        if self.rate < 0:
            config.log.error("rate must be >= 0, got %s", self.rate)
            return False
        try:
            body = config.body
            _, _, _, self.frame_id = find_imu(body.model, body.body_ids)
        except LookupError as exc:
            config.log.error("body %s: %s", config.body_name, exc)
            return False
        self.topic = imu_topic(config.body_name)
        self.msg_type = Imu
        self.publisher = config.node.create_publisher(Imu, self.topic, imu_qos())
        self.published = 0
        return True

    def initialize(self, io: ControllerIO) -> bool:
        self.data = io.data
        self.accel, self.gyro, _, _ = find_imu(io.body.model, io.body.body_ids)
        self.accumulator = PeriodAccumulator(io.time_step, self.rate)
        self.accel_sum = np.zeros(3)  # m/s^2, summed over the steps of this period
        self.gyro_sum = np.zeros(3)  # rad/s
        self.count = 0  # steps summed
        # One message, reused: rclpy copies it inside publish().
        self.msg = self.msg_type()
        self.msg.header.frame_id = self.frame_id
        q = self.msg.orientation
        q.x = q.y = q.z = q.w = 0.0  # unknown, see orientation_covariance
        self.msg.orientation_covariance[0] = -1.0
        return True

    def control(self) -> bool:
        # The readings of the step just taken (mj_step computes the sensors,
        # then advances time): add every one of them.
        self.accel_sum += self.data.sensordata[self.accel]
        self.gyro_sum += self.data.sensordata[self.gyro]
        self.count += 1
        if self.accumulator.tick():
            self.publish()
        return True

    def publish(self) -> None:
        """Publish the mean of the steps summed, and start over (simulation thread)."""
        a = self.accel_sum / self.count
        w = self.gyro_sum / self.count
        msg = self.msg
        msg.header.stamp = ros_time(self.data.time)
        acc, vel = msg.linear_acceleration, msg.angular_velocity
        acc.x, acc.y, acc.z = float(a[0]), float(a[1]), float(a[2])  # m/s^2
        vel.x, vel.y, vel.z = float(w[0]), float(w[1]), float(w[2])  # rad/s
        self.publisher.publish(msg)
        self.published += 1
        self.last = (a, w)
        self.accel_sum[:] = 0.0
        self.gyro_sum[:] = 0.0
        self.count = 0

    def unconfigure(self) -> None:
        self.node.destroy_publisher(self.publisher)

    def summary(self) -> dict:
        record = {"topic": self.topic, "rate": self.rate, "frame_id": self.frame_id,
                  "published": self.published}
        if self.published:
            a, w = self.last
            record["last_linear_acceleration"] = [round(float(v), 6) for v in a]
            record["last_angular_velocity"] = [round(float(v), 6) for v in w]
        return record
