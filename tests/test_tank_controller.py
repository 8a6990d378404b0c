"""Step 1 controller: the math, the Joy convention, and bad input."""

import math
from types import SimpleNamespace

import mujoco
import pytest

from tutorial.controllers import tank_controller as tc
from tutorial.core.body import Body
from tutorial.core.controller import ControllerIO
from tutorial.core.world import ModelEntry, build_world

from conftest import MODEL


def axes(lh=0.0, lv=0.0, rh=0.0, rv=0.0):
    return [lh, lv, rh, rv, 0.0, 0.0, 0.0, 0.0]


def test_left_stick_up_drives_both_tracks_forward():
    assert tc.track_velocities(axes(lv=1.0)) == (2.0, 2.0)


def test_left_stick_left_turns_left():
    left, right = tc.track_velocities(axes(lh=1.0))
    assert left == -1.0 and right == 1.0  # right track faster: the tank turns left (counter-clockwise)


def test_dead_zones_are_the_originals():
    assert tc.track_velocities(axes(lv=0.19, lh=-0.19)) == (0.0, 0.0)
    assert tc.track_velocities(axes(lv=0.2))[0] == pytest.approx(0.4)
    assert tc.turret_rates(axes(rh=0.149, rv=-0.149)) == (0.0, 0.0)
    assert tc.turret_rates(axes(rh=-0.15))[0] == pytest.approx(0.3)


def test_turret_rate_is_0_002_rad_per_ms_at_full_stick():
    yaw, pitch = tc.turret_rates(axes(rh=-1.0, rv=1.0))
    assert yaw * 0.001 == pytest.approx(0.002)  # stick right: TURRET_Y reference grows (clockwise from above)
    assert pitch * 0.001 == pytest.approx(-0.002)  # stick pushed forward: barrel goes down, as in the original


# Written by hand from the original's formulas (ROS's joy convention: stick up and stick left are +1).
# (left stick H, left stick V) -> (left track, right track), m/s.
TRACK_TABLE = [
    ((0.0, 1.0), (2.0, 2.0)),  # forward
    ((0.0, -1.0), (-2.0, -2.0)),  # backward
    ((1.0, 0.0), (-1.0, 1.0)),  # turn left on the spot
    ((-1.0, 0.0), (1.0, -1.0)),  # turn right on the spot
    ((0.5, 0.5), (0.5, 1.5)),  # forward and left
    ((-0.5, 0.5), (1.5, 0.5)),  # forward and right
    ((0.5, -0.5), (-1.5, -0.5)),  # backward, stick left
    ((-0.5, -0.5), (-0.5, -1.5)),  # backward, stick right
    ((0.0, 0.2), (0.4, 0.4)),  # at the dead zone's edge: taken as it is
    ((0.0, -0.2), (-0.4, -0.4)),
    ((0.2, 0.0), (-0.2, 0.2)),
    ((0.3, 0.19), (-0.3, 0.3)),  # forward inside the dead zone, turning outside it
    ((0.19, -0.19), (0.0, 0.0)),
]
# (right stick H, right stick V) -> (TURRET_Y rate, TURRET_P rate), rad/s.
TURRET_TABLE = [
    ((-1.0, 0.0), (2.0, 0.0)),  # stick right: clockwise from above
    ((1.0, 0.0), (-2.0, 0.0)),
    ((0.0, 1.0), (0.0, -2.0)),  # pushed forward: the barrel goes down
    ((0.0, -1.0), (0.0, 2.0)),
    ((0.15, -0.15), (-0.3, 0.3)),  # at the dead zone's edge
    ((-0.5, 0.5), (1.0, -1.0)),
    ((0.149, -0.149), (0.0, 0.0)),
]


@pytest.mark.parametrize(("stick", "expected"), TRACK_TABLE)
def test_track_velocities_by_a_table_written_by_hand(stick, expected):
    got = tc.track_velocities(axes(lh=stick[0], lv=stick[1]))
    assert got == pytest.approx(expected, abs=1e-12)
    assert all(math.copysign(1.0, v) == 1.0 for v in got if v == 0.0)  # a stopped track prints 0.0, not -0.0


