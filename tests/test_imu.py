"""Steps 4 and 5 in one process: the IMU mean, its message, the viewer's checks, arrows and shake."""

import math
from types import SimpleNamespace

import mujoco
import numpy as np
import pytest

from tutorial.controllers import imu_state_publisher as pub
from tutorial.controllers import imu_state_subscriber as sub
from tutorial.core.body import Body
from tutorial.core.controller import ControllerConfig, ControllerIO
from tutorial.core.world import ModelEntry, build_world
from tutorial.interfaces.imu import check_imu, find_imu, imu_qos

from conftest import MODEL, PROJECT


class RecordingPublisher:
    """Stands in for an rclpy publisher: keeps a copy of what each publish() sent."""

    def __init__(self):
        self.sent = []

    def publish(self, msg):
        self.sent.append(
            SimpleNamespace(
                stamp_ns=msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec,
                frame_id=msg.header.frame_id,
                accel=np.array([msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z]),
                gyro=np.array([msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z]),
                orientation=[msg.orientation.x, msg.orientation.y, msg.orientation.z, msg.orientation.w],
                orientation_covariance=list(msg.orientation_covariance),
                other_covariances=list(msg.angular_velocity_covariance) + list(msg.linear_acceleration_covariance),
            )
        )


class FakeNode:
    def __init__(self):
        self.publisher = RecordingPublisher()

    def create_publisher(self, msg_type, topic, qos):
        self.topic, self.qos = topic, qos
        return self.publisher

    def destroy_publisher(self, publisher):
        pass


def tank_world(*extra):
    model = build_world([ModelEntry("Room", MODEL / "room.xml"), ModelEntry("Tank", MODEL / "tank.xml"), *extra])
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return model, data


def run_publisher(seconds, rate=20.0):
    """The Step 4 controller over a resting tank for ``seconds``; also every step's sensor reading."""
    model, data = tank_world()
    body = Body(model, data, "Tank")
    node = FakeNode()
    controller = pub.RttImuStatePublisher()
    assert controller.configure(
        ControllerConfig(name="RttImuStatePublisher", body=body, node=node, parameters={"rate": rate})
    )
    assert controller.initialize(ControllerIO(body=body, time_step=model.opt.timestep, node=node, data=data))
    readings = []
    for _ in range(round(seconds / model.opt.timestep)):
        readings.append(data.sensordata[:6].copy())  # what control() reads this step
        assert controller.control()
        mujoco.mj_step(model, data)
    return controller, node, np.array(readings)


def test_the_tanks_imu_is_found_by_type_on_its_chassis():
    model, _ = tank_world()
    accel, gyro, site, frame = find_imu(model, Body(model, mujoco.MjData(model), "Tank").body_ids)
    assert (accel, gyro) == (slice(0, 3), slice(3, 6))
    assert mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_SITE, site) == "Tank/IMU"
    assert frame == "CHASSIS"  # the site has the CHASSIS's origin and axes


def test_a_body_without_imu_is_refused_with_its_name(caplog):
    model, data = tank_world(ModelEntry("Crane", MODEL / "crane.xml", position=(5, 5, 0)))
    with pytest.raises(LookupError, match="no accelerometer"):
        find_imu(model, Body(model, data, "Crane").body_ids)
    config = ControllerConfig(
        name="RttImuStatePublisher", body=Body(model, data, "Crane"), node=FakeNode(), parameters={"rate": 20.0}
    )
    assert not pub.RttImuStatePublisher().configure(config)
    assert caplog.messages == ["body Crane: the body has no accelerometer on a site"]


def test_an_imu_site_off_the_link_origin_names_its_own_frame(tmp_path):
    xml = (MODEL / "tank.xml").read_text().replace('<site name="IMU" pos="0 0 0"', '<site name="IMU" pos="0.1 0 0"')
    (tmp_path / "tank.xml").write_text(xml)
    model = build_world([ModelEntry("Tank", tmp_path / "tank.xml")])
    assert find_imu(model, Body(model, mujoco.MjData(model), "Tank").body_ids)[3] == "IMU"


