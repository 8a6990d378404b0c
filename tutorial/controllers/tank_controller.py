"""Step 1: drive the tank's tracks and turret from ``sensor_msgs/Joy``.

The lesson of this step is the thread hand-off.  The ``/joy`` subscription
callback runs on the ROS spin thread, while ``control()`` runs on the
simulation thread every 1 ms.  They share one thing, the newest stick
state, and they share it through a lock:

* the callback copies the message's axes and buttons and stores them under
  the lock, replacing what was there (queue size 1: only the newest matters);
* ``control()`` takes the stored state out under the same lock and then works
  on its own copy, so the lock is held for a few assignments only and never
  during the control computation.

Without the lock, ``control()`` could read axes from one message and buttons
from another (in C++, even a half-copied array).  With it, each step sees
one whole message.
"""

from __future__ import annotations

import threading

from tutorial import joy
from tutorial.controller import ControllerConfig, ControllerIO, SimpleController

JOY_TOPIC = "/joy"

TRACK_DEAD_ZONE = 0.2  # stick units
TURRET_DEAD_ZONE = 0.15  # stick units
TRACK_SPEED_GAIN = 2.0  # m/s of track surface per unit of forward stick
TURN_SPEED_GAIN = 1.0  # m/s of track surface difference per unit of turning stick
TURRET_P_GAIN = 200.0  # N*m/rad
TURRET_D_GAIN = 50.0  # N*m*s/rad
TURRET_RATE = 2.0  # rad/s at full stick (0.002 rad per 1 ms step)
TURRET_JOINTS = ("TURRET_Y", "TURRET_P")  # driven by right stick H, V
TRACKS = ("TRACK_L", "TRACK_R")


def _choreonoid_sign(value: float) -> float:
    """A stick value in Choreonoid's sign convention (up and left negative); 0 stays +0.0."""
    return -value if value else 0.0


def track_velocities(axes) -> tuple[float, float]:
    """Track surface velocities (left, right) in m/s from a Joy's axes.

    Left stick: up drives forward, left turns left (ROS 2 joy convention).
    The original formulas are in Choreonoid's convention (up and left
    negative), so the stick values are negated first.

    Args:
        axes: ``Joy.axes`` (any length; missing or non-finite axes count as 0).

    Any thread may call it.
    """
    v = _choreonoid_sign(joy.dead_zone(joy.axis(axes, joy.LEFT_STICK_V), TRACK_DEAD_ZONE))
    h = _choreonoid_sign(joy.dead_zone(joy.axis(axes, joy.LEFT_STICK_H), TRACK_DEAD_ZONE))
    left = -TRACK_SPEED_GAIN * v + TURN_SPEED_GAIN * h
    right = -TRACK_SPEED_GAIN * v - TURN_SPEED_GAIN * h
    return left + 0.0, right + 0.0  # + 0.0 turns a -0.0 into 0.0 for printing


def turret_rates(axes) -> tuple[float, float]:
    """Reference rates (TURRET_Y, TURRET_P) in rad/s from a Joy's right stick.

    In Choreonoid's sign convention the reference advances by
    ``TURRET_RATE * stick``: stick right turns the turret clockwise seen from
    above (TURRET_Y turns about -Z), stick pulled back raises the barrel,
    like a flight stick, as in the original.

    Args:
        axes: ``Joy.axes`` (any length; missing or non-finite axes count as 0).
    """
    yaw = _choreonoid_sign(joy.dead_zone(joy.axis(axes, joy.RIGHT_STICK_H), TURRET_DEAD_ZONE))
    pitch = _choreonoid_sign(joy.dead_zone(joy.axis(axes, joy.RIGHT_STICK_V), TURRET_DEAD_ZONE))
    return TURRET_RATE * yaw, TURRET_RATE * pitch


