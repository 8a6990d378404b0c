"""Checks for the exercises of notebook 07 (record and replay).

Exercise 7.1, when did the operator let go: ``release_times(path) -> list[float]``,
the seconds (since the bag's first ``/joy``) at which every stick came back to the centre.
Exercise 7.2, the turret's top speed: ``peak_speed(series, joint) -> (rad/s, s)`` from a
:class:`tutorial.bag.reader.JointSeries`.

The checks write small bags of their own with the library's
:class:`tutorial.bag.writer.BagWriter` (messages with known values at known
times), so every case is exact, and read nothing from the network.
"""

from __future__ import annotations

import math
import tempfile
from pathlib import Path

import numpy as np

from tutorial.exercises.grader import Case, CaseFailed, Result, grade, show

T0 = 1_700_000_000_000_000_000  # ns: the bags' first log time (any epoch time will do)


def write_bag(path: Path, messages: list[tuple[str, float, object]]) -> Path:
    """Write ``(topic, seconds after T0, message)`` into an MCAP bag at ``path``; the path."""
    from rclpy.qos import QoSProfile
    from rclpy.serialization import serialize_message

    from tutorial.bag.qos import profile_dict, serialize_profiles
    from tutorial.bag.writer import BagWriter
    from tutorial.interfaces.definitions import full_text

    writer = BagWriter(path, overwrite=True)
    try:
        for topic, seconds, msg in messages:
            type_name = type(msg).__module__.split(".")[0] + "/msg/" + type(msg).__name__
            qos = serialize_profiles([profile_dict(QoSProfile(depth=10))])
            writer.add_topic(topic, type_name, full_text(type_name), qos)
            t = T0 + round(seconds * 1e9)
            writer.write(topic, t, t, serialize_message(msg))
    finally:
        writer.close()
    return path


def _joy(lv: float = 0.0, rh: float = 0.0, axes=None):
    from sensor_msgs.msg import Joy

    return Joy(axes=list(axes) if axes is not None else [0.0, lv, rh, 0.0, 0.0, 0.0, 0.0, 0.0], buttons=[0] * 8)


def _state(t: float, turret_y: float):
    from sensor_msgs.msg import JointState

    msg = JointState(name=["TURRET_Y", "TURRET_P"], position=[turret_y, 0.1])
    msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(round(t * 1e9), 1_000_000_000)
    return msg


def check_release_times(func) -> Result:
    """Check ``func(path) -> list[float]``: when every axis of ``/joy`` came back to 0, s after the first Joy.

    A Joy is *released* when every axis is 0 (a Joy with no axes too); a
    release is a released Joy right after one that was not.  Times are log
    times (when the recorder received the message), in seconds since the
    bag's first ``/joy`` message.  Other topics are ignored.
    """

    def bag(label, messages, expected, hint):
        call = f"release_times(a bag: {label})"

        def run():
            with tempfile.TemporaryDirectory() as d:
                path = write_bag(Path(d) / "check.mcap", messages)
                got = func(path)
            try:
                got_list = [float(t) for t in got]
            except (TypeError, ValueError):
                raise CaseFailed(f"{call} returned {got!r}, expected a list of seconds {show(expected)}.") from None
            if len(got_list) != len(expected) or any(abs(a - b) > 1e-6 for a, b in zip(got_list, expected)):
                raise CaseFailed(
                    f"{call} returned {show([round(t, 4) for t in got_list])}, expected {show(expected)}.", hint
                )

        return Case(call, run, hint)

    repeat = [0.05 * k for k in range(20)]  # a joy node repeating its state at 20 Hz for 1 s
    return grade(
        "Exercise 7.1, when did the operator let go",
        [
            bag(
                "forward for 1 s, then let go",
                [("/joy", t, _joy(lv=0.5)) for t in repeat] + [("/joy", 1.0, _joy())],
                [1.0],
                "a release is a Joy with every axis 0, right after one that was not.",
            ),
            bag(
                "let go, then repeated at 20 Hz",
                [
                    ("/joy", 0.0, _joy(lv=0.5)),
                    ("/joy", 0.4, _joy()),
                    *[("/joy", 0.4 + 0.05 * k, _joy()) for k in range(1, 10)],
                ],
                [0.4],
                "a joy node repeats a released state: only the first released Joy after a push counts.",
            ),
            bag(
                "two pushes",
                [
                    ("/joy", 0.0, _joy(lv=1.0)),
                    ("/joy", 0.5, _joy()),
                    ("/joy", 1.0, _joy(rh=-0.6)),
                    ("/joy", 2.25, _joy()),
                ],
                [0.5, 2.25],
                "every push that ends is one release.",
            ),
            bag(
                "still pushed at the end",
                [("/joy", 0.0, _joy()), ("/joy", 0.3, _joy(lv=0.8))],
                [],
                "a bag that starts released and ends pushed holds no release.",
            ),
            bag(
                "joint states around the Joys",
                [
                    ("/Tank/joint_state", 0.0, _state(0.0, 0.0)),
                    ("/joy", 0.5, _joy(lv=0.5)),
                    ("/Tank/joint_state", 0.6, _state(0.1, 0.2)),
                    ("/joy", 1.5, _joy()),
                ],
                [1.0],
                "read only /joy (read_messages(path, topics=['/joy'])), and count from the first Joy.",
            ),
            bag(
                "a Joy with no axes",
                [("/joy", 0.0, _joy(rh=0.7)), ("/joy", 0.2, _joy(axes=[]))],
                [0.2],
                "a Joy with no axes has no stick pushed: it is released.",
            ),
        ],
    )


