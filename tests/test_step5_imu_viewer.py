"""The Step 5 IMU viewer in this process: message by message, on a clock the test sets (notebook 05's lesson).

A stand-in node keeps the subscription; its callbacks are called as the spin
thread would, and the main thread's posted work runs on a real
:class:`MainLoop` owned by the test.  The controller's ``clock`` is the
test's, so rates, ages and the shake's half second are exact.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import mujoco
import numpy as np
import pytest

from tutorial.controllers import imu_state_subscriber as sub
from tutorial.core.body import Body
from tutorial.core.call_later import MainLoop
from tutorial.core.controller import ControllerConfig
from tutorial.core.world import ModelEntry, build_world

from conftest import MODEL
from conftest import ViewerNode as Node

pytestmark = pytest.mark.unit


class Clock:
    def __init__(self, now=100.0):
        self.now = now

    def __call__(self):
        return self.now


def imu(accel=(0.0, 0.0, 9.8), gyro=(0.0, 0.0, 0.0), frame_id="CHASSIS"):
    from sensor_msgs.msg import Imu

    msg = Imu()
    msg.header.frame_id = frame_id
    a, w = msg.linear_acceleration, msg.angular_velocity
    a.x, a.y, a.z = accel
    w.x, w.y, w.z = gyro
    return msg


def make_viewer(model_path=MODEL / "tank.xml"):
    """A configured IMU viewer of the tank on the test's clock; its node, loop, records and every call_every."""
    model = build_world([ModelEntry("Tank", model_path)])
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    body = Body(model, data, "Tank")
    loop, node, out, timers = MainLoop(), Node(), [], []
    config = ControllerConfig(
        name="RttImuStateSubscriber", body=body, node=node, parameters={}, call_later=loop.call_later,
        call_every=lambda period, func: timers.append((period, func)), output=out.append,
    )  # fmt: skip
    v = sub.RttImuStateSubscriber()
    v.clock = Clock()
    assert v.configure(config)
    return SimpleNamespace(v=v, loop=loop, node=node, out=out, timers=timers, body=body, data=data, model=model)


@pytest.fixture
def viewer():
    return make_viewer()


def events(out, kind):
    return [r for r in out if r.get("event") == kind]


def test_it_subscribes_the_imu_topic_and_sets_its_two_timers(viewer):
    from sensor_msgs.msg import Imu

    from tutorial.interfaces.imu import imu_qos

    (s,) = viewer.node.subscriptions
    assert (s.msg_type, s.topic, s.qos) == (Imu, "/Tank/imu", imu_qos())
    assert s.callback == viewer.v.on_imu and s.events.matched == viewer.v.on_matched
    assert viewer.timers == [(0.02, viewer.v.shake_tick), (1.0, viewer.v.report_status)]
    assert viewer.v.frame_id == "CHASSIS"


def test_the_callback_only_counts_and_hands_over_and_the_newest_message_wins(viewer):
    v = viewer.v
    (s,) = viewer.node.subscriptions
    v.clock.now = 100.25
    s.callback(imu(accel=(1.0, 0.0, 9.8)))
    v.clock.now = 100.5
    s.callback(imu(accel=(0.0, 2.0, 9.8)))  # before the main thread got to the first: it replaces it
    assert v.summary()["received"] == 2 and v.accepted == 0 and v.accel is None  # nothing shown yet
    assert viewer.loop.process_pending() == 1
    assert v.arrival == 100.5  # stamped with the clock when it arrived, not when it was shown
    np.testing.assert_allclose(v.accel_arrow.vector, [0.0, 0.2, 0.0], atol=1e-12)
    s = v.summary()
    assert (s["received"], s["accepted"], s["superseded"], s["rejected"]) == (2, 1, 1, {})


def test_a_publisher_that_comes_and_goes_is_reported_on_the_main_thread(viewer):
    (s,) = viewer.node.subscriptions
    s.events.matched(SimpleNamespace(current_count=2))
    assert viewer.out == []
    viewer.loop.process_pending()
    assert viewer.out == [{"event": "publishers", "node": "/rtt_viewer", "topic": "/Tank/imu", "count": 2}]


def test_the_status_line_says_the_rate_and_age_on_the_viewers_clock(viewer):
    v = viewer.v
    (s,) = viewer.node.subscriptions
    v.clock.now = 101.0
    v.report_status()  # nothing yet
    first = viewer.out[-1]
    assert (first["rate_hz"], first["age_ms"], first["received"]) == (0.0, None, 0)
    for t in (101.25, 101.5, 102.5):
        v.clock.now = t
        s.callback(imu(accel=(3.0, 4.0, 9.8)))
        viewer.loop.process_pending()
    v.clock.now = 103.0
    v.report_status()
    record = viewer.out[-1]
    assert record == {"event": "imu_status", "node": "/rtt_viewer", "rate_hz": 1.5, "age_ms": 500.0, **v.summary()}
    v.clock.now = 103.5
    v.report_status()
    assert (viewer.out[-1]["rate_hz"], viewer.out[-1]["age_ms"]) == (0.0, 1000.0)  # none since the last line