@pytest.mark.parametrize(("stick", "expected"), TURRET_TABLE)
def test_turret_rates_by_a_table_written_by_hand(stick, expected):
    got = tc.turret_rates(axes(rh=stick[0], rv=stick[1]))
    assert got == pytest.approx(expected, abs=1e-12)
    assert all(math.copysign(1.0, v) == 1.0 for v in got if v == 0.0)  # a still turret rate is 0.0, not -0.0


def test_pd_torque_uses_the_original_gains():
    assert tc.pd_torque(0.1, 0.0, 0.0, 0.0) == pytest.approx(20.0)
    assert tc.pd_torque(0.0, 0.0, 0.0, 0.2) == pytest.approx(-10.0)


@pytest.mark.parametrize("bad", [[], [0.5], [math.nan] * 8, [math.inf, -math.inf, 1e300, -1e300], [0.0] * 100])
def test_bad_axes_never_raise_and_never_give_non_finite_commands(bad):
    left, right = tc.track_velocities(bad)
    yaw, pitch = tc.turret_rates(bad)
    assert all(math.isfinite(v) and abs(v) <= 3.0 for v in (left, right))
    assert all(math.isfinite(v) and abs(v) <= tc.TURRET_RATE for v in (yaw, pitch))


def make_controller(joy_timeout: float = 0.0):
    """The Step 1 controller on the tank in its room, unconfigured (no ROS), initialized; the safe stop off by
    default."""
    model = build_world([ModelEntry("Room", MODEL / "room.xml"), ModelEntry("Tank", MODEL / "tank.xml")])
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    controller = tc.RttTankController()
    controller.joy_timeout = joy_timeout
    io = ControllerIO(body=Body(model, data, "Tank"), time_step=model.opt.timestep, node=None, data=data)
    assert controller.initialize(io)
    return controller, model, data


def joy(axes_, buttons=(0,) * 8):
    return SimpleNamespace(axes=list(axes_), buttons=list(buttons))


def test_malformed_joy_is_counted_and_simulation_stays_finite():
    controller, model, data = make_controller()
    for msg in (joy([math.nan] * 8), joy([1.0]), joy([], []), joy(axes(lv=1.0), [1])):
        controller.on_joy(msg)
        for _ in range(50):
            assert controller.control()
            mujoco.mj_step(model, data)
    assert controller.summary() == {"joy_received": 4, "joy_malformed": 4, "joy_timeouts": 0}
    assert all(math.isfinite(v) for v in data.qpos)


def test_full_stick_moves_the_tank_forward_and_the_turret():
    controller, model, data = make_controller()
    controller.on_joy(joy(axes(lv=0.5, rh=-0.5)))
    x0 = data.qpos[0]
    for _ in range(1000):
        controller.control()
        mujoco.mj_step(model, data)
    body = Body(model, data, "Tank")
    assert data.qpos[0] - x0 > 0.5
    assert body.joint("TURRET_Y").q == pytest.approx(1.0, abs=0.1)  # 1 rad/s for 1 s


def test_turret_reference_stays_inside_the_joint_range():
    controller, model, data = make_controller()
    controller.on_joy(joy(axes(rv=-1.0)))  # pull back: barrel up, held for 2 s
    for _ in range(2000):
        controller.control()
        mujoco.mj_step(model, data)
    pitch = Body(model, data, "Tank").joint("TURRET_P")
    assert controller.q_ref[1] == pytest.approx(pitch.info.upper)
    assert pitch.q == pytest.approx(pitch.info.upper, abs=0.02)


def run(controller, model, data, steps: int, feed=None) -> None:
    for k in range(steps):
        if feed is not None:
            feed(k)
        controller.control()
        mujoco.mj_step(model, data)


