"""The parts of the checks of notebooks 02 and 04 that whole answers do not pin down: no simulation, no ROS node.

The exercises' tests (tests/test_exercises.py) run each check on worked
solutions and on wrong answers.  These hold each part to its own rule at
its edges: a hint to the mistake it names (an empty period, the step
before a period, the step after it), the numbers a message shows, and the
hidden runs' draws to what the statement promises (found by make mutate:
a mutant of each survived the whole answers).
"""

from __future__ import annotations

import math
import random
from types import SimpleNamespace

import pytest

from tutorial.exercises import step2_joint_state_publisher as step2
from tutorial.exercises import step4_imu_publisher as step4

# One reading per step (x, y, z in m/s^2).  Steps 2 to 4 are the checked period; each other step is made
# larger, or smaller, than the period's own so that each mistake's window gives a value of its own.
READINGS = [
    (9.0, 0.0, 0.0),  # 0: before the period, the largest horizontal reading up to the period's end
    (0.0, 7.0, 0.0),  # 1: the step just before the period
    (1.0, 1.0, 0.0),  # 2: the period's first
    (2.0, 0.0, 5.0),  # 3: the period's largest with z in the norm (5.39), not horizontally (2)
    (0.0, 3.0, 0.0),  # 4: the period's last, its horizontal peak (3)
    (60.0, 0.0, 0.0),  # 5: after the period
]
FIRST, LAST = 2, 4


def hint(got: float, mean: float = 0.123, readings=READINGS, first: int = FIRST, last: int = LAST) -> str:
    return step4._diagnose(got, mean, readings, first, last)


def test_4_1_the_right_peak_gets_no_hint():
    assert hint(3.0) == ""


def test_4_1_the_periods_mean_is_named_as_the_mean():
    assert "the period's mean" in hint(0.123)


def test_4_1_a_norm_with_z_is_named_only_over_the_periods_own_steps():
    assert "x and y only" in hint(math.sqrt(2.0**2 + 5.0**2))
    # the steps before the period (9, 7) and after it (60) are no such mistake
    assert hint(60.0) == ""
    for before in (9.0, 7.0):
        assert "x and y only" not in hint(before)


def test_4_1_a_peak_never_started_over_is_named_only_after_the_first_period():
    assert "start over" in hint(9.0)  # the largest since step 0
    # the second period (steps 1 to 2), step 0 the largest: started over, not one step early
    assert "start over" in hint(8.0, readings=[(0.0, 8.0, 0.0), (1.0, 1.0, 0.0), (0.0, 3.0, 0.0)], first=1, last=2)


def test_4_1_a_peak_one_step_early_is_named_for_the_step_before_the_period_only():
    early = "belongs to the period it ends"
    assert early in hint(7.0)  # steps 1 to 3: the step before, not the last
    # the period's own last step is larger than the early window's (steps 1 and 2): its peak is still named
    assert early in hint(2.5, readings=[(0.0, 0.0, 0.0), (0.0, 2.5, 0.0), (1.0, 1.0, 0.0), (0.0, 3.0, 0.0)], last=3)
    # the first period: its early window is its own steps but the last (0 and 1 of 0 to 2)
    assert early in hint(5.0, readings=[(0.0, 5.0, 0.0), (1.0, 1.0, 0.0), (0.0, 9.0, 0.0)], first=0, last=2)
    # the second period (steps 1 to 2): its early window starts at step 0
    assert early in hint(8.0, readings=[(0.0, 8.0, 0.0), (1.0, 1.0, 0.0), (0.0, 9.0, 0.0)], first=1, last=2)


def test_4_1_an_empty_early_window_reads_as_a_peak_of_zero():
    # rate 0: each step is its own period; the first (step 0 alone) has no step before it.  A peak of 0
    # there is one published before its step's reading was added: the early mistake.
    one = [(0.0, 1.0, 2.0)]
    assert "belongs to the period it ends" in hint(0.0, mean=5.0, readings=one, first=0, last=0)
    assert hint(0.5, mean=5.0, readings=one, first=0, last=0) == ""


def test_4_1_numbers_in_a_message_have_six_significant_digits():
    assert step4._num(0.000123456789) == "0.000123457"
    assert step4._num(20.0) == "20"


@pytest.mark.parametrize("got", [math.nan, math.inf, 3])
def test_4_1_a_peak_that_is_no_finite_float_is_never_the_right_one(got):
    assert not step4._same(got, 3.0)


