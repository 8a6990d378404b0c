"""Step 5: show the body's IMU in the viewer: two arrows and a collision shake.

The viewer of Step 3 gets a second controller on the same body.  It
subscribes ``/<body>/imu`` (Step 4) and, like the joint-state subscriber,
its callback only counts the message and hands it to the main thread with
``call_later``: the model and the view belong to the main thread.  As in
Step 3, the newest message wins: one replaced before the main thread got to
it is counted as ``superseded``.  (A hit in such a message would be missed;
a real collision shows in a few messages in a row, each one a new hit.)

On the main thread, each message is checked first (NaN, infinite and
absurd values are rejected and counted), then drawn as two arrows from the
IMU's origin (the CHASSIS origin):

* acceleration, red, 0.1 m per m/s^2, with gravity's 9.8 m/s^2 taken off
  z, so a tank at rest shows no arrow;
* angular velocity, blue, 0.4 m per rad/s.

The readings are in the IMU's frame (CHASSIS's axes), so the arrows are
turned by the CHASSIS's orientation in the world: they turn with the body.
An arrow shorter than its threshold is hidden (noise, not news).

A horizontal acceleration above 20 m/s^2 is a collision: the viewer's tank
shakes for 0.5 s, its root moved by a random offset of up to 0.02 m on each
axis every 20 ms around the position it had when the shake began; a new hit
restarts the 0.5 s.  The shake runs on the main loop's timer, never in the
callback, and the last tick puts the saved position back exactly.
"""

from __future__ import annotations

import math
import threading
import time
from collections import Counter

import mujoco
import numpy as np

from tutorial.controller import ControllerConfig, SimpleController
from tutorial.controllers.imu_state_publisher import find_imu, imu_qos, imu_topic

GRAVITY_OFFSET = np.array([0.0, 0.0, -9.8])  # m/s^2, added to the acceleration shown
ACCEL_SCALE = 0.1  # m of arrow per m/s^2
GYRO_SCALE = 0.4  # m of arrow per rad/s
ACCEL_MIN_LENGTH = 0.05  # m: shorter acceleration arrows are hidden
GYRO_MIN_LENGTH = 0.01  # m: shorter angular-velocity arrows are hidden
ACCEL_COLOR = (1.0, 0.2, 0.2)  # red
GYRO_COLOR = (0.2, 0.2, 1.0)  # blue
# Beyond these a reading is absurd, not a collision: a mean of 1000 m/s^2 over
# 50 ms is a change of speed of 50 m/s; 100 rad/s is 16 turns a second, three
# times what common MEMS gyros measure.  They also catch a wrong unit: a tank
# at rest in mm/s^2 reads 9807, a turn of 2 rad/s in deg/s reads 115.
ACCEL_LIMIT = 1000.0  # m/s^2, norm
GYRO_LIMIT = 100.0  # rad/s, norm
HIT_ACCELERATION = 20.0  # m/s^2, horizontal (x, y) norm that counts as a collision
SHAKE_AMPLITUDE = 0.02  # m, on each axis
SHAKE_PERIOD = 0.02  # s between two shake ticks
SHAKE_DURATION = 0.5  # s from the newest hit
SHAKE_SEED = 5  # a seeded generator: the same shake every run
STATUS_PERIOD = 1.0  # s