def test_a_collision_is_said_once_shakes_on_the_timer_and_ends_where_it_began(viewer):
    v, data = viewer.v, viewer.data
    root = sub.root_position_address(viewer.model, viewer.body.root_id)
    home = data.qpos[root : root + 3].copy()
    imu_home = data.site_xpos[v.site].copy()
    v.clock.now = 200.0
    assert v.update_imu(imu(accel=(-30.0, 4.0, 9.8)), 200.0) is None
    assert events(viewer.out, "shake") == [
        {
            "event": "shake",
            "node": "/rtt_viewer",
            "body": "Tank",
            "horizontal_acceleration": round(math.hypot(30, 4), 3),
        }
    ]
    moved = []
    for k in range(1, 15):  # 0.28 s of 20 ms ticks
        v.clock.now = 200.0 + 0.02 * k
        v.shake_tick()
        moved.append(data.qpos[root : root + 3] - home)
        np.testing.assert_allclose(v.accel_arrow.origin, data.site_xpos[v.site])  # the arrows move with the IMU
    assert np.abs(moved).max() <= sub.SHAKE_AMPLITUDE and np.abs(moved).min(axis=1).max() > 0
    assert not np.allclose(data.site_xpos[v.site], imu_home)  # the kinematics follow the shaken root
    v.update_imu(imu(accel=(25.0, 0.0, 9.8)), v.clock.now)  # another hit while shaking: 0.5 s more, not said again
    assert len(events(viewer.out, "shake")) == 1
    ends_at = v.clock.now + 0.5
    while v.shake.shaking:
        v.clock.now = round(v.clock.now + 0.02, 9)
        v.shake_tick()
        assert v.clock.now <= ends_at + 1e-9
    assert v.clock.now == pytest.approx(ends_at)
    assert data.qpos[root : root + 3].tolist() == home.tolist()
    np.testing.assert_array_equal(data.site_xpos[v.site], imu_home)
    (end,) = events(viewer.out, "shake_end")
    assert end == {"event": "shake_end", "node": "/rtt_viewer", "body": "Tank", "position": home.tolist()}
    s = v.summary()
    assert (s["shakes"], s["hits"], s["shaking"]) == (1, 2, False)
    assert s["max_shake_offset"] == round(v.shake.max_offset, 6) and 0 < s["max_shake_offset"] <= 0.02
    v.shake_tick()  # not shaking: the root stays
    assert data.qpos[root : root + 3].tolist() == home.tolist()


def test_unconfigure_mid_shake_puts_the_model_back_and_drops_the_subscription(viewer):
    v, data = viewer.v, viewer.data
    root = sub.root_position_address(viewer.model, viewer.body.root_id)
    home = data.qpos[root : root + 3].copy()
    imu_home = data.site_xpos[v.site].copy()
    v.update_imu(imu(accel=(0.0, 21.0, 9.8)), v.clock.now)
    v.clock.now += 0.02
    v.shake_tick()
    assert not np.array_equal(data.qpos[root : root + 3], home)
    v.unconfigure()
    assert data.qpos[root : root + 3].tolist() == home.tolist()
    np.testing.assert_array_equal(data.site_xpos[v.site], imu_home)
    assert viewer.node.destroyed == viewer.node.subscriptions


def test_unconfigure_when_not_shaking_leaves_the_model_alone(viewer):
    v, data = viewer.v, viewer.data
    before = data.qpos.copy()
    v.unconfigure()
    np.testing.assert_array_equal(data.qpos, before)
    assert viewer.node.destroyed == viewer.node.subscriptions


def test_a_horizontal_acceleration_of_exactly_20_is_no_hit(viewer):
    v = viewer.v
    v.update_imu(imu(accel=(12.0, 16.0, 9.8)), v.clock.now)  # hypot = 20.0
    assert not v.shake.shaking and events(viewer.out, "shake") == []
    v.update_imu(imu(accel=(12.0, 16.001, 9.8)), v.clock.now)
    assert v.shake.shaking


def test_a_body_fixed_to_the_world_is_never_shaken_but_shows_its_arrows(tmp_path):
    xml = (MODEL / "tank.xml").read_text().replace('<freejoint name="CHASSIS"/>', "")
    (tmp_path / "tank.xml").write_text(xml)
    viewer = make_viewer(tmp_path / "tank.xml")
    v = viewer.v
    assert v.root is None
    before = viewer.data.qpos.copy()
    assert v.update_imu(imu(accel=(40.0, 0.0, 9.8)), v.clock.now) is None
    assert not v.shake.shaking and events(viewer.out, "shake") == []
    np.testing.assert_allclose(v.accel_arrow.vector, [4.0, 0.0, 0.0], atol=1e-12)
    v.clock.now += 0.02
    v.shake_tick()
    np.testing.assert_array_equal(viewer.data.qpos, before)