def test_the_tank_stops_when_the_joystick_goes_silent():
    controller, model, data = make_controller(joy_timeout=0.5)
    # a joystick repeating "forward" at 20 Hz for 1 s, then silent (its node died)
    run(controller, model, data, 1000, lambda k: k % 50 == 0 and controller.on_joy(joy(axes(lv=0.5))))
    assert controller.timeouts == 0 and controller.tracks[0].dq_target == pytest.approx(1.0)
    x_silent = data.qpos[0]
    run(controller, model, data, 440)  # 0.489 s without a Joy (the last came at step 950): not yet
    assert controller.timeouts == 0 and not controller.stopped
    run(controller, model, data, 100)
    assert controller.timeouts == 1 and controller.stopped
    assert controller.tracks[0].dq_target == 0.0 and controller.tracks[1].dq_target == 0.0
    assert controller.rates == (0.0, 0.0)
    x_stopped = data.qpos[0]
    run(controller, model, data, 1500)  # 1.5 s more of silence: one timeout, the tank stands
    assert controller.timeouts == 1
    assert abs(data.qpos[0] - x_stopped) < 0.1 and data.qpos[0] > x_silent
    assert abs(data.qvel[0]) < 0.01
    controller.on_joy(joy(axes(lv=0.5)))  # the joystick is back
    run(controller, model, data, 10)
    assert not controller.stopped and controller.tracks[0].dq_target == pytest.approx(1.0)


def test_no_timeout_before_the_first_joy_and_none_when_disabled():
    controller, model, data = make_controller(joy_timeout=0.5)
    run(controller, model, data, 2000)  # no joystick at all: the tank was never told to move
    assert controller.timeouts == 0
    controller, model, data = make_controller(joy_timeout=0.0)
    controller.on_joy(joy(axes(lv=0.5)))
    run(controller, model, data, 2000)
    assert controller.timeouts == 0 and controller.tracks[0].dq_target == pytest.approx(1.0)


def test_the_safe_stop_and_the_resume_are_reported_once_each_with_where_the_tank_is():
    """report() posts one status line per event to the main thread, each under a key of its own."""
    controller, model, data = make_controller(joy_timeout=0.5)
    posted = []

    def call_later(func, record, key=None):  # the main thread's queue: what was posted, and with which key
        posted.append((func, record, key))

    output = object()
    node = SimpleNamespace(get_fully_qualified_name=lambda: "/rtt")
    controller.config = SimpleNamespace(call_later=call_later, output=output, node=node)
    controller.on_joy(joy(axes(lv=0.5)))
    run(controller, model, data, 600)  # 0.6 s: the joystick went silent after its one Joy
    controller.on_joy(joy(axes(lv=0.5)))
    run(controller, model, data, 5)
    assert [r["event"] for _, r, _ in posted] == ["joy_timeout", "joy_resumed"]
    assert all(func is output for func, _, _ in posted) and posted[0][2] is not posted[1][2] is not None
    stop, resume = posted[0][1], posted[1][1]
    assert stop["node"] == "/rtt" and stop["t"] == pytest.approx(0.5, abs=0.002)
    assert stop["line"] == "[/rtt] no /joy for 0.50 s: tracks stopped, turret held"
    assert resume["line"] == "[/rtt] /joy is back: driving again" and resume["t"] == pytest.approx(0.6, abs=0.002)
    root = Body(model, data, "Tank").root_pose()[0]
    assert resume["root_position"] == pytest.approx([round(float(v), 4) for v in root], abs=0.01)
    assert stop["root_position"][0] != 0.0 and set(stop) == {"event", "node", "t", "root_position", "line"}


class StandInNode:
    """Keeps the subscriptions made and destroyed."""

    def __init__(self):
        self.subscriptions, self.destroyed = [], []

    def get_fully_qualified_name(self):
        return "/rtt"

    def create_subscription(self, msg_type, topic, callback, qos):
        sub = SimpleNamespace(msg_type=msg_type, topic=topic, callback=callback, qos=qos)
        self.subscriptions.append(sub)
        return sub

    def destroy_subscription(self, sub):
        self.destroyed.append(sub)


def configure(parameters, log=None):
    import logging

    from tutorial.core.controller import ControllerConfig

    model = build_world([ModelEntry("Tank", MODEL / "tank.xml")])
    node = StandInNode()
    config = ControllerConfig(
        name="RttTankController", body=Body(model, mujoco.MjData(model), "Tank"), node=node, parameters=parameters,
        log=log or logging.getLogger("test.tank"),
    )  # fmt: skip
    controller = tc.RttTankController()
    return controller, controller.configure(config), node