def test_each_message_is_the_mean_of_every_step_of_its_period():
    controller, node, readings = run_publisher(1.0)
    sent = node.publisher.sent
    assert node.topic == "/Tank/imu"
    assert len(sent) == controller.published == 20  # steps 0, 50, ..., 950
    assert [m.stamp_ns for m in sent] == [k * 50_000_000 for k in range(20)]  # simulation time, exact
    windows = [readings[0:1]] + [readings[50 * k - 49 : 50 * k + 1] for k in range(1, 20)]
    for m, window in zip(sent, windows):
        np.testing.assert_allclose(m.accel, window[:, :3].mean(axis=0), rtol=0, atol=1e-12)
        np.testing.assert_allclose(m.gyro, window[:, 3:].mean(axis=0), rtol=0, atol=1e-12)


def test_at_rest_the_accelerometer_reads_gravity_up_and_orientation_is_unknown():
    _, node, _ = run_publisher(1.0)
    for m in node.publisher.sent[10:]:  # after 0.5 s: settled on the floor
        np.testing.assert_allclose(m.accel, [0.0, 0.0, 9.80665], atol=0.01)
        np.testing.assert_allclose(m.gyro, [0.0, 0.0, 0.0], atol=1e-3)
    m = node.publisher.sent[-1]
    assert m.frame_id == "CHASSIS"
    assert m.orientation_covariance == [-1.0] + [0.0] * 8
    assert m.orientation == [0.0, 0.0, 0.0, 0.0]
    assert m.other_covariances == [0.0] * 18


def test_the_qos_is_reliable_keep_last_1():
    from rclpy.qos import HistoryPolicy, ReliabilityPolicy

    qos = imu_qos()
    assert (qos.reliability, qos.history, qos.depth) == (ReliabilityPolicy.RELIABLE, HistoryPolicy.KEEP_LAST, 1)


def test_rate_0_publishes_every_step_and_a_negative_rate_is_refused():
    _, node, readings = run_publisher(0.1, rate=0.0)
    assert len(node.publisher.sent) == 100
    np.testing.assert_array_equal(node.publisher.sent[7].accel, readings[7, :3])  # a mean of one step
    model, data = tank_world()
    config = ControllerConfig(name="x", body=Body(model, data, "Tank"), node=FakeNode(), parameters={"rate": -1.0})
    assert not pub.RttImuStatePublisher().configure(config)


# ---- Step 5: the viewer's side -------------------------------------------------


def imu(accel=(0.0, 0.0, 9.8), gyro=(0.0, 0.0, 0.0), frame_id="CHASSIS"):
    from sensor_msgs.msg import Imu

    msg = Imu()
    msg.header.frame_id = frame_id
    a, w = msg.linear_acceleration, msg.angular_velocity
    a.x, a.y, a.z = accel
    w.x, w.y, w.z = gyro
    return msg


@pytest.mark.parametrize(
    "msg, reason",
    [
        (imu(accel=(math.nan, 0, 9.8)), "not_finite"),
        (imu(gyro=(0, -math.inf, 0)), "not_finite"),
        (imu(accel=(0, 0, 9806.65)), "absurd"),  # mm/s^2
        (imu(gyro=(0, 0, 114.6)), "absurd"),  # deg/s
        (imu(frame_id="imu_link"), "wrong_frame"),
    ],
)
def test_bad_imu_messages_are_rejected_with_a_reason(msg, reason):
    assert check_imu(msg, "CHASSIS") == (None, None, reason)


def test_good_imu_messages_pass_and_an_empty_frame_means_the_viewers():
    for msg in (imu(accel=(999.0, 0, 0), gyro=(0, 0, 99.0)), imu(frame_id="")):
        accel, gyro, reason = check_imu(msg, "CHASSIS")
        assert reason is None and accel.shape == gyro.shape == (3,)


def test_a_hit_is_a_horizontal_acceleration_above_20():
    assert not sub.is_hit([12.0, 16.0, 50.0])  # exactly 20 horizontal; vertical does not count
    assert sub.is_hit([12.0, 16.001, 0.0])