def check_imu(msg, frame_id: str):
    """Decide whether a received ``sensor_msgs/Imu`` may be shown.

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
    if np.linalg.norm(accel) > ACCEL_LIMIT or np.linalg.norm(gyro) > GYRO_LIMIT:
        return None, None, "absurd"
    if msg.header.frame_id not in ("", frame_id):
        return None, None, "wrong_frame"
    return accel, gyro, None


def is_hit(accel) -> bool:
    """A collision: the horizontal (x, y) acceleration is above 20 m/s^2."""
    return math.hypot(accel[0], accel[1]) > HIT_ACCELERATION


class CollisionShake:
    """When and where to shake one root position (main thread).

    Args:
        rng: a ``numpy.random.Generator`` for the offsets.

    :meth:`hit` starts or prolongs a shake; :meth:`tick`, every 20 ms, says
    where to put the root.  Times are in s on any monotonic clock.
    """

    def __init__(self, rng: np.random.Generator):
        self.rng = rng
        self.home: np.ndarray | None = None  # m, shaken around; None: not shaking
        self.until = 0.0
        self.hits = 0
        self.episodes = 0
        self.max_offset = 0.0  # m, the largest offset on any axis so far

    @property
    def shaking(self) -> bool:
        return self.home is not None

    def hit(self, now: float, position) -> None:
        """A collision at ``now``; ``position`` (3,) is the root's now, m.

        A hit during a shake restarts its 0.5 s but keeps the position
        saved at its start: ``position`` is a shaken one then.
        """
        self.hits += 1
        if self.home is None:
            self.home = np.array(position, dtype=float)
            self.episodes += 1
        self.until = now + SHAKE_DURATION

    def tick(self, now: float) -> np.ndarray | None:
        """Where to put the root now: (3,) m, or None when not shaking.

        The tick at the end returns the saved position itself, so the root
        goes back exactly.
        """
        if self.home is None:
            return None
        if now >= self.until:
            home, self.home = self.home, None
            return home
        offset = self.rng.uniform(-SHAKE_AMPLITUDE, SHAKE_AMPLITUDE, 3)
        self.max_offset = max(self.max_offset, float(np.abs(offset).max()))
        return self.home + offset


def root_position_address(model: mujoco.MjModel, body_id: int) -> int | None:
    """Where a link's position (3,) starts in ``qpos``; None without a free joint."""
    joint = model.body_jntadr[body_id]
    if joint < 0 or model.jnt_type[joint] != mujoco.mjtJoint.mjJNT_FREE:
        return None
    return int(model.jnt_qposadr[joint])