def check_peak_speed(func) -> Result:
    """Check ``func(series, joint) -> (speed, time)``: a joint's largest |dq/dt| between consecutive states.

    ``speed`` in rad/s (or m/s), ``time`` the later stamp of that pair, s;
    a state without the joint (NaN) is skipped, and so is a pair with the
    same stamp; fewer than two usable states give ``(0.0, nan)``.
    """
    from tutorial.bag.series import JointSeries

    def series(stamps, q):
        stamps = np.asarray(stamps, dtype=float)
        return JointSeries(
            "/Tank/joint_state",
            stamps,
            stamps - stamps[0] if len(stamps) else stamps,
            {"TURRET_Y": np.asarray(q, dtype=float), "TURRET_P": np.zeros(len(stamps))},
        )

    def case(label, s, joint, expected, hint):
        call = f"peak_speed(a series: {label}, {joint!r})"

        def run():
            got = func(s, joint)
            try:
                speed, at = (float(v) for v in got)
            except (TypeError, ValueError):
                raise CaseFailed(f"{call} returned {got!r}, expected (speed, time) {show(expected)}.") from None
            want_speed, want_at = expected
            same_at = (math.isnan(at) and math.isnan(want_at)) or abs(at - want_at) <= 1e-9
            if abs(speed - want_speed) > 1e-9 or not same_at:
                said = f"{call} returned ({speed:.6g}, {at:.6g}), expected ({want_speed:.6g}, {want_at:.6g})."
                if speed == want_speed == 0.0 and math.isnan(at) and not math.isnan(want_at):
                    raise CaseFailed(  # a joint that stood still, taken for one with no pairs
                        said,
                        "a joint that stood still has pairs, each at speed 0.0: the first pair wins the tie, so "
                        "the time is its later stamp; (0.0, math.nan) is for fewer than two usable states only.",
                    )
                raise CaseFailed(said, hint)

        return Case(call, run, hint)

    t = [0.0, 0.02, 0.04, 0.06, 0.08]
    return grade(
        "Exercise 7.2, the turret's top speed",
        [
            case(
                "steady at 1 rad/s",
                series(t, [0.0, 0.02, 0.04, 0.06, 0.08]),
                "TURRET_Y",
                (1.0, 0.02),
                "speed = |q[i+1] - q[i]| / (stamp[i+1] - stamp[i]); ties: the first pair.",
            ),
            case(
                "one fast step",
                series(t, [0.0, 0.02, 0.10, 0.12, 0.14]),
                "TURRET_Y",
                (4.0, 0.04),
                "the time is the later stamp of the fastest pair.",
            ),
            case(
                "turning back",
                series(t, [0.5, 0.4, 0.1, 0.05, 0.0]),
                "TURRET_Y",
                (15.0, 0.04),
                "a speed has no sign: take the absolute value.",
            ),
            case(
                "a state without the joint",
                series(t, [0.0, np.nan, 0.04, 0.06, 0.08]),
                "TURRET_Y",
                (1.0, 0.04),
                "skip a state whose position is NaN (its message did not carry the joint): pair the usable ones.",
            ),
            case(
                "two states with one stamp",
                series([0.0, 0.02, 0.02, 0.04], [0.0, 0.02, 0.05, 0.06]),
                "TURRET_Y",
                (1.0, 0.02),
                "a pair with no time between them has no speed: skip it (never divide by zero).",
            ),
            case(
                "another joint",
                series(t, [0.0, 1.0, 2.0, 3.0, 4.0]),
                "TURRET_P",
                (0.0, 0.02),
                "use series.positions[joint], the joint asked for.",
            ),
            case(
                "a single state",
                series([0.0], [0.3]),
                "TURRET_Y",
                (0.0, math.nan),
                "with fewer than two usable states, return (0.0, math.nan).",
            ),
        ],
    )