def test_the_shake_lasts_half_a_second_from_the_newest_hit_and_returns_exactly():
    shake = sub.CollisionShake(np.random.default_rng(0))
    home = np.array([0.1, 0.2, 0.107])
    assert shake.tick(0.0) is None
    shake.hit(1.0, home)
    positions = [shake.tick(1.0 + 0.02 * k) for k in range(1, 25)]  # until 1.48 s
    offsets = np.array(positions) - home
    assert np.abs(offsets).max() <= sub.SHAKE_AMPLITUDE and np.abs(offsets).max() > 0.015
    assert len({tuple(o) for o in offsets}) == 24  # a new offset every tick, on x, y and z
    shake.hit(1.3, positions[-1])  # a second hit, while shaken: restarts the 0.5 s, keeps home
    assert shake.tick(1.5) is not None and shake.shaking
    end = shake.tick(1.8)
    assert end.tolist() == home.tolist() and not shake.shaking  # exactly, to the last bit
    assert shake.tick(1.82) is None
    assert (shake.hits, shake.episodes) == (2, 1)
    shake.hit(5.0, home)
    assert shake.episodes == 2


def test_a_free_root_has_its_position_at_the_start_of_its_qpos():
    model, _ = tank_world()
    body = Body(model, mujoco.MjData(model), "Tank")
    assert sub.root_position_address(model, body.root_id) == model.jnt_qposadr[model.body_jntadr[body.root_id]]
    assert sub.root_position_address(model, 0) is None  # the world body has no free joint


@pytest.fixture
def viewer(node):
    """The Step 5 project opened in this process, headless: the App and its IMU subscriber."""
    from tutorial.app.app import App
    from tutorial.core.project import load_project

    records = []
    app = App(load_project(PROJECT / "step5.yaml"), node=node, headless=True, output=records.append)
    app.open()
    app.records = records
    yield app, app.controller("RttImuStateSubscriber")
    app.close()


def test_arrows_follow_the_reading_take_gravity_off_and_hide_when_short(viewer):
    app, controller = viewer
    assert set(app.overlays.arrows) == {"Tank/acceleration", "Tank/angular_velocity"}
    assert controller.update_imu(imu(accel=(3.0, 4.0, 9.8), gyro=(0.0, 0.0, 0.5)), 0.0) is None
    accel, gyro = controller.accel_arrow, controller.gyro_arrow
    origin = app.data.site_xpos[controller.site]
    np.testing.assert_allclose(accel.origin, origin)
    np.testing.assert_allclose(accel.vector, [0.3, 0.4, 0.0], atol=1e-12)  # 0.1 m per m/s^2, 9.8 off z
    np.testing.assert_allclose(gyro.vector, [0.0, 0.0, 0.2], atol=1e-12)  # 0.4 m per rad/s
    assert accel.visible and gyro.visible
    controller.update_imu(imu(accel=(0.0, 0.0, 9.8 + 0.49), gyro=(0.0, 0.024, 0.0)), 0.0)
    assert accel.length == pytest.approx(0.049) and not accel.visible  # below 0.05 m
    assert gyro.length == pytest.approx(0.0096) and not gyro.visible  # below 0.01 m
    controller.update_imu(imu(accel=(0.0, 0.0, 9.8 + 0.51), gyro=(0.0, 0.026, 0.0)), 0.0)
    assert accel.visible and gyro.visible


def test_arrows_turn_with_the_body(viewer):
    app, controller = viewer
    root = sub.root_position_address(app.model, controller.body.root_id)
    app.data.qpos[root + 3 : root + 7] = [math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4)]  # yaw +90 deg
    controller.body.notify_kinematic_state_change()
    controller.update_imu(imu(accel=(5.0, 0.0, 9.8), gyro=(0.0, 1.0, 0.0)), 0.0)
    np.testing.assert_allclose(controller.accel_arrow.vector, [0.0, 0.5, 0.0], atol=1e-12)  # forward is +y now
    np.testing.assert_allclose(controller.gyro_arrow.vector, [-0.4, 0.0, 0.0], atol=1e-12)


def test_rejected_messages_are_counted_and_leave_the_arrows_alone(viewer):
    app, controller = viewer
    controller.update_imu(imu(accel=(3.0, 4.0, 9.8)), 0.0)
    before = controller.accel_arrow.vector.copy()
    for msg in (imu(accel=(math.nan, 0, 0)), imu(accel=(1e4, 0, 0)), imu(frame_id="map")):
        assert controller.update_imu(msg, 0.0) is not None
    np.testing.assert_array_equal(controller.accel_arrow.vector, before)
    s = controller.summary()
    assert s["accepted"] == 1 and s["rejected"] == {"absurd": 1, "not_finite": 1, "wrong_frame": 1}


