"""Checks for the exercises of notebook 07 (record and replay).

Exercise 7.1, when did the operator let go: ``release_times(path) -> list[float]``,
the seconds (since the bag's first ``/joy``) at which every stick came back to the centre.
Exercise 7.2, the turret's top speed: ``peak_speed(series, joint) -> (rad/s, s)`` from a
:class:`tutorial.tools.bag.reader.JointSeries`.

The checks write small bags of their own with the library's
:class:`tutorial.tools.bag.writer.BagWriter` (messages with known values at known
times), so every case is exact, and read nothing from the network.  Over
400 lines, one job: one notebook's checks, with the bags and series their
hidden cases draw.
"""

from __future__ import annotations

import math
import tempfile
from pathlib import Path

import numpy as np

from tutorial.exercises.grader import Case, CaseFailed, Result, grade, hidden_random, show

T0 = 1_700_000_000_000_000_000  # ns: the bags' first log time (any epoch time will do)
JOY, OTHER_JOY = "/joy", "/remote/joy"  # the operator's Joys; another gamepad's, which do not count


def write_bag(path: Path, messages: list[tuple[str, float, object]]) -> Path:
    """Write ``(topic, seconds after T0, message)`` into an MCAP bag at ``path``; the path."""
    from rclpy.qos import QoSProfile
    from rclpy.serialization import serialize_message

    from tutorial.interfaces.definitions import full_text
    from tutorial.tools.bag.qos import profile_dict, serialize_profiles
    from tutorial.tools.bag.writer import BagWriter

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