def test_a_body_without_an_imu_is_refused_saying_which(caplog):
    import logging

    model = build_world([ModelEntry("Crane", MODEL / "crane.xml")])
    log = logging.getLogger("test.imu_viewer")
    node = Node()
    config = ControllerConfig(name="V", body=Body(model, mujoco.MjData(model), "Crane"), node=node, log=log)
    with caplog.at_level(logging.ERROR, logger="test.imu_viewer"):
        assert sub.RttImuStateSubscriber().configure(config) is False
    assert caplog.messages == ["body Crane: the body has no accelerometer on a site"]
    assert node.subscriptions == []


def test_rejections_are_counted_by_reason_and_sorted_in_the_summary(viewer):
    v = viewer.v
    (subscription,) = viewer.node.subscriptions
    for msg in (imu(frame_id="map"), imu(accel=(math.inf, 0, 0)), imu(frame_id="odom")):
        subscription.callback(msg)
        viewer.loop.process_pending()
    s = v.summary()
    assert list(s["rejected"].items()) == [("not_finite", 1), ("wrong_frame", 2)]
    assert (s["received"], s["accepted"], s["superseded"]) == (3, 0, 0)
    assert s["arrows"] == {
        "acceleration": {"length": 0.0, "visible": False}, "angular_velocity": {"length": 0.0, "visible": False}
    }  # fmt: skip


def test_the_shake_is_seeded_random_on_each_axis_and_its_largest_offset_is_summarised(viewer):
    v, data = viewer.v, viewer.data
    root = sub.root_position_address(viewer.model, viewer.body.root_id)
    home = data.qpos[root : root + 3].copy()
    v.update_imu(imu(accel=(0.0, 30.0, 9.8)), v.clock.now)
    rng = np.random.default_rng(sub.SHAKE_SEED)  # the same shake every run
    expected = [rng.uniform(-sub.SHAKE_AMPLITUDE, sub.SHAKE_AMPLITUDE, 3) for _ in range(5)]
    offsets = []
    for k in range(5):
        v.clock.now += 0.02
        v.shake_tick()
        offsets.append(data.qpos[root : root + 3] - home)
        if k == 1:  # the largest offset so far, to the micrometre
            assert v.summary()["max_shake_offset"] == round(float(np.abs(expected[:2]).max()), 6) == 0.017843
    np.testing.assert_allclose(offsets, expected, rtol=0, atol=1e-12)
    assert all(len(set(np.round(o, 9))) == 3 for o in offsets)  # each axis its own offset


def test_an_arrow_exactly_at_its_shortest_shown_length_is_shown(viewer):
    v = viewer.v
    v.update_imu(imu(accel=(0.5, 0.0, 9.8), gyro=(0.0, 0.024999999999999998, 0.0)), v.clock.now)
    assert v.accel_arrow.length == 0.05 and v.gyro_arrow.length == 0.01  # exactly, in floating point
    assert v.accel_arrow.visible and v.gyro_arrow.visible


def test_the_status_rate_and_age_are_rounded_to_a_tenth_over_any_interval(viewer):
    v = viewer.v
    (s,) = viewer.node.subscriptions
    v.clock.now = 100.25
    s.callback(imu())
    viewer.loop.process_pending()
    v.clock.now = 100.5  # half a second after the configure: one message
    v.report_status()
    assert (viewer.out[-1]["rate_hz"], viewer.out[-1]["age_ms"]) == (2.0, 250.0)
    v.clock.now = 103.50037  # three seconds more, none: the newest is 3.25037 s old
    v.report_status()
    assert (viewer.out[-1]["rate_hz"], viewer.out[-1]["age_ms"]) == (0.0, 3250.4)
    s.callback(imu())
    viewer.loop.process_pending()
    v.clock.now = 106.50037
    v.report_status()
    assert viewer.out[-1]["rate_hz"] == 0.3  # one in three seconds


def test_only_a_free_root_has_a_position_to_shake(tmp_path):
    path = tmp_path / "arm.xml"
    path.write_text(
        '<mujoco><worldbody><body name="base"><joint name="hinge" type="hinge"/><geom size="0.1"/></body>'
        '<body name="cart"><freejoint/><geom size="0.1"/></body></worldbody></mujoco>'
    )
    model = mujoco.MjModel.from_xml_path(str(path))
    assert sub.root_position_address(model, model.body("base").id) is None  # a hinge: nothing to move
    assert sub.root_position_address(model, model.body("cart").id) == 1  # after the hinge's one number
    assert sub.root_position_address(model, 0) is None  # the world