def test_2_2_a_hidden_tumble_starts_in_the_air_turned_any_way_and_spinning_about_both_horizontal_axes():
    starts = [step2._tumble(random.Random(seed)) for seed in range(400)]
    for s in starts:
        assert math.isclose(sum(q * q for q in s["quat"]), 1.0)
        assert all(1.0 <= abs(w) <= 2.0 for w in s["spin"][:2]) and abs(s["spin"][2]) <= 2.0
        assert s["place"][2] == 1.0 and all(abs(p) <= 1.0 for p in s["place"][:2])
        assert all(abs(d) <= limit for d, limit in zip(s["drift"], (0.2, 0.2, 0.05)))
    # every orientation equally likely: each component's mean near 0 (a biased draw puts one near 0.5)
    for k in range(4):
        assert abs(sum(s["quat"][k] for s in starts) / len(starts)) < 0.1
    # both ways and spread over their ranges
    for key, k in [*(("spin", k) for k in range(3)), ("place", 0), ("place", 1), *(("drift", k) for k in range(3))]:
        values = [s[key][k] for s in starts]
        assert min(values) < 0 < max(values), (key, k)
    for k in range(2):
        magnitudes = [abs(s["spin"][k]) for s in starts]
        assert min(magnitudes) < 1.2 and max(magnitudes) > 1.8


def test_2_1_the_hidden_choices_follow_the_statement():
    draws = [step2._hidden_choices(random.Random(seed)) for seed in range(300)]
    assert all(len(runs) == 4 for runs in draws)
    runs = [run for runs in draws for run in runs]
    sizes, orders, spaces, rates = set(), set(), set(), set()
    for joints, expected, rate, script in runs:
        names = joints.split(",") if joints else []
        chosen = [n.strip() for n in names]
        assert len(set(chosen)) == len(chosen) <= 2 and set(chosen) <= set(step2.TANK)
        assert expected == (chosen or step2.TANK)
        sizes.add(len(chosen))
        orders.add(tuple(chosen))
        spaces |= {len(n) - len(n.lstrip(" ")) for n in names} | {len(n) - len(n.rstrip(" ")) for n in names}
        rates.add(rate)
        assert [t for t, _ in script] == [0.1, 0.9, 1.0] and script[0][1] == (0.0, 0.0, 0.0, 0.0)
        for _, sticks in script[1:]:
            assert sticks[0] == 0.0 and abs(sticks[1]) <= 0.5
            assert all(0.3 <= abs(v) <= 0.8 for v in sticks[2:])
    assert sizes == {0, 1, 2} and {("TURRET_P", "TURRET_Y"), ("TURRET_Y", "TURRET_P")} <= orders
    assert spaces == {0, 1, 2} and rates == set(step2.HIDDEN_CHOICE_RATES)
    sticks = [s for _, _, _, script in runs for _, s in script[1:]]
    for k in (1, 2, 3):  # forward, turn, tilt: either way, over their whole ranges
        values = [s[k] for s in sticks]
        assert min(values) < 0 < max(values)
        assert max(abs(v) for v in values) > (0.45 if k == 1 else 0.75)
    assert min(abs(s[k]) for s in sticks for k in (2, 3)) < 0.35


def test_2_1_the_hidden_names_the_tank_lacks_follow_the_statement():
    kinds = list(step2.LACKING)
    seen = {kind: set() for kind in kinds}
    positions, counts = set(), set()
    for seed in range(300):
        cases = step2._hidden_lacking(random.Random(seed))
        assert [kind for kind, _ in cases] == kinds
        for kind, joints in cases:
            names = [n.strip() for n in joints.split(",")]
            lacking = [k for k, n in enumerate(names) if n not in step2.TANK]
            assert len(lacking) == 1 and lacking[0] < len(names) - 1  # one, never the last
            known = [n for n in names if n in step2.TANK]
            assert len(set(known)) == len(known) in (1, 2)
            positions.add(lacking[0])
            counts.add(len(known))
            seen[kind].add(names[lacking[0]])
    assert positions == {0, 1} and counts == {1, 2}
    wrong_case = seen["a joint of the tank in the wrong case"]
    assert {n.upper() for n in wrong_case} == set(step2.TANK) and not wrong_case & set(step2.TANK)
    assert {"turret_y", "Turret_p"} <= wrong_case
    assert seen["a part of a joint's name"] == {"TURRET", "TURRET_", "URRET_P", "RRET_Y", "_P"}
    assert seen["another robot's joint"] == {"GUN", "SLEW", "LUFF", "TROLLEY", "WHEEL_L"}


def test_2_x_every_hidden_rate_has_a_period_of_whole_steps():
    for rate in (*step2.HIDDEN_CHOICE_RATES, *(r for rates in step2.HIDDEN_POSE_RATES.values() for r in rates)):
        assert math.isclose(1000.0 / rate, round(1000.0 / rate)), rate
    assert all(r == int(r) for r in step2.HIDDEN_POSE_RATES["whole"])
    assert all(r != int(r) for r in step2.HIDDEN_POSE_RATES["fractional"])