def test_configure_subscribes_joy_and_unconfigure_drops_it_once():
    from sensor_msgs.msg import Joy

    from tutorial.interfaces import joy as joy_interface

    controller, ok, node = configure({"joy_timeout": 0.0})
    assert ok and controller.joy_timeout == 0.0  # 0 is allowed: the safe stop off
    (sub,) = node.subscriptions
    assert (sub.msg_type, sub.topic, sub.callback, sub.qos) == (
        Joy, "/joy", controller.on_joy, joy_interface.joy_subscriber_qos()
    )  # fmt: skip
    controller.unconfigure()
    controller.unconfigure()
    assert node.destroyed == [sub]
    controller, ok, node = configure({})
    assert ok and controller.joy_timeout == 0.5  # the default


def test_a_negative_joy_timeout_is_refused_saying_why(caplog):
    import logging

    with caplog.at_level(logging.ERROR, logger="test.tank"):
        controller, ok, node = configure({"joy_timeout": -0.1})
    assert ok is False and node.subscriptions == []
    assert caplog.messages == ["joy_timeout must be >= 0 s, got -0.1"]


def test_a_controller_never_configured_unconfigures_quietly_and_has_the_default_safe_stop():
    controller = tc.RttTankController()
    controller.unconfigure()
    assert controller.take_input() == (0, (), ())
    assert controller.summary() == {"joy_received": 0, "joy_malformed": 0, "joy_timeouts": 0}
    model = build_world([ModelEntry("Tank", MODEL / "tank.xml")])
    data = mujoco.MjData(model)
    assert controller.initialize(ControllerIO(body=Body(model, data, "Tank"), time_step=0.001, node=None, data=data))
    controller.on_joy(joy(axes(lv=0.5)))
    for _ in range(600):
        controller.control()
    assert controller.stopped and controller.summary()["joy_timeouts"] == 1  # the default 0.5 s


def test_before_any_joy_the_turret_reference_stays_where_it_was():
    controller, model, data = make_controller()
    before = list(controller.q_ref)
    run(controller, model, data, 200)
    assert controller.q_ref == before and controller.rates == (0.0, 0.0)


def test_the_safe_stop_trips_at_the_timeout_itself_and_every_silence_is_counted():
    model = build_world([ModelEntry("Tank", MODEL / "tank.xml")])
    data = mujoco.MjData(model)
    controller = tc.RttTankController()
    controller.joy_timeout = 0.5
    assert controller.initialize(ControllerIO(body=Body(model, data, "Tank"), time_step=0.25, node=None, data=data))
    for silence in (1, 2):
        controller.on_joy(joy(axes(lv=0.5)))
        assert controller.control() and not controller.stopped  # the new Joy
        assert controller.control() and not controller.stopped  # 0.25 s silent
        assert controller.control() and controller.stopped  # 0.5 s silent: exactly the timeout
        assert controller.summary()["joy_timeouts"] == silence


def test_well_formed_joys_are_not_counted_as_malformed():
    controller, _, _ = make_controller()
    for _ in range(3):
        controller.on_joy(joy(axes(lv=0.5)))
    assert controller.summary() == {"joy_received": 3, "joy_malformed": 0, "joy_timeouts": 0}


def test_a_report_rounds_the_time_to_the_millisecond_and_the_position_to_a_tenth_of_a_millimetre():
    controller, model, data = make_controller()
    posted = []
    controller.config = SimpleNamespace(
        call_later=lambda func, record, key=None: posted.append(record), output=None,
        node=SimpleNamespace(get_fully_qualified_name=lambda: "/rtt"),
    )  # fmt: skip
    data.time = 1.23456
    data.qpos[:3] = [0.123456, -2.345678, 0.0501234]
    mujoco.mj_kinematics(model, data)
    controller.report("joy_timeout", "text")
    (record,) = posted
    assert record == {
        "event": "joy_timeout", "node": "/rtt", "t": 1.235, "root_position": [0.1235, -2.3457, 0.0501],
        "line": "[/rtt] text",
    }  # fmt: skip
