"""``/<body>/imu`` (``sensor_msgs/Imu``): the body's accelerometer and rate gyro.

* ``linear_acceleration``, m/s^2: what an accelerometer measures, gravity's
  reaction included, so a body at rest reads about +9.81 on z;
* ``angular_velocity``, rad/s;
* ``orientation`` unknown (no sensor measures it): ``orientation_covariance[0] = -1``
  says so (ROS's convention);
* ``header.frame_id``: the frame both vectors are in (:func:`imu_frame_id`).

Topic :func:`imu_topic`, QoS :func:`imu_qos`.  Which sensors make a body's
IMU, and in which frame, is read from the model by :func:`find_imu`, by
sensor type, as Choreonoid finds a body's devices.  A received Imu is
checked by :func:`check_imu` before anything is drawn.
"""

from __future__ import annotations

import mujoco
import numpy as np

# Beyond these a reading is absurd, not a collision: a mean of 1000 m/s^2 over
# 50 ms is a change of speed of 50 m/s; 100 rad/s is 16 turns a second, three
# times what common MEMS gyros measure.  They also catch a wrong unit: a tank
# at rest in mm/s^2 reads 9807, a turn of 2 rad/s in deg/s reads 115.
ACCEL_LIMIT = 1000.0  # m/s^2, norm
GYRO_LIMIT = 100.0  # rad/s, norm


def imu_topic(body_name: str) -> str:
    """``/<body name>/imu``, e.g. ``/Tank/imu``."""
    return f"/{body_name}/imu"


def imu_qos():
    """The IMU's QoS: reliable, keep last 1, volatile.

    * keep last 1: a display needs only the newest reading; no queue builds
      up behind a slow subscriber;
    * reliable: a collision shows in only one or two messages, and a viewer
      that lost them would miss it.  A reliable publisher also serves
      subscribers that ask for best effort (ROS's "sensor data" profile),
      while a best-effort publisher would not serve reliable ones (what a
      subscription created with a plain queue depth asks for);
    * volatile: an old reading is no use to a subscriber that joins later.
    """
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

    return QoSProfile(
        depth=1,
        history=HistoryPolicy.KEEP_LAST,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.VOLATILE,
    )


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

    Any thread may call it: it only reads the model.
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
        if (
            model.sensor_type[s] == kind
            and model.sensor_objtype[s] == mujoco.mjtObj.mjOBJ_SITE
            and int(model.site_bodyid[site]) in body_ids
        ):
            adr = int(model.sensor_adr[s])
            return slice(adr, adr + 3), site
    kind_name = kind.name.removeprefix("mjSENS_").lower()  # "accelerometer", "gyro"
    raise LookupError(f"the body has no {kind_name} on a site")


def imu_frame_id(model: mujoco.MjModel, site: int) -> str:
    """The frame the IMU measures in, as a message's ``header.frame_id``.

    The link's name (``CHASSIS``) when the site has the link's origin and
    axes (it has, in the tank), else the site's own name.  Named as in the
    model, without the world's ``Tank/`` prefix: the topic ``/Tank/imu``
    already says whose it is.
    """
    on_link_frame = np.allclose(model.site_pos[site], 0) and np.allclose(model.site_quat[site], [1, 0, 0, 0])
    if on_link_frame:
        link = int(model.site_bodyid[site])
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, link)
    else:
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_SITE, site)
    return name.split("/", 1)[-1]  # the world's name is "Tank/CHASSIS"


def check_imu(msg, frame_id: str):
    """Decide whether a received ``sensor_msgs/Imu`` may be shown (any thread).

    Args:
        msg: the message.
        frame_id: the frame the viewer draws in; an empty ``frame_id`` is
            taken to mean it too (the original tutorial left it empty).

    Returns:
        ``(acceleration (3,) m/s^2, angular_velocity (3,) rad/s, None)``, or
        ``(None, None, reason)`` with reason ``not_finite``, ``absurd`` or
        ``wrong_frame`` (vectors in another frame would be drawn wrongly).
    """
    a = msg.linear_acceleration
    w = msg.angular_velocity
    accel = np.array([a.x, a.y, a.z], dtype=float)
    gyro = np.array([w.x, w.y, w.z], dtype=float)
    if not (np.isfinite(accel).all() and np.isfinite(gyro).all()):
        return None, None, "not_finite"
    # A norm past 1.8e308 overflows to inf, which is absurd: no numpy warning for it.
    with np.errstate(over="ignore"):
        absurd = np.linalg.norm(accel) > ACCEL_LIMIT or np.linalg.norm(gyro) > GYRO_LIMIT
    if absurd:
        return None, None, "absurd"
    if msg.header.frame_id not in ("", frame_id):
        return None, None, "wrong_frame"
    return accel, gyro, None