class RttImuStateSubscriber(SimpleController):
    """Step 5 controller: shows ``/<body>/imu`` as arrows, shakes on collisions."""

    def configure(self, config: ControllerConfig) -> bool:
        from rclpy.event_handler import SubscriptionEventCallbacks
        from sensor_msgs.msg import Imu

        self.config = config
        self.body = config.body
        self.model, self.data = config.body.model, config.body.data
        try:
            _, _, self.site, self.frame_id = find_imu(self.model, self.body.body_ids)
        except LookupError as exc:
            config.log.error("body %s: %s", config.body_name, exc)
            return False
        self.root = root_position_address(self.model, self.body.root_id)
        self.node = config.node
        self.node_name = config.node.get_fully_qualified_name()
        self.topic = imu_topic(config.body_name)
        overlays, name = config.overlays, config.body_name
        self.accel_arrow = overlays.arrow(f"{name}/acceleration", ACCEL_COLOR)
        self.gyro_arrow = overlays.arrow(f"{name}/angular_velocity", GYRO_COLOR)
        self.accel = self.gyro = None  # the newest accepted reading, IMU axes
        self.arrival = None  # monotonic time, s, it arrived
        self.shake = CollisionShake(np.random.default_rng(SHAKE_SEED))
        self.lock = threading.Lock()  # guards `received`: the spin thread writes it
        self.received = 0
        self.accepted = 0  # main thread only, as are the rest
        self.rejected: Counter = Counter()
        self.last_report = (time.monotonic(), 0)
        self.subscription = config.node.create_subscription(
            Imu, self.topic, self.on_imu, imu_qos(),
            event_callbacks=SubscriptionEventCallbacks(matched=self.on_matched))
        config.call_every(SHAKE_PERIOD, self.shake_tick)
        config.call_every(STATUS_PERIOD, self.report_status)
        return True

    # ---- spin thread --------------------------------------------------------
    def on_imu(self, msg) -> None:
        """Subscription callback (spin thread): count it, hand it to the main thread."""
        with self.lock:
            self.received += 1
        self.config.call_later(self.update_imu, msg, time.monotonic())

    def on_matched(self, status) -> None:
        """A publisher of the topic appeared or went (spin thread)."""
        self.config.call_later(self.report_publishers, status.current_count)

    # ---- main thread --------------------------------------------------------
    def report_publishers(self, count: int) -> None:
        self.config.output({"event": "publishers", "node": self.node_name,
                            "topic": self.topic, "count": count})

    def update_imu(self, msg, arrival: float) -> str | None:
        """Check one message and show it (main thread, via ``call_later``).

        Returns:
            None when shown, else the reason it was rejected.
        """
        accel, gyro, reason = check_imu(msg, self.frame_id)
        if reason is not None:
            self.rejected[reason] += 1
            return reason
        self.accepted += 1
        self.accel, self.gyro, self.arrival = accel, gyro, arrival
        self.draw_arrows()
        if is_hit(accel) and self.root is not None:
            self.start_shake(accel)
        return None

    def draw_arrows(self) -> None:
        """Place both arrows at the IMU, turned with the body (main thread)."""
        if self.accel is None:
            return
        origin = self.data.site_xpos[self.site]  # m, world frame
        to_world = self.data.site_xmat[self.site].reshape(3, 3)  # IMU axes -> world
        accel = ACCEL_SCALE * (self.accel + GRAVITY_OFFSET)  # m, IMU axes
        gyro = GYRO_SCALE * self.gyro
        self.accel_arrow.set(origin, to_world @ accel,
                             visible=np.linalg.norm(accel) >= ACCEL_MIN_LENGTH)
        self.gyro_arrow.set(origin, to_world @ gyro,
                            visible=np.linalg.norm(gyro) >= GYRO_MIN_LENGTH)

    def start_shake(self, accel) -> None:
        """A collision: start a shake, or restart its 0.5 s (main thread)."""
        if not self.shake.shaking:
            self.config.output({
                "event": "shake", "node": self.node_name, "body": self.body.name,
                "horizontal_acceleration": round(math.hypot(accel[0], accel[1]), 3)})
        position = self.data.qpos[self.root:self.root + 3]  # m, the root link's
        self.shake.hit(time.monotonic(), position)

    def shake_tick(self) -> None:
        """Every 20 ms (main loop timer): move the root while a shake is on."""
        position = self.shake.tick(time.monotonic())
        if position is None:
            return
        self.data.qpos[self.root:self.root + 3] = position
        self.body.notify_kinematic_state_change()
        self.draw_arrows()  # they start at the IMU, which moved
        if not self.shake.shaking:
            self.config.output({"event": "shake_end", "node": self.node_name,
                                "body": self.body.name, "position": position.tolist()})

    def report_status(self) -> None:
        """Once a second: an ``imu_status`` record (main thread)."""
        now = time.monotonic()
        with self.lock:
            received = self.received
        then, received_then = self.last_report
        self.last_report = (now, received)
        age = None if self.arrival is None else round((now - self.arrival) * 1e3, 1)
        self.config.output({
            "event": "imu_status", "node": self.node_name,
            "rate_hz": round((received - received_then) / max(now - then, 1e-9), 1),
            "age_ms": age, **self.summary()})

    def unconfigure(self) -> None:
        if self.shake.shaking:  # leave the model where it was, not mid-shake
            self.data.qpos[self.root:self.root + 3] = self.shake.home
            self.body.notify_kinematic_state_change()
        self.node.destroy_subscription(self.subscription)

    def summary(self) -> dict:
        with self.lock:
            received = self.received
        handled = self.accepted + sum(self.rejected.values())
        return {
            "topic": self.topic, "received": received, "accepted": self.accepted,
            # replaced by a newer message before the main thread got to them
            # (call_later coalesces); in a status line, one may still be pending
            "superseded": received - handled,
            "rejected": dict(sorted(self.rejected.items())),
            "arrows": {"acceleration": self.accel_arrow.record(),
                       "angular_velocity": self.gyro_arrow.record()},
            "shakes": self.shake.episodes, "hits": self.shake.hits,
            "shaking": self.shake.shaking,
            "max_shake_offset": round(self.shake.max_offset, 6),
        }