def test_4_1_the_hidden_rates_follow_the_statement():
    rates = [step4._hidden_peak_rates(random.Random(seed)) for seed in range(300)]
    for k, (low, high) in enumerate(((6, 20), (20, 45))):
        drawn = [r[k] for r in rates]
        assert all(low <= r <= high for r in drawn)
        assert min(drawn) < low + 1 and max(drawn) > high - 1
        assert not any(math.isclose(1000 / r, round(1000 / r)) for r in drawn)  # no whole number of steps


def _ms(seconds: float) -> float:
    return round(seconds * 1000, 6)


def test_4_2_the_hidden_parameters_follow_the_statement():
    draws = [step4._hidden_collision_parameters(random.Random(seed)) for seed in range(3000)]
    ranges = {  # per drawn set: each key's range; holdoffs in ms, a whole number and a half
        0: {"rate": (30, 50), "threshold": (2.5, 5), "holdoff": (150.5, 399.5)},
        1: {"rate": (9.5, 15), "threshold": (5, 10), "holdoff": (20.5, 599.5)},
    }
    for k, limits in ranges.items():
        assert all(set(d[k]) == {"rate", "threshold", "holdoff"} for d in draws)
        for key, (low, high) in limits.items():
            drawn = [_ms(d[k][key]) if key == "holdoff" else d[k][key] for d in draws]
            assert all(low <= v <= high for v in drawn), (k, key)
            if key == "holdoff":  # every whole number of ms drawn: both ends too
                assert (min(drawn), max(drawn)) == (low, high), (k, key)
            else:  # spread over the whole range
                edge = (high - low) / 40
                assert min(drawn) < low + edge and max(drawn) > high - edge, (k, key)
    tiny = [_ms(d[2]) for d in draws]
    assert min(tiny) == 2.5 and max(tiny) == 44.5
    for holdoff in tiny + [_ms(d[k]["holdoff"]) for d in draws for k in (0, 1)]:
        assert holdoff % 1 == 0.5  # a whole number of ms and a half: never a whole number of steps


def test_2_2_the_same_rotation_is_q_or_minus_q_of_unit_length_up_to_the_tolerance():
    q = (0.0, 0.6, 0.0, 0.8)
    assert step2._same_rotation(q, q, 1e-9) and step2._same_rotation(tuple(-v for v in q), q, 1e-9)
    # 1 - |a . b| exactly at the tolerance passes; a hair beyond it does not
    half_turn = (0.0, 0.0, math.sqrt(0.75), 0.5)  # |a . b| = 0.5 exactly
    assert step2._same_rotation((0.0, 0.0, 0.0, 1.0), half_turn, 0.5)
    assert not step2._same_rotation((0.0, 0.0, 0.0, 1.0), half_turn, 0.4999)
    # a quaternion scaled off unit length fails however close its direction: within 1e-3 of 1 in squared norm
    assert step2._same_rotation((0.0, 0.0, 0.0, math.sqrt(1.0009765625)), (0.0, 0.0, 0.0, 1.0), 1e-2)
    assert not step2._same_rotation((0.0, 0.0, 0.0, math.sqrt(1.00146484375)), (0.0, 0.0, 0.0, 1.0), 1e-2)
    assert not step2._same_rotation((0.0, 0.0, 0.0, 0.5), (0.0, 0.0, 0.0, 1.0), 1.0)
    for bad in (math.nan, math.inf, -math.inf):
        assert not step2._same_rotation((bad, 0.0, 0.0, 1.0), (0.0, 0.0, 0.0, 1.0), 1.0)
        assert not step2._same_rotation((bad, 0.0, 0.0, 1.0), (0.6, 0.0, 0.0, 0.8), 1.0)


def test_2_2_the_checks_own_runs_are_measured_by_their_turn_and_their_tilt():
    def about(axis, angle):  # w x y z
        return (math.cos(angle / 2), *(math.sin(angle / 2) * a for a in axis))

    assert math.isclose(step2._turned([about((0, 0, 1), 0.1), about((0, 0, 1), -0.25)]), 0.25)
    assert step2._turned([about((1, 0, 0), 1.0)]) == 0.0  # a roll is no turn
    assert math.isclose(step2._tilted([about((1, 0, 0), 0.2), about((0, 1, 0), -1.0)]), math.sin(0.5))
    assert math.isclose(step2._tilted([about((0.6, 0.8, 0), 1.0)]), math.sin(0.5))
    assert step2._tilted([about((0, 0, 1), 2.0)]) == 0.0  # a turn is no tilt
    # tumbling: the angle turned from the first orientation, about any axis
    tumble = [about((1, 0, 0), 0.0), about((0.6, 0.8, 0), 0.5), about((0.6, 0.8, 0), 1.5)]
    assert math.isclose(step2._rotated(tumble), 1.5)
    assert math.isclose(step2._rotated([about((0, 1, 0), 0.3), about((0, 1, 0), -0.9)]), 1.2)
    assert step2._rotated([about((0, 0, 1), 0.7)] * 3) == 0.0
    # a quaternion's dot product with itself can round above 1 (1.0000000000000002 for this turn of 0.05 rad,
    # its cos and sin written out, so that every platform's arithmetic gives the same): 0, no error
    q = (0.9996875162757026, 0.0, 0.0, 0.024997395914712332)
    assert sum(v * v for v in q) > 1.0
    assert step2._rotated([q, q]) == 0.0