def test_a_collision_shakes_the_model_on_the_timer_and_puts_it_back_exactly(viewer):
    app, controller = viewer
    root = sub.root_position_address(app.model, controller.body.root_id)
    home = app.data.qpos[root : root + 3].copy()
    controller.update_imu(imu(accel=(-30.0, 0.0, 9.8)), 0.0)
    assert controller.shake.shaking
    assert app.data.qpos[root : root + 3].tolist() == home.tolist()  # not moved by the message itself
    seen = []

    def moved():
        seen.append(app.data.qpos[root : root + 3] - home)
        return not controller.shake.shaking

    assert app.loop.run_until(moved, timeout=5.0)
    offsets = np.array(seen)
    assert np.abs(offsets).max() <= sub.SHAKE_AMPLITUDE and np.abs(offsets).max() > 0
    assert app.data.qpos[root : root + 3].tolist() == home.tolist()
    np.testing.assert_array_equal(app.data.site_xpos[controller.site], controller.accel_arrow.origin)
    events = [r["event"] for r in app.records if r["event"] in ("shake", "shake_end")]
    assert events == ["shake", "shake_end"]
    assert controller.summary()["shakes"] == 1


def test_the_viewers_imu_records_read_as_lines(viewer):
    from tutorial.tools.rtt_run import format_record

    app, controller = viewer
    controller.update_imu(imu(accel=(3.0, 4.0, 9.8), gyro=(0.0, 0.0, 0.005)), 0.0)
    controller.update_imu(imu(accel=(math.nan, 0, 0)), 0.0)
    controller.report_status()
    record = dict(app.records[-1], age_ms=12.0, rate_hz=20.0, node="/rtt_viewer")
    assert format_record(record) == (
        "[/rtt_viewer] /Tank/imu: 20.0 msg/s, newest 12 ms old, arrows: acceleration 0.500 m, "
        "angular velocity 0.002 m (hidden), shakes 0, rejected: not_finite 1"
    )
    shake = {"event": "shake", "node": "/rtt_viewer", "body": "Tank", "horizontal_acceleration": 56.77}
    assert format_record(shake) == "[/rtt_viewer] Tank: collision, 56.8 m/s^2 horizontal: shaking the view"
    summary = format_record(
        {
            "event": "summary",
            "project": "step5",
            "node": "/rtt_viewer",
            "controllers": {"RttImuStateSubscriber": controller.summary()},
        }
    )
    assert (
        "RttImuStateSubscriber: arrows: acceleration=(length=0.5, visible=True), "
        "angular_velocity=(length=0.002, visible=False)"
    ) in summary


def test_the_first_message_is_the_first_steps_reading_a_free_fall():
    _, node, readings = run_publisher(0.06)
    first = node.publisher.sent[0]
    assert first.stamp_ns == 0
    np.testing.assert_array_equal(first.accel, readings[0, :3])
    assert abs(first.accel[2]) < 1e-6  # placed 1 mm above the floor: falling, the accelerometer reads 0


def test_period_mean_is_the_mean_of_what_was_added_and_starts_over():
    mean = pub.PeriodMean()
    for reading in ([1.0, 2.0, 3.0], [3.0, 2.0, 1.0]):
        mean.add(np.array(reading))
    np.testing.assert_array_equal(mean.take(), [2.0, 2.0, 2.0])
    mean.add(np.array([5.0, 0.0, -5.0]))
    np.testing.assert_array_equal(mean.take(), [5.0, 0.0, -5.0])  # the first two are gone
    with pytest.raises(ZeroDivisionError, match=r"^PeriodMean\.take: no reading was added$"):
        mean.take()


def test_the_stamp_is_the_simulation_time_split_by_step_2s_stamp_parts():
    from tutorial.core.period import PeriodAccumulator
    from tutorial.interfaces.timing import stamp_parts

    controller, node, _ = run_publisher(2.0, rate=3.0)  # a period that is no whole number of steps
    accumulator = PeriodAccumulator(0.001, 3.0)
    due = [k for k in range(2000) if accumulator.tick()]  # 0, 334, 667, 1000, 1334, 1667
    stamps = [stamp_parts(k * 0.001) for k in due]
    assert stamps[4] == (1, 334_000_000)
    assert [m.stamp_ns for m in node.publisher.sent] == [sec * 1_000_000_000 + ns for sec, ns in stamps]
    assert controller.published == 6