def pd_torque(q_ref: float, q: float, dq_ref: float, dq: float) -> float:
    """Turret torque in N*m: ``P*(q_ref - q) + D*(dq_ref - dq)`` (rad, rad/s)."""
    return TURRET_P_GAIN * (q_ref - q) + TURRET_D_GAIN * (dq_ref - dq)


class RttTankController(SimpleController):
    """Step 1 controller: tracks by the left stick, turret by the right stick.

    Topics: subscribes ``/joy`` (``sensor_msgs/Joy``), QoS reliable, keep
    last 1: only the newest stick state is of use to a controller.
    """

    def __init__(self):
        self._lock = threading.Lock()
        # Written by the spin thread, read by the simulation thread: guarded by _lock.
        self._latest_axes: tuple = ()
        self._latest_buttons: tuple = ()
        self._received = 0
        self._malformed = 0
        self.subscription = None

    # ---- main thread --------------------------------------------------------
    def configure(self, config: ControllerConfig) -> bool:
        from rclpy.qos import QoSProfile, ReliabilityPolicy, HistoryPolicy
        from sensor_msgs.msg import Joy

        self.node = config.node
        qos = QoSProfile(depth=1, history=HistoryPolicy.KEEP_LAST, reliability=ReliabilityPolicy.RELIABLE)
        self.subscription = config.node.create_subscription(Joy, JOY_TOPIC, self.on_joy, qos)
        return True

    def unconfigure(self) -> None:
        if self.subscription is not None:
            self.node.destroy_subscription(self.subscription)
            self.subscription = None

    # ---- spin thread ----------------------------------------------------------
    def on_joy(self, msg) -> None:
        """Subscription callback (spin thread): store the newest stick state.

        Copies out of the message first, then swaps the copy in under the
        lock.  A malformed message (too few axes or buttons, NaN) is counted;
        what it has is still used, read safely by :func:`tutorial.joy.axis`.
        """
        axes = tuple(msg.axes)
        buttons = tuple(msg.buttons)
        well_formed = joy.is_well_formed(axes, buttons)
        with self._lock:
            self._latest_axes = axes
            self._latest_buttons = buttons
            self._received += 1
            if not well_formed:
                self._malformed += 1

    def take_input(self) -> tuple[tuple, tuple]:
        """The newest (axes, buttons), taken out under the lock (any thread)."""
        with self._lock:
            return self._latest_axes, self._latest_buttons

    # ---- simulation thread ----------------------------------------------------
    def initialize(self, io: ControllerIO) -> bool:
        self.io = io
        self.dt = io.time_step
        self.turret = [io.body.joint(name) for name in TURRET_JOINTS]
        self.tracks = [io.body.track(name) for name in TRACKS]
        self.q_ref = [j.q for j in self.turret]
        self.axes_in_use = None
        self.rates = (0.0, 0.0)
        return True

    def control(self) -> bool:
        axes, _buttons = self.take_input()  # lock held only inside take_input
        if axes is not self.axes_in_use:
            # A new message: work out the commands once, not every millisecond.
            self.axes_in_use = axes
            left, right = track_velocities(axes)
            self.tracks[0].dq_target = left  # stays in force until changed
            self.tracks[1].dq_target = right
            self.rates = turret_rates(axes)
        q_refs, rates, dt = self.q_ref, self.rates, self.dt
        for i, joint in enumerate(self.turret):
            q_ref, dq_ref = q_refs[i], 0.0
            if rates[i]:
                # The reference advances with the stick and stays inside the joint's
                # range, so holding the stick at a limit winds nothing up.  Its rate
                # is what it really moved: 0 at a limit.
                info = joint.info
                q_ref = min(max(q_ref + rates[i] * dt, info.lower), info.upper)
                dq_ref = (q_ref - q_refs[i]) / dt
                q_refs[i] = q_ref
            joint.u = pd_torque(q_ref, joint.q, dq_ref, joint.dq)
        return True

    def summary(self) -> dict:
        with self._lock:
            return {"joy_received": self._received, "joy_malformed": self._malformed}