def _imu(*means):
    return [SimpleNamespace(linear_acceleration=SimpleNamespace(x=x, y=y)) for x, y in means]


def test_4_2_the_exact_threshold_is_the_largest_mean_below_the_top_that_every_way_computes_alike():
    from tutorial.exercises.grader import CaseFailed

    # horizontal means 5.001, 4.0 and 4.243 (3, 3: every way gives 4.242640687119285)
    assert step4._exact_threshold(_imu((0.1, 5.0), (4.0, 0.0), (3.0, 3.0))) == math.hypot(3.0, 3.0)
    # a mean that the ways compute apart is passed over: hypot(0.076, 1.624) ends in ...675, the square root ...673
    x, y = 0.076, 1.624
    assert math.hypot(x, y) != math.sqrt(x * x + y * y)
    assert step4._exact_threshold(_imu((5.0, 5.0), (x, y), (0.0, 0.1))) == 0.1
    with pytest.raises(CaseFailed, match=r"^the Imu messages have no mean that every way to compute hypot\(x, y\)"):
        step4._exact_threshold(_imu((3.0, 4.0), (0.0, 5.0)))  # no mean below the largest


def test_4_x_each_message_after_an_imu_message_is_paired_with_it_and_one_after_another_with_none():
    node = SimpleNamespace(order=["/Tank/imu", "/Tank/peak", "/Tank/peak", "/Tank/other", "/Tank/imu", "/Tank/peak"])
    assert step4._follows(node, "/Tank/peak") == [0, None, 1]
    assert step4._follows(SimpleNamespace(order=["/Tank/peak", "/Tank/imu"]), "/Tank/peak") == [None]


def test_4_2_the_threshold_y_decides_lies_between_the_larger_part_and_the_hypot():
    threshold = step4._y_threshold(_imu((10.0, 0.1), (3.0, 3.0), (0.0, 2.0)))
    assert 3.0 < threshold < math.hypot(3.0, 3.0) and threshold == (3.0 + math.hypot(3.0, 3.0)) / 2
    assert step4._y_threshold(_imu((-3.0, 3.0), (0.0, 0.0))) == threshold  # signs and still periods alike
    with pytest.raises(RuntimeError, match=r"^the Imu messages have no mean whose y part decides"):
        step4._y_threshold(_imu((10.0, 0.1), (0.0, 2.0), (0.0, 0.0)))  # 10.0005: within 5 % of its larger part
    # small means too (a tank at rest): the largest ratio, however small the parts
    assert step4._y_threshold(_imu((0.9, 0.0), (0.003, 0.003))) == (0.003 + math.hypot(0.003, 0.003)) / 2
    with pytest.raises(RuntimeError, match=r"^the Imu messages have no mean whose y part decides"):
        step4._y_threshold(_imu((0.0, 0.0), (0.0, 0.0)))  # nothing moves: no threshold of 0
    y = 0.3201562118716422  # hypot(1, y) is 1.05 exactly, in floats: 5 % above its larger part is enough
    assert math.hypot(1.0, y) == 1.05 * 1.0
    assert step4._y_threshold(_imu((1.0, y))) == (1.0 + 1.05) / 2


def test_4_x_the_noting_node_gives_rclpy_every_argument_of_a_publisher_and_notes_each_message_in_turn():
    from std_msgs.msg import Float64

    made, sent = [], []

    class Real:  # what rclpy's Node is asked for
        def create_publisher(self, msg_type, topic, qos_profile, **kwargs):
            made.append((msg_type, topic, qos_profile, kwargs))
            return SimpleNamespace(publish=lambda msg: sent.append((topic, msg.data)), destroy=lambda: None)

    node = step4._NotingNode(Real())
    imu = node.create_publisher(Float64, "/Tank/imu", 1, callback_group="group")
    peak = node.create_publisher(Float64, "/Tank/peak", 2)
    imu.publish(Float64(data=1.0))
    peak.publish(Float64(data=2.0))
    imu.publish(Float64(data=3.0))
    assert made == [(Float64, "/Tank/imu", 1, {"callback_group": "group"}), (Float64, "/Tank/peak", 2, {})]
    assert node.order == ["/Tank/imu", "/Tank/peak", "/Tank/imu"]
    assert sent == [("/Tank/imu", 1.0), ("/Tank/peak", 2.0), ("/Tank/imu", 3.0)]


