# Frozen from notebooks/01_step1_tank_controller.ipynb by scripts/freeze_reference.py: the later steps
# stand on this copy, so editing that notebook changes its own step only.

"""Step 1: drive the tank's tracks and turret from ``sensor_msgs/Joy``.

Built in ``notebooks/01_step1_tank_controller.ipynb``: edit it there, then
run ``make export``.  The ``/joy`` callback runs on the ROS spin thread and
``control()`` on the simulation thread; they share the newest stick state
under one lock, held for a few assignments only.
"""

from __future__ import annotations

import threading

from ...core.controller import ControllerConfig, ControllerIO, SimpleController
from ...interfaces import joy

TRACK_DEAD_ZONE = 0.2  # stick units
TURRET_DEAD_ZONE = 0.15  # stick units
TRACK_SPEED_GAIN = 2.0  # m/s of track surface per unit of forward stick
TURN_SPEED_GAIN = 1.0  # m/s of track difference per unit of turning stick
TURRET_P_GAIN = 200.0  # N*m/rad
TURRET_D_GAIN = 50.0  # N*m*s/rad
TURRET_RATE = 2.0  # rad/s at full stick (0.002 rad per 1 ms step)
TURRET_JOINTS = ("TURRET_Y", "TURRET_P")  # driven by the right stick's H and V
TRACKS = ("TRACK_L", "TRACK_R")
DEFAULT_JOY_TIMEOUT = 0.5  # s


def _choreonoid_sign(value: float) -> float:
    """A stick value in Choreonoid's convention (up, left negative); 0 stays +0.0."""
    return -value if value else 0.0


def track_velocities(axes) -> tuple[float, float]:
    """Track surface velocities ``(left, right)`` in m/s from a Joy's axes.

    Left stick: up drives forward, left turns left (ROS 2's joy convention).
    The original formulas are written in Choreonoid's convention (up and
    left negative), so the stick values are negated first.

    Args:
        axes: ``Joy.axes`` (any length; missing or non-finite axes count as 0).

    Any thread may call it.
    """
    v = joy.dead_zone(joy.axis(axes, joy.LEFT_STICK_V), TRACK_DEAD_ZONE)
    h = joy.dead_zone(joy.axis(axes, joy.LEFT_STICK_H), TRACK_DEAD_ZONE)
    v, h = _choreonoid_sign(v), _choreonoid_sign(h)
    left = -TRACK_SPEED_GAIN * v + TURN_SPEED_GAIN * h
    right = -TRACK_SPEED_GAIN * v - TURN_SPEED_GAIN * h
    return left + 0.0, right + 0.0  # + 0.0 turns a -0.0 into 0.0 for printing


def turret_rates(axes) -> tuple[float, float]:
    """Reference rates ``(TURRET_Y, TURRET_P)`` in rad/s from a Joy's right stick.

    In Choreonoid's convention the reference moves by ``TURRET_RATE *
    stick``: stick right turns the turret clockwise seen from above
    (TURRET_Y turns about -Z); stick pulled back raises the barrel, like a
    flight stick, as in the original.

    Args:
        axes: ``Joy.axes`` (any length; missing or non-finite axes count as 0).
    """
    yaw = joy.dead_zone(joy.axis(axes, joy.RIGHT_STICK_H), TURRET_DEAD_ZONE)
    pitch = joy.dead_zone(joy.axis(axes, joy.RIGHT_STICK_V), TURRET_DEAD_ZONE)
    return TURRET_RATE * _choreonoid_sign(yaw), TURRET_RATE * _choreonoid_sign(pitch)


def pd_torque(q_ref: float, q: float, dq_ref: float, dq: float) -> float:
    """Turret torque in N*m: ``P*(q_ref - q) + D*(dq_ref - dq)`` (rad, rad/s)."""
    return TURRET_P_GAIN * (q_ref - q) + TURRET_D_GAIN * (dq_ref - dq)


__all__ = [
    "TRACK_DEAD_ZONE",
    "TURRET_DEAD_ZONE",
    "TRACK_SPEED_GAIN",
    "TURN_SPEED_GAIN",
    "TURRET_P_GAIN",
    "TURRET_D_GAIN",
    "TURRET_RATE",
    "TURRET_JOINTS",
    "TRACKS",
    "DEFAULT_JOY_TIMEOUT",
    "track_velocities",
    "turret_rates",
    "pd_torque",
    "RttTankController",
]


