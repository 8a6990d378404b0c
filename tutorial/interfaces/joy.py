"""``/joy`` (``sensor_msgs/Joy``): the operator's sticks and buttons.

Topic :data:`TOPIC`; QoS :func:`joy_publisher_qos` for a publisher
(``rtt-joy``, the notebooks' teleop panel) and :func:`joy_subscriber_qos`
for the tank controller; the axis layout and the checks on a received Joy
(:func:`axis`, :func:`is_well_formed`).

We follow ROS 2's joy nodes, so a stock ``joy_node`` (or any other Joy
publisher) drives the tank: stick *up* and stick *left* read +1.0, and the
standard pad layout is

=====  =========================  =======  ==========
axis   meaning                    button   meaning
=====  =========================  =======  ==========
0      left stick, horizontal     0        A
1      left stick, vertical       1        B
2      right stick, horizontal    2        X
3      right stick, vertical      3        Y
4      D-pad, horizontal          4        L
5      D-pad, vertical            5        R
6      left trigger               6        SELECT
7      right trigger              7        START
=====  =========================  =======  ==========

Choreonoid's joystick reports up and left as *negative*; the original
controller's formulas are written for that, so :mod:`tutorial.controllers.tank_controller`
flips the sign once, where it reads the sticks.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

TOPIC = "/joy"
AUTOREPEAT = 20.0  # Hz: an unchanged state is published again this often (rtt-joy and ROS 2's joy_node)

LEFT_STICK_H, LEFT_STICK_V, RIGHT_STICK_H, RIGHT_STICK_V = 0, 1, 2, 3
DPAD_H, DPAD_V, LEFT_TRIGGER, RIGHT_TRIGGER = 4, 5, 6, 7
NUM_AXES = 8
BUTTON_A, BUTTON_B, BUTTON_X, BUTTON_Y, BUTTON_L, BUTTON_R, BUTTON_SELECT, BUTTON_START = range(8)
NUM_BUTTONS = 8


def axis(axes: Sequence[float], index: int) -> float:
    """One axis of a Joy message, made safe to use.

    Args:
        axes: ``Joy.axes`` as received (any length, any values).
        index: which axis.

    Returns:
        The value clamped to [-1, 1]; 0.0 when the message has no such axis
        or the value is NaN or infinite (a broken publisher must not move the robot).

    Any thread may call it.
    """
    if index >= len(axes):
        return 0.0
    v = float(axes[index])
    if not math.isfinite(v):
        return 0.0
    return max(-1.0, min(1.0, v))


def dead_zone(value: float, threshold: float) -> float:
    """0.0 when ``|value| < threshold`` (stick noise around the centre), else ``value``."""
    return 0.0 if abs(value) < threshold else value


def is_well_formed(axes: Sequence[float], buttons: Sequence[int]) -> bool:
    """True when a Joy message has the full standard layout and only finite axis values."""
    return len(axes) >= NUM_AXES and len(buttons) >= NUM_BUTTONS and all(math.isfinite(a) for a in axes)


def joy_publisher_qos():
    """A Joy publisher's QoS: reliable, keep last 10 (ROS 2's default, and ``joy_node``'s).

    * reliable: a stick released to zero must arrive, or the robot keeps
      the last command until the safe stop;
    * keep last 10: a Joy is a few dozen bytes, and a subscriber that keeps
      only the newest (:func:`joy_subscriber_qos`) drops what it does not need.
    """
    from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy

    return QoSProfile(depth=10, history=HistoryPolicy.KEEP_LAST, reliability=ReliabilityPolicy.RELIABLE)


def joy_subscriber_qos():
    """What a controller asks of ``/joy``: reliable, keep last 1, volatile.

    * keep last 1: a controller acts on the newest stick state only; an
      older one is already out of date;
    * reliable: matches every Joy publisher (a best-effort subscriber would
      too, but then a lost "sticks released" waits for the next repeat);
    * volatile: a stick state from before the controller started is stale.
    """
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

    return QoSProfile(
        depth=1,
        history=HistoryPolicy.KEEP_LAST,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.VOLATILE,
    )