# ---- 2.1's check on a stand-in drive: what it asks of each run, and its count of messages at the edge ----------

JOINT_ADDRESSES = {"TURRET_Y": (7, 6), "TURRET_P": (8, 7)}  # (qpos, dof): the tank's free joint comes first


def _stand_in_2_1(
    runs: list, count=lambda rate: round(rate * step2.DURATION) + 1, edit=None, at=None, refuse=True, log=True
):
    """A stand-in for 2.1's drive, as a right answer runs: ``count(rate)`` messages 1/rate apart, of the joints
    asked for, with the values of one state (TURRET_Y's position and velocity 0); refuses a name the tank lacks,
    logging an error.  Each run's ``(joints, rate, script)`` is appended to ``runs``; ``edit(message)`` changes
    each message; ``at(seconds, state)`` stands in for the probe's state at a stamp; ``refuse``: refuse a name the
    tank lacks, or those names for which ``refuse(names)`` is true (``log``: with an error logged; "not done": a
    stub's NotImplementedError instead)."""
    from tutorial.app.app import ControllerError

    qpos, qvel, effort = [0.0] * 7 + [0.0, -0.5], [0.0] * 6 + [0.0, -2.5], [0.0] * 6 + [3.0, 4.0]
    state = (qpos, None, None, qvel, effort)

    def drive(name, cls, parameters, script=None, duration=None, tumble=None):
        joints, rate = parameters["joints"], parameters["rate"]
        runs.append((joints, rate, script))
        names = [n.strip() for n in joints.split(",") if n.strip()] or step2.TANK
        if refuse(names) if callable(refuse) else refuse and not set(names) <= set(step2.TANK):
            if log == "not done":  # the refusal left as a stub
                raise ControllerError("Selected raised in configure") from NotImplementedError()
            refused = ControllerError("Selected refused to configure")
            refused.errors_logged = 1 if log else 0  # what _drive says of config.log's errors
            raise refused
        messages = []
        for k in range(count(rate)):
            sec, nanosec = divmod(round(k / rate * 1e9), 1_000_000_000)
            messages.append(
                SimpleNamespace(
                    name=list(names),
                    position=[qpos[JOINT_ADDRESSES[n][0]] for n in names if n in JOINT_ADDRESSES],
                    velocity=[qvel[JOINT_ADDRESSES[n][1]] for n in names if n in JOINT_ADDRESSES],
                    effort=[effort[JOINT_ADDRESSES[n][1]] for n in names if n in JOINT_ADDRESSES],
                    header=SimpleNamespace(stamp=SimpleNamespace(sec=sec, nanosec=nanosec)),
                )
            )
        for msg in messages if edit else ():
            edit(msg)
        publisher = SimpleNamespace(messages=lambda: messages)
        node = SimpleNamespace(published=lambda topic: [publisher] if topic == "/Tank/joint_state" else [])
        probe = SimpleNamespace(at=lambda seconds: at(seconds, state) if at else state)
        return node, probe, dict(JOINT_ADDRESSES)

    return drive


def test_2_1_each_hidden_run_drives_the_turret_with_the_script_drawn_for_it(monkeypatch):
    runs: list = []
    monkeypatch.setattr(step2, "_drive", _stand_in_2_1(runs))
    monkeypatch.setattr(step2, "hidden_random", lambda exercise: random.Random(f"test/{exercise}"))
    result = step2.check_selected_joints(type("Selected", (), {}))
    assert result.passed, str(result)
    drawn = step2._hidden_choices(random.Random("test/2.1"))
    chosen = [(joints, rate, script) for joints, _, rate, script in drawn]
    assert [run for run in runs if run[2] is not None] == chosen
    assert all(script is None for _, _, script in runs[: len(runs) - len(chosen) - len(step2.LACKING)])