class RttTankController(SimpleController):
    """Step 1 controller: tracks by the left stick, turret by the right stick.

    Topic: subscribes ``/joy`` (``sensor_msgs/Joy``), QoS
    :func:`tutorial.interfaces.joy.joy_subscriber_qos`: reliable, keep last 1,
    a controller needs only the newest stick state.

    Parameter ``joy_timeout`` (s, default 0.5, 0 disables): once no Joy has
    arrived for that long, the tracks stop and the turret holds its angle
    until the next Joy: the safe stop.  ``rtt-joy`` and ROS 2's
    ``joy_node`` repeat the sticks at 20 Hz, so a live operator never trips
    it.  It counts simulated time, the controller's own clock.
    """

    PARAMETERS = {
        "joy_timeout": (
            float,
            DEFAULT_JOY_TIMEOUT,
            "s without a Joy before the tank stops (0: never)",
        )
    }

    def __init__(self):
        self._lock = threading.Lock()
        # Written by the spin thread, read by the simulation thread: under _lock.
        self._axes: tuple = ()
        self._buttons: tuple = ()
        self._received = 0
        self._malformed = 0
        self.joy_timeout = DEFAULT_JOY_TIMEOUT
        self.config = None
        self.subscription = None

    # ---- main thread ------------------------------------------------------
    def configure(self, config: ControllerConfig) -> bool:
        from sensor_msgs.msg import Joy

        self.config = config
        self.joy_timeout = config.parameters.get("joy_timeout", DEFAULT_JOY_TIMEOUT)
        if self.joy_timeout < 0:
            config.log.error("joy_timeout must be >= 0 s, got %s", self.joy_timeout)
            return False
        self.subscription = config.node.create_subscription(Joy, joy.TOPIC, self.on_joy, joy.joy_subscriber_qos())
        return True

    def unconfigure(self) -> None:
        if self.subscription is not None:
            self.config.node.destroy_subscription(self.subscription)
            self.subscription = None

    # ---- spin thread --------------------------------------------------------
    def on_joy(self, msg) -> None:
        """Subscription callback (spin thread): store the newest stick state.

        Copies out of the message first, then swaps the copy in under the
        lock.  A malformed message (too few axes or buttons, NaN) is counted;
        what it has is still used, read safely by :func:`tutorial.interfaces.joy.axis`.
        """
        axes, buttons = tuple(msg.axes), tuple(msg.buttons)
        well_formed = joy.is_well_formed(axes, buttons)
        with self._lock:
            self._axes, self._buttons = axes, buttons
            self._received += 1
            self._malformed += not well_formed

    def take_input(self) -> tuple[int, tuple, tuple]:
        """``(count, axes, buttons)``: Joys received so far, the newest (any thread)."""
        with self._lock:
            return self._received, self._axes, self._buttons

    # ---- simulation thread ----------------------------------------------------
    def initialize(self, io: ControllerIO) -> bool:
        self.io = io
        self.dt = io.time_step
        self.turret = [io.body.joint(name) for name in TURRET_JOINTS]
        self.tracks = [io.body.track(name) for name in TRACKS]
        self.q_ref = [j.q for j in self.turret]  # turret references, rad
        self.rates = (0.0, 0.0)  # their rates, rad/s
        self.seen = 0  # how many Joys control() has acted on
        self.silent = 0.0  # s of simulated time since the last new Joy
        self.stopped = False  # the safe stop is in force
        self.timeouts = 0
        return True

    def control(self) -> bool:
        count, axes, _buttons = self.take_input()  # the lock is held in there only
        if count != self.seen:
            # A new Joy: work out the commands once, not every millisecond.
            self.seen, self.silent = count, 0.0
            self.command(*track_velocities(axes), turret_rates(axes))
            if self.stopped:
                self.stopped = False
                self.report("joy_resumed", "/joy is back: driving again")
        elif self.joy_timeout and count and not self.stopped:
            self.silent += self.dt
            if self.silent >= self.joy_timeout:
                self.stopped = True
                self.timeouts += 1
                self.command(0.0, 0.0, (0.0, 0.0))  # the turret holds its reference
                self.report(
                    "joy_timeout",
                    f"no /joy for {self.joy_timeout:.2f} s: tracks stopped, turret held",
                )
        self.control_turret()
        return True

    def command(self, left: float, right: float, rates: tuple) -> None:
        """Set the track velocities (m/s) and turret reference rates (rad/s)."""
        self.tracks[0].dq_target = left  # stays in force until changed
        self.tracks[1].dq_target = right
        self.rates = rates

    def control_turret(self) -> None:
        """Move each turret reference at its rate, and follow it by torque PD."""
        for i, joint in enumerate(self.turret):
            q_ref, dq_ref = self.q_ref[i], 0.0
            if self.rates[i]:
                # The reference stays inside the joint's range, so holding the
                # stick at a limit winds nothing up; its rate is what it really
                # moved: 0 at a limit.
                lower, upper = joint.info.lower, joint.info.upper
                q_ref = min(max(q_ref + self.rates[i] * self.dt, lower), upper)
                dq_ref = (q_ref - self.q_ref[i]) / self.dt
                self.q_ref[i] = q_ref
            joint.u = pd_torque(q_ref, joint.q, dq_ref, joint.dq)

    def report(self, event: str, text: str) -> None:
        """Post a status line to the main thread, once per event (simulation thread)."""
        if self.config is None:
            return  # not configured (a unit test): nobody to tell
        x, y, z = (round(float(v), 4) for v in self.io.body.root_pose()[0])
        node = self.config.node.get_fully_qualified_name()
        record = {
            "event": event,
            "node": node,
            "t": round(self.io.current_time, 3),
            "root_position": [x, y, z],
            "line": f"[{node}] {text}",
        }
        # A key of its own: two reports close together must not coalesce into one.
        self.config.call_later(self.config.output, record, key=object())

    def summary(self) -> dict:
        with self._lock:
            received, malformed = self._received, self._malformed
        return {
            "joy_received": received,
            "joy_malformed": malformed,
            "joy_timeouts": getattr(self, "timeouts", 0),
        }