def test_arrow_vectors_scale_the_reading_and_take_gravity_off_z():
    accel, gyro = sub.arrow_vectors([3.0, 4.0, 9.8], [0.0, 0.0, 0.5])
    np.testing.assert_allclose(accel, [0.3, 0.4, 0.0], atol=1e-12)  # 0.1 m per m/s^2
    np.testing.assert_allclose(gyro, [0.0, 0.0, 0.2], atol=1e-12)  # 0.4 m per rad/s
    accel, _ = sub.arrow_vectors([0.0, 0.0, 0.0], [0.0, 0.0, 0.0])  # free fall
    np.testing.assert_allclose(accel, [0.0, 0.0, -0.98], atol=1e-12)


def test_on_a_simulated_clock_the_shake_ends_half_a_second_after_the_hit(viewer):
    app, controller = viewer
    now = [50.0]
    controller.clock = lambda: now[0]
    root = sub.root_position_address(app.model, controller.body.root_id)
    home = app.data.qpos[root : root + 3].copy()
    controller.update_imu(imu(accel=(0.0, 25.0, 9.8)), now[0])  # 25 m/s^2 sideways: a hit
    ticks = 0
    while controller.shake.shaking:
        now[0] = 50.0 + 0.02 * (ticks + 1)
        controller.shake_tick()
        ticks += 1
        assert ticks <= 30
    assert ticks == 25  # 0.5 s of 20 ms ticks; the 25th puts the root back
    assert app.data.qpos[root : root + 3].tolist() == home.tolist()
    assert [r["event"] for r in app.records if r["event"].startswith("shake")] == ["shake", "shake_end"]


# ---- recordings: the arrows of a run, animated with its bodies ---------------------------


def recorded_arrows(visible_per_frame, fps=15.0):
    """A recording of the tank at rest with one red arrow, visible or not in each frame; its commands."""
    import umsgpack

    from tutorial.core.overlays import Overlays
    from tutorial.notebook import replay

    model = build_world([ModelEntry("Tank", MODEL / "tank.xml")])
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    overlays = Overlays()
    # Opaque: headless Chromium's virtual time sometimes hangs on half-transparent arrows (seen with
    # several panes); showing and hiding does not depend on the opacity.
    red = overlays.arrow("Tank/acceleration", (1.0, 0.2, 0.2), opacity=1.0)
    snapshots = []
    for k, visible in enumerate(visible_per_frame):
        red.set((0.0, 0.0, 0.2), (0.5, 0.1 * k, 0.0), visible=visible)
        snapshots.append(overlays.snapshot())
    recording = replay.record_replay(
        model,
        [data.qpos.copy()] * len(snapshots),
        fps,
        overlays=overlays,
        overlay_frames=snapshots,
        camera=([-0.6, -0.75, 0.55], [0.0, 0.0, 0.0]),
    )
    return recording, [umsgpack.unpackb(c) for c in recording.commands()]


def test_a_recording_draws_the_arrows_and_animates_them_with_the_bodies():
    from tutorial.view.meshcat_overlays import arrow_poses

    _, commands = recorded_arrows([False, True, True, True])
    path = "/meshcat/rtt_overlays/Tank/acceleration"
    objects = {c["path"] for c in commands if c["type"] == "set_object"}
    assert {f"{path}/shaft", f"{path}/head"} <= objects
    assert [c["value"] for c in commands if c["type"] == "set_property" and c["path"] == path] == [False]
    animation = next(c for c in commands if c["type"] == "set_animation")
    clips = {a["path"]: {t["name"]: t for t in a["clip"]["tracks"]} for a in animation["animations"]}
    assert any(p.startswith("/meshcat/rtt/") for p in clips)  # the bodies' clips are still there
    visible = clips[path][".visible"]
    assert [(k["time"], k["value"]) for k in visible["keys"]] == [(0, False), (1, True), (3, True)]
    shaft = clips[f"{path}/shaft"]
    assert [k["time"] for k in shaft[".position"]["keys"]] == [0, 1, 2, 3]  # it turns every frame
    position, _, y_scale = arrow_poses((0.0, 0.0, 0.2), (0.5, 0.2, 0.0))[0]
    np.testing.assert_allclose(shaft[".position"]["keys"][2]["value"], position, atol=1e-4)
    np.testing.assert_allclose(shaft[".scale"]["keys"][2]["value"], [1.0, y_scale, 1.0], atol=1e-4)