def _joy(lv: float = 0.0, rh: float = 0.0, axes=None, stamp: float = 0.0, buttons=None):
    from sensor_msgs.msg import Joy

    buttons = list(buttons) if buttons is not None else [0] * 8
    msg = Joy(axes=list(axes) if axes is not None else [0.0, lv, rh, 0.0, 0.0, 0.0, 0.0, 0.0], buttons=buttons)
    msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(round(stamp * 1e9), 1_000_000_000)
    return msg


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

    While grading, hidden bags drawn by the same rules (a D-pad or trigger
    pushed alone, an axis barely off centre, two axes pushed opposite ways,
    another gamepad's Joys, a first Joy that is released, buttons held in a
    long drive, the Joys stamped by the gamepad's own clock) are judged by
    :func:`_releases`.
    """

    def bag(label, messages, expected, hint, hidden=False):
        call = label if hidden else f"release_times(a bag: {label})"

        def run():
            with tempfile.TemporaryDirectory() as d:
                path = write_bag(Path(d) / "check.mcap", messages)
                got = func(path)
            try:
                got_list = [float(t) for t in got]
            except (TypeError, ValueError):
                raise CaseFailed(f"{call} returned {got!r}, expected a list of seconds {show(expected)}.") from None
            # not abs(...) <= tol: a NaN time, which compares False with everything, fails
            if len(got_list) != len(expected) or any(not abs(a - b) <= 1e-6 for a, b in zip(got_list, expected)):
                raise CaseFailed(
                    f"{call} returned {show([round(t, 4) for t in got_list])}, expected {show(expected)}.", hint
                )

        return Case(call, run, hint, hidden)

    def drawn(rng, label, kind):
        """A hidden case: a bag drawn by ``kind``'s rules, its releases found by the statement's rule."""
        messages = _random_joy_bag(rng, kind)
        return bag(label, messages, _releases(messages), "follow each rule of the statement, for every Joy.", True)

    rng = hidden_random("7.1")  # while grading: this learner's own bags, by the statement's rules
    hidden = (
        [
            drawn(rng, "a D-pad or trigger axis pushed alone", "dpad"),
            drawn(rng, "an axis barely off centre, which is not released", "tiny"),
            drawn(rng, "two axes pushed opposite ways at once", "opposite"),
            drawn(rng, "another gamepad's Joys and joint states between the Joys", "topics"),
            drawn(rng, "a bag whose first Joy is released and comes after other topics", "late"),
            drawn(rng, "a long drive of pushes, repeats and releases over several seconds", "long"),
        ]
        if rng
        else []
    )
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
            *hidden,
        ],
    )


def _releases(messages) -> list[float]:
    """The statement's rule: log times of the /joy Joys with every axis 0 right after one that was not, in s
    after the first /joy (as :func:`write_bag` stores the times: whole nanoseconds)."""
    joys = sorted(((T0 + round(s * 1e9), msg) for topic, s, msg in messages if topic == JOY), key=lambda j: j[0])
    times, pushed = [], False
    for t, msg in joys:
        released = all(a == 0.0 for a in msg.axes)
        if released and pushed:
            times.append((t - joys[0][0]) * 1e-9)
        pushed = not released
    return times


def _pushed_axes(rng, kind: str) -> list[float]:
    """The axes of a pushed Joy: ``dpad`` a D-pad or trigger alone, ``tiny`` an axis barely off centre,
    ``opposite`` two axes pushed opposite ways (their sum 0), else one to three axes anywhere."""
    axes = [0.0] * 8
    if kind == "dpad":
        axes[rng.randrange(4, 8)] = rng.choice((-1.0, 1.0, rng.uniform(0.1, 1.0)))
    elif kind == "tiny":
        axes[rng.randrange(8)] = rng.choice((-1.0, 1.0)) * rng.uniform(1e-4, 0.04)
    elif kind == "opposite":
        i, j = rng.sample(range(8), 2)
        axes[i] = rng.uniform(0.1, 1.0)
        axes[j] = -axes[i]
    else:
        for i in rng.sample(range(8), rng.randrange(1, 4)):
            axes[i] = rng.choice((-1.0, 1.0)) * rng.uniform(0.01, 1.0)
    return axes


def _random_joy_bag(rng, kind: str) -> list[tuple[str, float, object]]:
    """A bag's ``(topic, s, message)``: pushes (by :func:`_pushed_axes`) and releases on /joy, each state repeated
    at 20 Hz a few times, the Joys stamped by the gamepad's clock (not the recorder's); for ``topics``, ``late``
    and ``long``, joint states and another gamepad's Joys between them, sometimes before the first /joy; for
    ``long``, buttons held now and then (a button is no axis: a Joy with every axis 0 is released)."""
    clock = rng.uniform(1.0, 500.0)  # s: the gamepad's clock when the bag starts
    released = (lambda: [0.0] * 8, lambda: [-0.0] * 8, lambda: [], lambda: [0.0] * rng.randrange(1, 8))
    t = rng.uniform(0.5, 3.0) if kind in ("topics", "late") else rng.choice((0.0, rng.uniform(0.0, 2.0)))
    pushing = {"late": False, "long": rng.random() < 0.5}.get(kind, True)  # does the first Joy push?
    messages = []
    for _ in range(rng.randrange(5, 9) if kind == "long" else rng.randrange(3, 6)):
        axes = _pushed_axes(rng, kind if kind in ("dpad", "tiny", "opposite") else "any") if pushing else None
        for _ in range(rng.randrange(1, 5)):
            state = axes if pushing else rng.choice(released)()
            buttons = [int(rng.random() < 0.3) for _ in range(8)] if kind == "long" else None
            messages.append((JOY, t, _joy(axes=state, stamp=clock + t - rng.uniform(0.001, 0.03), buttons=buttons)))
            t += 0.05
        t += rng.uniform(0.0, 0.6)
        pushing = not pushing
    if kind in ("topics", "late", "long"):
        end = t
        for _ in range(rng.randrange(4, 12)):
            s = rng.uniform(0.0, end)
            if rng.random() < 0.5:
                messages.append(("/Tank/joint_state", s, _state(s, rng.uniform(-1.0, 1.0))))
            else:
                axes = _pushed_axes(rng, "any") if rng.random() < 0.5 else [0.0] * 8
                messages.append((OTHER_JOY, s, _joy(axes=axes, stamp=clock + s)))
        first = min(s for topic, s, _ in messages if topic == JOY)
        messages.append((OTHER_JOY, first * rng.uniform(0.0, 0.9), _joy(axes=_pushed_axes(rng, "any"))))
    return sorted(messages, key=lambda m: m[1])


def check_peak_speed(func) -> Result:
    """Check ``func(series, joint) -> (speed, time)``: a joint's largest |dq/dt| between consecutive states.

    ``speed`` in rad/s (or m/s), ``time`` the later stamp of that pair, s;
    a state without the joint (NaN) is skipped, and so is a pair with the
    same stamp; fewer than two usable states give ``(0.0, nan)``.

    While grading, hidden series drawn by the same rules (stamps from a
    second or more, uneven, repeated; exact ties; states without the joint)
    are judged by :func:`_peak`.
    """
    from tutorial.tools.bag.series import JointSeries

    def series(stamps, q):
        stamps = np.asarray(stamps, dtype=float)
        return JointSeries(
            "/Tank/joint_state",
            stamps,
            stamps - stamps[0] if len(stamps) else stamps,
            {"TURRET_Y": np.asarray(q, dtype=float), "TURRET_P": np.zeros(len(stamps))},
        )

    def case(label, s, joint, expected, hint, hidden=False):
        call = label if hidden else f"peak_speed(a series: {label}, {joint!r})"

        def run():
            got = func(s, joint)
            try:
                speed, at = (float(v) for v in got)
            except (TypeError, ValueError):
                raise CaseFailed(f"{call} returned {got!r}, expected (speed, time) {show(expected)}.") from None
            want_speed, want_at = expected
            same_at = (math.isnan(at) and math.isnan(want_at)) or abs(at - want_at) <= 1e-9
            if not abs(speed - want_speed) <= 1e-9 or not same_at:  # a NaN speed fails
                said = f"{call} returned ({speed:.6g}, {at:.6g}), expected ({want_speed:.6g}, {want_at:.6g})."
                if speed == want_speed == 0.0 and math.isnan(at) and not math.isnan(want_at):
                    raise CaseFailed(  # a joint that stood still, taken for one with no pairs
                        said,
                        "a joint that stood still has pairs, each at speed 0.0: the first pair wins the tie, so "
                        "the time is its later stamp; (0.0, math.nan) is for fewer than two usable states only.",
                    )
                raise CaseFailed(said, hint)

        return Case(call, run, hint, hidden)

    def drawn(rng, label, kind):
        """A hidden case: a series drawn by ``kind``'s rules, its peak found by the statement's rule."""
        s, joint = _random_series(rng, kind)
        return case(label, s, joint, _peak(s.stamp, s.positions[joint]), "follow each rule of the statement.", True)

    rng = hidden_random("7.2")  # while grading: this learner's own series, by the statement's rules
    hidden = (
        [
            drawn(rng, "states stamped a second or more into the simulation, unevenly spaced", "late"),
            drawn(rng, "a drive of many states, stamped a second or more in", "late"),
            drawn(rng, "several pairs tied at the top speed", "ties"),
            drawn(rng, "states without the joint at the ends and in a row", "nan"),
            drawn(rng, "several states sharing a stamp", "repeats"),
            drawn(rng, "only one state carries the joint", "one"),
            drawn(rng, "a joint that stood still, stamped a second or more in", "still"),
        ]
        if rng
        else []
    )
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
            *hidden,
        ],
    )


def _peak(stamps, q) -> tuple[float, float]:
    """The statement's rule: the largest |dq/dt| between consecutive usable states (NaN skipped, a pair with no
    time between them skipped; the first of equal speeds), and the later stamp; (0.0, nan) without a pair."""
    usable = [(t, x) for t, x in zip(stamps.tolist(), q.tolist()) if not math.isnan(x)]
    best = (0.0, math.nan)
    for (t0, q0), (t1, q1) in zip(usable, usable[1:]):
        if t1 > t0 and (math.isnan(best[1]) or abs((q1 - q0) / (t1 - t0)) > best[0]):
            best = (abs((q1 - q0) / (t1 - t0)), t1)
    return best


def _random_series(rng, kind: str):
    """A JointSeries of TURRET_Y and TURRET_P, and the joint to ask for: stamped from a second or more of
    simulation time, states 1 ms to 0.1 s apart, received 0 to 5 ms later, the other joint moving too.
    ``ties``: speeds of a few values, exact in binary, the top one more than once; ``repeats``: states sharing a
    stamp; ``nan``, ``one``: states without the joint; ``still``: the joint does not move."""
    from tutorial.tools.bag.series import JointSeries

    n = rng.randrange(6, 40)
    if kind == "ties":
        steps = [rng.choice((1, 2, 4)) / 64 for _ in range(n - 1)]
        speeds = [rng.choice((-2, -1, 0, 1, 2)) for _ in steps]
        for k in rng.sample(range(n - 1), rng.randrange(2, 4)):
            speeds[k] = rng.choice((-4, 4))
        start, moves = rng.randrange(1, 400) + rng.randrange(64) / 64, [v * dt for v, dt in zip(speeds, steps)]
    else:
        steps = [rng.choice((0.001, 0.02, 0.02, 0.05, rng.uniform(0.001, 0.1))) for _ in range(n - 1)]
        start, moves = rng.uniform(1.0, 500.0), [rng.uniform(-3.0, 3.0) * dt for dt in steps]
        for k in rng.sample(range(n - 1), rng.randrange(2, 5)) if kind == "repeats" else ():
            steps[k], moves[k] = 0.0, rng.uniform(-0.5, 0.5)  # two messages in one step
    stamps = np.cumsum([start, *steps])
    q = np.cumsum([rng.randrange(-64, 64) / 64, *([0.0] * (n - 1) if kind == "still" else moves)])
    if kind == "nan":
        gone = [0, n - 1, *rng.sample(range(1, n - 2), 3)]
        q[gone + [gone[-1] + 1]] = np.nan
    elif kind == "one":
        keep = rng.randrange(n)
        q[[k for k in range(n) if k != keep]] = np.nan
    other = np.cumsum([0.0, *(rng.uniform(-3.0, 3.0) * dt for dt in steps)])
    received = stamps + np.array([rng.uniform(0.0, 0.005) for _ in range(n)])
    joint, another = rng.sample(("TURRET_Y", "TURRET_P"), 2)
    return JointSeries("/Tank/joint_state", stamps, received - received[0], {joint: q, another: other}), joint