def test_2_1_a_run_needs_rate_x_duration_messages_at_least(monkeypatch):
    def graded(count):
        monkeypatch.setattr(step2, "_drive", _stand_in_2_1([], count))
        monkeypatch.setattr(step2, "hidden_random", lambda exercise: None)
        return step2.check_selected_joints(type("Selected", (), {}))

    assert graded(lambda rate: round(rate * step2.DURATION)).passed  # exactly 100 at 50 Hz, 20 at 10 Hz
    short = graded(lambda rate: round(rate * step2.DURATION) - 1)
    assert not short.passed and short.case == "Selected with joints='TURRET_P,TURRET_Y', rate=50.0"
    assert "published 99 messages in 2.0 s, expected at least 100." in short.message
    assert "Hint: keep publishing through RttJointStatePublisher.control()." in short.message
    assert not graded(lambda rate: round(rate * step2.DURATION) // 2).passed  # half the rate


@pytest.mark.parametrize("publishers", [0, 2])
def test_2_1_a_run_with_other_than_one_joint_state_publisher_is_told_so(monkeypatch, publishers):
    drive = _stand_in_2_1([])

    def drive_with(*args, **kwargs):
        node, probe, app = drive(*args, **kwargs)
        [publisher] = node.published("/Tank/joint_state")
        return SimpleNamespace(published=lambda topic: [publisher] * publishers), probe, app

    monkeypatch.setattr(step2, "_drive", drive_with)
    monkeypatch.setattr(step2, "hidden_random", lambda exercise: None)
    result = step2.check_selected_joints(type("Selected", (), {}))
    assert str(result) == (
        "✗ Exercise 2.1, publish chosen joints: Selected with joints='TURRET_P,TURRET_Y', rate=50.0: "
        f"with joints='TURRET_P,TURRET_Y' the controller made {publishers} publishers of /Tank/joint_state, "
        "expected 1. Hint: let RttJointStatePublisher.configure create it: call super().configure(config) and "
        "check what it returns."
    )


def _graded_2_1(monkeypatch, hidden=False, **stand_in):
    monkeypatch.setattr(step2, "_drive", _stand_in_2_1([], **stand_in))
    monkeypatch.setattr(step2, "hidden_random", lambda exercise: random.Random(f"test/{exercise}") if hidden else None)
    return str(step2.check_selected_joints(type("Selected", (), {})))


FIRST_CASE = "✗ Exercise 2.1, publish chosen joints: Selected with joints='TURRET_P,TURRET_Y', rate=50.0"
ORDER_HINT = "publish the joints in the order the parameter names them."  # the first case's


def test_2_1_names_out_of_order_are_told_with_the_cases_hint(monkeypatch):
    def reverse(msg):
        msg.name.reverse()

    assert _graded_2_1(monkeypatch, edit=reverse) == (
        f"{FIRST_CASE} published name=['TURRET_Y', 'TURRET_P'], expected ['TURRET_P', 'TURRET_Y']. Hint: {ORDER_HINT}"
    )


def test_2_1_a_stamp_that_is_no_step_of_the_run_is_told(monkeypatch):
    told = _graded_2_1(monkeypatch, at=lambda seconds, state: None if seconds > 0.5 else state)
    assert told == f"{FIRST_CASE}: a message stamped 0.520 s, not a step of the run. Hint: {ORDER_HINT}"


def test_2_1_a_position_or_velocity_within_1e_9_passes_and_a_hair_more_does_not(monkeypatch):
    def off_by(rad):
        def edit(msg):
            if "TURRET_Y" in msg.name:
                msg.position[msg.name.index("TURRET_Y")] = rad  # the state's TURRET_Y is 0

        return edit

    assert _graded_2_1(monkeypatch, edit=off_by(1e-9)).startswith("✓")
    assert "TURRET_Y was published as 0.000000 rad" in _graded_2_1(monkeypatch, edit=off_by(1.0000001e-9))

    def velocity_off_by(rad_s):
        def edit(msg):
            if "TURRET_Y" in msg.name:
                msg.velocity[msg.name.index("TURRET_Y")] = rad_s  # the state's TURRET_Y velocity is 0

        return edit

    assert _graded_2_1(monkeypatch, edit=velocity_off_by(1e-9)).startswith("✓")
    assert "TURRET_Y's velocity was published" in _graded_2_1(monkeypatch, edit=velocity_off_by(1.0000001e-9))


def test_2_1_arrays_of_other_lengths_than_the_names_are_told(monkeypatch):
    def shorten(msg):
        msg.velocity = msg.velocity[:1]

    assert _graded_2_1(monkeypatch, edit=shorten) == (
        f"{FIRST_CASE}: name, position, velocity and effort have lengths 2, 2, 1, 2. "
        "Hint: a JointState's arrays must all be as long as its name list."
    )


@pytest.mark.parametrize(
    "field, unit, value, got",
    [("velocity", "rad/s", "0.000000", "-2.500000"), ("effort", "N m", "3.000000", "4.000000")],
)
def test_2_1_a_velocity_or_effort_not_the_joints_own_is_told(monkeypatch, field, unit, value, got):
    def swap(msg):
        values = getattr(msg, field)
        values.reverse()  # TURRET_P's value given to TURRET_Y and back

    assert _graded_2_1(monkeypatch, edit=swap) == (
        f"{FIRST_CASE}: at t = 0.000 s TURRET_P's {field} was published as {value} {unit}, but the simulation "
        f"had {got} {unit}. Hint: a joint's {field} comes from its own dof address (qvel, qfrc_actuator), in the "
        "order of the names you publish: not from its qpos address."
    )


def test_2_1_a_name_the_tank_lacks_accepted_is_told(monkeypatch):
    assert _graded_2_1(monkeypatch, refuse=False) == (
        "✗ Exercise 2.1, publish chosen joints: Selected with joints='GUN' was accepted, but the tank has no joint "
        "'GUN'. Hint: configure() should return False when a name is not in config.body.joint_names (and log why "
        "with config.log.error)."
    )


def test_2_1_a_hidden_refusal_without_an_error_logged_fails_and_the_visible_ones_pass(monkeypatch):
    told = _graded_2_1(monkeypatch, hidden=True, log=False)
    assert told.startswith(
        "✗ Exercise 2.1, publish chosen joints: a hidden case failed: a name the tank lacks (a joint of the tank in "
        "the wrong case): configure logs an error, returns False."
    ), told
    assert _graded_2_1(monkeypatch, hidden=True).startswith("✓"), "the same, logged"


def test_2_1_a_name_the_tank_lacks_after_one_it_has_is_named(monkeypatch):
    first_only = _graded_2_1(monkeypatch, refuse=lambda names: names[0] not in step2.TANK)  # only the first checked
    assert first_only == (
        "✗ Exercise 2.1, publish chosen joints: Selected with joints='TURRET_Y,GUN' was accepted, but the tank has "
        "no joint 'GUN'. Hint: configure() should return False when a name is not in config.body.joint_names (and "
        "log why with config.log.error)."
    )


def test_2_1_a_refusal_left_as_a_stub_is_not_done_yet(monkeypatch):
    told = _graded_2_1(monkeypatch, log="not done")
    assert told.startswith("✗ Exercise 2.1, publish chosen joints: not done yet: Selected with joints='GUN' raised"), (
        told
    )


# ---- 4.2's rule, as the check models it (_compare_reports), at its edges and in its words ----------------------


def _imu_at(*readings):
    """Imu messages ``(t in ms, x, y)``, frame "imu"."""
    return [
        SimpleNamespace(
            linear_acceleration=SimpleNamespace(x=x, y=y, z=9.8),
            header=SimpleNamespace(
                stamp=SimpleNamespace(sec=ms // 1000, nanosec=ms % 1000 * 1_000_000), frame_id="imu"
            ),
        )
        for ms, x, y in readings
    ]


def _reports_of(imu, indices, **changed):
    """The reports a right answer publishes for ``imu[k]`` at each of ``indices``, with the fields ``changed``."""
    out = []
    for k in indices:
        a, header = imu[k].linear_acceleration, imu[k].header
        stamp = SimpleNamespace(sec=header.stamp.sec, nanosec=header.stamp.nanosec)
        report = SimpleNamespace(
            header=SimpleNamespace(stamp=stamp, frame_id=header.frame_id), vector=SimpleNamespace(x=a.x, y=a.y, z=0.0)
        )
        for name, value in changed.items():
            if name == "frame_id":
                report.header.frame_id = value
            elif name == "nanosec":
                report.header.stamp.nanosec += value
            else:
                setattr(report.vector, name, value)
        out.append(report)
    return out


# 0.5 s apart at 50 ms: above 20 at 1.0 s (just), 1.2 s (inside the holdoff) and 1.5 s (exactly a holdoff after)
WALL = _imu_at((950, 3.0, 0.0), (1000, 20.0, 1e-6), (1200, 30.0, 0.0), (1250, 20.0, 0.0), (1500, 0.0, 25.0))


def test_4_2_above_threshold_strictly_then_again_a_whole_holdoff_after_the_last_report():
    assert step4._compare_reports("c", {}, WALL, _reports_of(WALL, [1, 4])) == [1, 4]
    # 20.0 exactly (at 1.25 s) is not above; 1.5 s is exactly 0.5 s after 1.0 s: reported
    assert step4._compare_reports("c", {"threshold": 2.0, "holdoff": 0.25}, WALL, _reports_of(WALL, [0, 2, 4])) == [
        0,
        2,
        4,
    ]


def test_4_2_a_run_without_a_collision_is_the_checks_own_fault_said_as_such():
    from tutorial.exercises.grader import CaseFailed

    with pytest.raises(CaseFailed) as caught:
        step4._compare_reports("c", {}, _imu_at((100, 1.0, 1.0)), [])
    assert (caught.value.what, caught.value.hint) == (
        "c: the Imu messages show no collision at all; the tank should have hit the wall at about 2.05 s.",
        "keep RttImuStatePublisher's behaviour: call super().publish().",
    )


@pytest.mark.parametrize(
    "indices, changed, what, hint",
    [
        (
            [1],
            {},
            "c made 1 report, stamped t = [1.0] s; expected 2 reports, at t = [1.0, 1.5] s.",
            "report when hypot(x, y) of the mean is above threshold, and then not again until holdoff s of "
            "simulated time have passed since that report (a period above threshold that is not reported does not "
            "start it again).",
        ),
        (  # a stamp off the Imu's, told to the millisecond, as the expected ones are
            [1],
            {"nanosec": 300_000},
            "c made 1 report, stamped t = [1.0] s; expected 2 reports, at t = [1.0, 1.5] s.",
            None,
        ),
        (
            [1, 2, 4],
            {},
            "c made 3 reports, stamped t = [1.0, 1.2, 1.5] s; expected 2 reports, at t = [1.0, 1.5] s.",
            None,
        ),
        (
            [1, 4],
            {"nanosec": 1},
            "c: the report of the Imu message of t = 1.0 s is stamped sec=1, nanosec=1; expected sec=1, nanosec=0.",
            "copy the Imu message's header (stamp and frame_id).",
        ),
        (
            [1, 4],
            {"frame_id": "Tank"},
            "c: the report at t = 1.0 s has frame_id 'Tank', expected 'imu'.",
            "the vector is in the IMU's frame: use the Imu message's frame_id.",
        ),
        (
            [1, 4],
            {"z": 9.8},
            "c: the report at t = 1.0 s carries [20.0, 0.0, 9.8], expected [20.0, 0.0, 0.0].",
            "the vector is the mean acceleration's horizontal part: (x, y, 0).",
        ),
    ],
)
def test_4_2_each_way_a_report_differs_is_told_in_its_own_words(indices, changed, what, hint):
    from tutorial.exercises.grader import CaseFailed

    with pytest.raises(CaseFailed) as caught:
        step4._compare_reports("c", {}, WALL, _reports_of(WALL, indices, **changed))
    assert caught.value.what == what
    assert hint is None or caught.value.hint == hint


def test_4_2_a_reports_vector_within_1e_9_passes_and_a_hair_more_does_not():
    from tutorial.exercises.grader import CaseFailed

    assert step4._compare_reports("c", {}, WALL, _reports_of(WALL, [1, 4], z=1e-9)) == [1, 4]
    with pytest.raises(CaseFailed, match="carries"):
        step4._compare_reports("c", {}, WALL, _reports_of(WALL, [1, 4], z=1.0000001e-9))


# ---- 4.2's check around its runs: its defaults case and a run that publishes no Imu message ------------------


@pytest.mark.parametrize(
    "parameters, got",
    [
        (None, "{'threshold': None, 'holdoff': None}"),  # no PARAMETERS at all: not a RttImuStatePublisher
        ({"rate": (float, 20.0, "")}, "{'threshold': None, 'holdoff': None}"),  # neither declared
        ({"threshold": (float, 20.0, ""), "holdoff": (float, 0.25, "")}, "{'threshold': 20.0, 'holdoff': 0.25}"),
    ],
)
def test_4_2_defaults_not_declared_are_told_as_none_before_any_run(monkeypatch, parameters, got):
    def no_run(*args, **kwargs):
        raise AssertionError("the defaults are judged before any run")

    monkeypatch.setattr(step4, "_drive", no_run)
    cls = type("Reporter", (), {} if parameters is None else {"PARAMETERS": parameters})
    assert str(step4.check_collision_reporter(cls)) == (
        f"✗ Exercise 4.2, report collisions: Reporter.PARAMETERS: its defaults are {got}, expected threshold 20.0 "
        'and holdoff 0.5. Hint: declare them: PARAMETERS = {**RttImuStatePublisher.PARAMETERS, "threshold": '
        '(float, 20.0, ...), "holdoff": (float, 0.5, ...)}.'
    )


def test_4_2_a_run_without_an_imu_publisher_is_named_by_its_case(monkeypatch):
    runs = []

    def drive(name, cls, parameters, script="wall", duration=step4.DURATION):
        runs.append(parameters)
        return SimpleNamespace(published=lambda topic=None: []), None

    monkeypatch.setattr(step4, "_drive", drive)
    monkeypatch.setattr(step4, "hidden_random", lambda exercise: None)
    cls = type("Reporter", (), {"PARAMETERS": {"threshold": (float, 20.0, ""), "holdoff": (float, 0.5, "")}})
    result = str(step4.check_collision_reporter(cls))
    call = f"Reporter with default parameters, the wall script for {step4.DURATION} s"
    assert result == (
        f"✗ Exercise 4.2, report collisions: {call} made 0 publishers of /Tank/imu (its topics: []), expected 1. "
        "Hint: keep publishing the Imu: call super().configure(config) and super().publish() (or super().control())."
    )
    assert runs == [{}]