def test_a_recording_is_the_same_bytes_twice_and_refuses_a_wrong_number_of_snapshots():
    from tutorial.core.overlays import Overlays
    from tutorial.notebook import replay

    first, _ = recorded_arrows([True, False, True])
    second, _ = recorded_arrows([True, False, True])
    assert first.commands() == second.commands()
    model = build_world([ModelEntry("Tank", MODEL / "tank.xml")])
    qpos = mujoco.MjData(model).qpos.copy()
    overlays = Overlays()
    with pytest.raises(ValueError, match="1 overlay snapshots for 2 frames"):
        replay.record_replay(model, [qpos, qpos], 15, overlays=overlays, overlay_frames=[overlays.snapshot()])


@pytest.mark.browser
def test_recorded_arrows_appear_and_hide_in_a_browser(tmp_path):
    """The page of a recording shows the arrow only in the frames it was visible (headless Chromium)."""
    import subprocess

    import matplotlib.image

    from tutorial.notebook import replay

    from browser import FLAGS, chromium

    if chromium() is None:
        pytest.skip("chromium is not installed (make test installs it)")
    red_pixels = {}
    for label, frames in {"hidden": [False, True, True], "shown": [True, False, False]}.items():
        recording, _ = recorded_arrows(frames, fps=0.1)  # 10 s a frame: the page stays in frame 0
        page = tmp_path / f"{label}.html"
        page.write_text(replay.page_html([recording]))
        png = tmp_path / f"{label}.png"
        subprocess.run(
            [
                chromium(),
                *FLAGS,
                f"--user-data-dir={tmp_path / label}",
                "--virtual-time-budget=3000",
                f"--screenshot={png}",
                page.as_uri(),
            ],
            check=True,
            timeout=120,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        image = matplotlib.image.imread(str(png))[..., :3]
        r, g, b = image[..., 0], image[..., 1], image[..., 2]
        red_pixels[label] = int(((r > g + 0.3) & (r > b + 0.3)).sum())
    assert red_pixels["shown"] > 50 and red_pixels["hidden"] == 0, red_pixels


def test_the_publishers_summary_holds_the_newest_message_rounded_and_unconfigure_drops_it():
    controller, node, _ = run_publisher(0.5)
    m = node.publisher.sent[-1]
    summary = controller.summary()
    assert summary == {
        "topic": "/Tank/imu", "rate": 20.0, "frame_id": "CHASSIS", "published": 10,
        "last_linear_acceleration": [round(float(v), 6) for v in m.accel],
        "last_angular_velocity": [round(float(v), 6) for v in m.gyro],
    }  # fmt: skip
    assert summary["last_linear_acceleration"] != [0.0, 0.0, 0.0] and summary["last_angular_velocity"] != [0.0] * 3
    destroyed = []
    node.destroy_publisher = destroyed.append
    controller.unconfigure()
    assert destroyed == [node.publisher]


def test_a_publisher_that_never_published_summarises_without_readings(caplog):
    import logging

    model, data = tank_world()
    controller = pub.RttImuStatePublisher()
    log = logging.getLogger("test.imu")
    config = ControllerConfig(
        name="x", body=Body(model, data, "Tank"), node=FakeNode(), parameters={"rate": 5.0}, log=log
    )
    assert controller.configure(config)
    assert controller.summary() == {"topic": "/Tank/imu", "rate": 5.0, "frame_id": "CHASSIS", "published": 0}
    with caplog.at_level(logging.ERROR, logger="test.imu"):
        assert not pub.RttImuStatePublisher().configure(
            ControllerConfig(
                name="x", body=Body(model, data, "Tank"), node=FakeNode(), parameters={"rate": -0.5}, log=log
            )
        )
    assert caplog.messages == ["rate must be >= 0 Hz, got -0.5"]
