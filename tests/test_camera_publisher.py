"""Step 6's camera publisher, in this process: what the picture shows, and the hand-off to the render thread.

The controller runs here without a Simulator: the test plays the simulation
thread, setting the turret's joint and the time in the simulation's MjData and
calling ``control()``; the controller's own render thread renders and publishes.
"""

from __future__ import annotations

import functools
import math
import os
import shlex
import subprocess
import sys
import threading

import mujoco
import numpy as np
import pytest

from tutorial.controllers.camera_image_publisher import RttCameraImagePublisher, body_cameras
from tutorial.core.body import Body
from tutorial.core.controller import ControllerConfig, ControllerIO
from tutorial.core.period import PeriodAccumulator
from tutorial.core.project import load_project
from tutorial.core.world import build_world
from tutorial.interfaces.image import camera_image_topic, fill_image, image_to_array

from conftest import PROJECT, ROOT, module_command, wait_until

CRATE_BEARING = math.atan2(-1.2, 1.8 + 0.04)  # rad, Room/crate_1 seen from the turret axis of a tank at the origin


@functools.lru_cache(maxsize=1)
def egl_problem() -> str | None:
    """Why EGL offscreen rendering does not work on this machine, or None when it does.

    Checked in a child process with ``MUJOCO_GL=egl`` forced, so a missing
    default in this process cannot make a test skip instead of fail.
    """
    probe = "from mujoco.egl import GLContext; c = GLContext(8, 8); c.make_current(); c.free()"
    r = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, timeout=60, env=dict(os.environ, MUJOCO_GL="egl")
    )
    return None if r.returncode == 0 else (r.stderr.strip().splitlines() or ["no output"])[-1]


@pytest.fixture
def egl():
    """Skips the test, saying why, where EGL offscreen rendering is not available."""
    problem = egl_problem()
    if problem:
        pytest.skip(f"EGL offscreen rendering is not available here: {problem}")


class Recorder:
    """Stands in for the controller's publisher: keeps what each message held, then publishes it."""

    def __init__(self, publisher):
        self.real = publisher
        self.lock = threading.Lock()
        self.messages: list[dict] = []

    def publish(self, msg) -> None:
        record = {
            "pixels": image_to_array(msg),
            "stamp": msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9,
            "frame_id": msg.header.frame_id,
            "encoding": msg.encoding,
            "height": msg.height,
            "width": msg.width,
            "step": msg.step,
            "is_bigendian": msg.is_bigendian,
            "size": len(msg.data),
        }
        with self.lock:
            self.messages.append(record)
        self.real.publish(msg)

    def count(self) -> int:
        with self.lock:
            return len(self.messages)


class Rig:
    """The step 6 world, a configured camera publisher and the simulation's MjData."""

    def __init__(self, node, controller: RttCameraImagePublisher, rate: float = 30.0):
        project = load_project(PROJECT / "step6.yaml")
        self.model = build_world(project.models, time_step=0.001)
        self.controller = controller
        main_body = Body(self.model, mujoco.MjData(self.model), "Tank")  # the main thread's view
        config = ControllerConfig(name="RttCameraImagePublisher", body=main_body, node=node, parameters={"rate": rate})
        assert controller.configure(config), controller.error
        self.recorder = Recorder(controller.publisher)
        controller.publisher = self.recorder
        self.data = mujoco.MjData(self.model)  # the simulation's
        self.turret_y = self.model.joint("Tank/TURRET_Y").qposadr[0]
        assert controller.initialize(
            ControllerIO(body=Body(self.model, self.data, "Tank"), time_step=0.001, node=node, data=self.data)
        )
        assert controller.start()
        self.steps = 0

    def step(self) -> bool:
        """One simulation step as the Simulator runs it, without physics: control(), then time advances."""
        ok = self.controller.control()
        self.steps += 1
        self.data.time = self.steps * 0.001
        return ok

    def close(self) -> None:
        c = self.controller
        c.stop()  # hands the final state over and lets the render thread end
        c.thread.join(10)  # before the recorder goes: the final picture is recorded too
        c.publisher = self.recorder.real
        c.unconfigure()
        assert not c.thread.is_alive(), "the render thread is still running after unconfigure()"


def crate_like(pixels: np.ndarray, rgba) -> np.ndarray:
    """(H, W) bool: pixels whose chromaticity (colour, whatever the brightness) is the crate's."""
    p = pixels.astype(float) + 1.0
    chroma = p / p.sum(axis=2, keepdims=True)
    target = np.asarray(rgba[:3], float) / float(np.sum(rgba[:3]))
    return (np.linalg.norm(chroma - target, axis=2) < 0.03) & (pixels.max(axis=2) > 40)


def project(model, turret_y: float, point) -> tuple[float, float]:
    """Pixel (u right, v down) where a world point appears in the Kinect picture, the turret at ``turret_y``.

    A pinhole camera computed here from the camera pose and fovy, independently of the renderer:
    MuJoCo cameras look along their -z with +y up.
    """
    data = mujoco.MjData(model)
    data.qpos[model.joint("Tank/TURRET_Y").qposadr[0]] = turret_y
    mujoco.mj_kinematics(model, data)
    mujoco.mj_camlight(model, data)
    cam = model.camera("Tank/Kinect").id
    c = data.cam_xmat[cam].reshape(3, 3).T @ (np.asarray(point) - data.cam_xpos[cam])
    width, height = model.cam_resolution[cam]
    f = (height / 2) / math.tan(math.radians(model.cam_fovy[cam]) / 2)
    return width / 2 + f * c[0] / -c[2], height / 2 - f * c[1] / -c[2]


def test_the_picture_changes_when_the_turret_turns_towards_an_obstacle(node, egl):
    rig = Rig(node, RttCameraImagePublisher())
    crate_rgba = rig.model.geom("Room/crate_1").rgba
    try:
        # TURRET_Y turns about -Z: positive turns the turret to the right, where the crate is
        rig.data.qpos[rig.turret_y] = -CRATE_BEARING
        assert rig.step()  # the first step is always due: one snapshot handed over
        assert wait_until(lambda: rig.recorder.count() == 1, timeout=10)
        rig.data.qpos[rig.turret_y] = CRATE_BEARING  # as far to the left: the crate is out of view
        while rig.controller.loop.posted < 2:  # steps until the next snapshot is due
            assert rig.step()
        assert wait_until(lambda: rig.recorder.count() == 2, timeout=10)
    finally:
        rig.close()
    assert rig.controller.error is None
    toward, away = rig.recorder.messages[:2]
    for m in (toward, away):
        assert (m["encoding"], m["height"], m["width"], m["step"], m["is_bigendian"], m["size"], m["frame_id"]) == (
            "rgb8",
            240,
            320,
            960,
            0,
            240 * 960,
            "Kinect",
        )
        assert m["pixels"].std() > 10, "a blank picture"
    assert toward["stamp"] == 0.0
    assert away["stamp"] == pytest.approx(0.034)  # the next 30 Hz period ends at the 34th step
    crate_toward, crate_away = (crate_like(m["pixels"], crate_rgba) for m in (toward, away))
    u, v = project(rig.model, -CRATE_BEARING, rig.model.geom("Room/crate_1").pos)
    assert 140 < u < 180, u  # the crate is near the middle, below the horizon (the camera looks down on it)
    around = (slice(round(v) - 5, round(v) + 6), slice(round(u) - 5, round(u) + 6))
    assert crate_toward[around].mean() > 0.9, "the crate's colour should be round where its centre projects"
    assert crate_toward.sum() > 1500  # pixels of crate colour
    assert crate_away.sum() < 20  # turned away: none
    assert np.abs(toward["pixels"].astype(int) - away["pixels"].astype(int)).mean() > 5


class SlowRender(RttCameraImagePublisher):
    """The render thread blocks in its first picture until the test opens ``gate``."""

    def __init__(self):
        self.gate = threading.Event()
        self.entered = threading.Event()

    def render_and_publish(self, snapshot):
        self.entered.set()
        if not self.gate.wait(30):
            raise AssertionError("gate never opened")
        super().render_and_publish(snapshot)


def test_control_never_waits_for_the_renderer_and_the_newest_snapshot_wins(node, egl):
    controller = SlowRender()
    rig = Rig(node, controller)
    errors: list[BaseException] = []
    try:
        assert rig.step()
        assert controller.entered.wait(10)  # the render thread holds snapshot 1 and is stuck
        done = threading.Event()

        def simulate():  # one simulated second more, on a thread of its own, while rendering is stuck
            try:
                for _ in range(999):
                    assert rig.step()
            except BaseException as exc:  # noqa: BLE001
                errors.append(exc)
            done.set()

        threading.Thread(target=simulate, daemon=True).start()
        assert done.wait(10), "control() waited for the blocked renderer"
        assert not errors, errors
        acc = PeriodAccumulator(0.001, 30.0)
        due = [k * 0.001 for k in range(1000) if acc.tick()]
        assert len(due) == 30
        assert controller.loop.posted == 30 and controller.loop.coalesced == 28  # the 1st is held, the 30th waits
        controller.gate.set()
        assert wait_until(lambda: rig.recorder.count() == 2, timeout=10)
    finally:
        controller.gate.set()
        rig.close()  # stop() hands over the final state (t = 1.000 s): published too
    assert controller.error is None
    stamps = [m["stamp"] for m in rig.recorder.messages]
    assert stamps == [0.0, pytest.approx(due[-1]), pytest.approx(1.0)]
    summary = controller.summary()
    assert (summary["handed_over"], summary["skipped"], summary["rendered"], summary["published"]) == (31, 28, 3, 3)


def test_fill_image_stamps_whole_nanoseconds_and_describes_the_rows():
    from sensor_msgs.msg import Image

    msg = Image()
    msg.header.frame_id = "Kinect"
    pixels = np.arange(2 * 3 * 3, dtype=np.uint8).reshape(2, 3, 3)
    fill_image(msg, pixels, 7.9999999999)  # Step 2's stamp_parts: never 1_000_000_000 ns
    assert (msg.header.stamp.sec, msg.header.stamp.nanosec) == (8, 0)
    assert (msg.height, msg.width, msg.encoding, msg.step, msg.is_bigendian) == (2, 3, "rgb8", 9, 0)
    assert msg.header.frame_id == "Kinect"  # left as it was
    np.testing.assert_array_equal(image_to_array(msg), pixels)


def test_configure_refuses_a_bad_rate_and_a_body_without_camera(node):
    project = load_project(PROJECT / "step6.yaml")
    model = build_world(project.models, time_step=0.001)
    data = mujoco.MjData(model)

    def configure(body, rate):
        return RttCameraImagePublisher().configure(
            ControllerConfig(name="cam", body=Body(model, data, body), node=node, parameters={"rate": rate})
        )

    assert body_cameras(model, "Tank") == [(0, "Kinect")]
    assert camera_image_topic("Tank") == "/Tank/camera/image"
    assert not configure("Tank", 0.0)
    assert not configure("Tank", -5.0)
    assert not configure("Room", 30.0)


@pytest.mark.cross_process
def test_without_egl_rtt_run_refuses_with_one_line_saying_why(egl):
    # glvnd finds no EGL vendor library: as on a machine without Mesa's libEGL
    env = dict(os.environ, MUJOCO_GL="egl", __EGL_VENDOR_LIBRARY_FILENAMES="/nonexistent/egl_vendor.json")
    r = subprocess.run(
        module_command("tutorial.tools.rtt_run", str(PROJECT / "step6.yaml"), "--headless", "--duration", "1"),
        capture_output=True,
        text=True,
        timeout=60,
        cwd=ROOT,
        env=env,
    )
    assert r.returncode == 1, r.stdout + r.stderr
    lines = r.stderr.strip().splitlines()
    assert lines[0].startswith("cannot render camera Kinect offscreen (MUJOCO_GL=egl; "), r.stderr
    assert lines[1] == "rtt-run: controller RttCameraImagePublisher refused to configure", r.stderr
    assert "Traceback" not in r.stdout + r.stderr


FORMATS = "compressed_format: one of ('jpeg', 'png'), jpeg_quality: 1..100"


class NoNode:
    """A node that must not be used: a refused configure creates no publisher."""

    def create_publisher(self, *args):
        raise AssertionError("a refused configure created a publisher")


@pytest.mark.unit
@pytest.mark.parametrize(
    ("parameters", "says"),
    [
        ({"rate": 0.0}, "rate must be > 0 Hz, got 0.0"),
        ({"rate": -5.0}, "rate must be > 0 Hz, got -5.0"),
        ({"rate": math.nan}, "rate must be > 0 Hz, got nan"),
        ({"rate": 30.0, "compressed_format": "gif"}, f"{FORMATS}; got 'gif', 80"),
        ({"rate": 30.0, "jpeg_quality": 0}, f"{FORMATS}; got 'jpeg', 0"),
        ({"rate": 30.0, "jpeg_quality": 101}, f"{FORMATS}; got 'jpeg', 101"),
    ],
)  # fmt: skip
def test_a_configure_with_bad_parameters_is_refused_saying_why(caplog, parameters, says):
    import logging

    model = build_world(load_project(PROJECT / "step6.yaml").models, time_step=0.001)
    log = logging.getLogger("test.camera")
    config = ControllerConfig(
        name="C", body=Body(model, mujoco.MjData(model), "Tank"), node=NoNode(), parameters=parameters, log=log
    )
    with caplog.at_level(logging.ERROR, logger="test.camera"):
        assert RttCameraImagePublisher().configure(config) is False
    assert caplog.messages == [says]


@pytest.mark.unit
def test_a_body_without_a_camera_or_its_resolution_is_refused_saying_which(caplog, tmp_path):
    import logging

    from tutorial.core.world import ModelEntry

    path = tmp_path / "cams.xml"
    path.write_text(
        '<mujoco><worldbody><body name="head"><geom type="sphere" size="0.1"/>'
        '<camera name="eye"/></body></worldbody></mujoco>'
    )
    model = build_world([ModelEntry("Room", ROOT / "model" / "room.xml"), ModelEntry("Bot", path)])
    log = logging.getLogger("test.camera")
    with caplog.at_level(logging.ERROR, logger="test.camera"):
        for body, says in (
            ("Room", "body Room has no camera"),
            ("Bot", 'camera eye: give it resolution="W H" in its model'),
        ):
            config = ControllerConfig(
                name="C", body=Body(model, mujoco.MjData(model), body), node=NoNode(), parameters={"rate": 30.0},
                log=log,
            )  # fmt: skip
            assert RttCameraImagePublisher().configure(config) is False
            assert caplog.messages[-1] == says


# ---- the render thread's work, with a stand-in renderer: no OpenGL needed -------------------------


class FakeRenderer:
    """Stands in for ``mujoco.Renderer``: keeps what each scene was made from; its picture encodes the time.

    Every pixel of a picture is ``round(1000 * data.time) % 256`` (the step, for a 1 ms step), so a test
    can tell which snapshot a published picture came from.
    """

    made: list[FakeRenderer] = []

    def __init__(self, model, height, width):
        self.model, self.height, self.width = model, height, width
        self.scenes: list[dict] = []
        self.closed = False
        FakeRenderer.made.append(self)

    def update_scene(self, data, camera):
        self.scenes.append(
            {
                "time": float(data.time),
                "qpos": data.qpos.copy(),
                "camera": camera,
                "cam_xpos": data.cam_xpos[camera].copy(),
            }
        )
        self.value = round(1000 * float(data.time)) % 256

    def render(self):
        return np.full((self.height, self.width, 3), self.value, np.uint8)

    def close(self):
        self.closed = True


class StandInNode:
    """A node whose publishers keep what they were given; ``subscribers`` is what each reports as its count."""

    def __init__(self, subscribers: int = 0, fail: str | None = None):
        self.subscribers, self.fail = subscribers, fail
        self.publishers: dict[str, StandInPublisher] = {}
        self.destroyed: list[str] = []

    def create_publisher(self, msg_type, topic, qos):
        self.publishers[topic] = StandInPublisher(self, topic, qos)
        return self.publishers[topic]

    def destroy_publisher(self, publisher):
        self.destroyed.append(publisher.topic)


class StandInPublisher:
    def __init__(self, node, topic, qos):
        self.node, self.topic, self.qos = node, topic, qos
        self.lock = threading.Lock()  # the render thread appends, the test reads
        self.sent: list[dict] = []

    def get_subscription_count(self):
        return self.node.subscribers

    def publish(self, msg):
        if self.node.fail:
            raise RuntimeError(self.node.fail)
        from tutorial.interfaces.compressed_image import compressed_to_array

        stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        if hasattr(msg, "format"):
            record = {
                "format": msg.format,
                "pixels": compressed_to_array(msg),
                "size": len(msg.data),
                "data": bytes(msg.data),
            }
        else:
            record = {"pixels": image_to_array(msg), "size": len(msg.data)}
        with self.lock:
            self.sent.append(dict(record, stamp=stamp, frame_id=msg.header.frame_id))

    def count(self) -> int:
        with self.lock:
            return len(self.sent)


RAW, COMPRESSED = "/Tank/camera/image", "/Tank/camera/image/compressed"


class StandInRig:
    """The camera publisher configured over stand-ins, its render thread rendering with :class:`FakeRenderer`."""

    def __init__(self, monkeypatch, parameters=None, node=None):
        monkeypatch.setattr(mujoco, "Renderer", FakeRenderer)
        FakeRenderer.made.clear()
        self.model = build_world(load_project(PROJECT / "step6.yaml").models, time_step=0.001)
        self.node = node or StandInNode()
        self.controller = RttCameraImagePublisher()
        config = ControllerConfig(
            name="C", body=Body(self.model, mujoco.MjData(self.model), "Tank"), node=self.node,
            parameters=parameters or {"rate": 30.0},
        )  # fmt: skip
        self.configured = self.controller.configure(config)
        self.data = mujoco.MjData(self.model)
        self.steps = 0

    def start(self):
        c = self.controller
        assert c.initialize(
            ControllerIO(body=Body(self.model, self.data, "Tank"), time_step=0.001, node=self.node, data=self.data)
        )
        assert c.start()

    def step(self) -> bool:
        ok = self.controller.control()
        self.steps += 1
        self.data.time = self.steps * 0.001
        return ok

    def close(self):
        c = self.controller
        c.stop()
        c.unconfigure()
        assert not c.thread.is_alive()


@pytest.mark.unit
def test_the_renderer_is_made_on_the_render_thread_at_the_cameras_size_and_closed_there(monkeypatch):
    rig = StandInRig(monkeypatch)
    assert rig.configured
    (renderer,) = FakeRenderer.made
    assert (renderer.height, renderer.width) == (240, 320)  # the model's resolution="320 240"
    thread = rig.controller.thread
    assert (thread.name, thread.daemon) == ("camera-render", True)  # never holds the program open
    warm_up = renderer.scenes[0]  # one picture before the simulation starts: the shaders
    assert warm_up["time"] == 0.0 and warm_up["camera"] == rig.controller.camera_id == 0
    np.testing.assert_array_equal(warm_up["qpos"], rig.model.qpos0)
    assert set(rig.node.publishers) == {RAW, COMPRESSED}
    rig.start()
    rig.close()  # stop() at t = 0: nothing was handed over yet, so the final picture is t = 0
    assert renderer.closed
    assert rig.node.destroyed == [RAW, COMPRESSED]
    assert [m["stamp"] for m in rig.node.publishers[RAW].sent] == [0.0]


@pytest.mark.unit
def test_a_snapshot_is_rendered_posed_as_the_simulation_was(monkeypatch):
    rig = StandInRig(monkeypatch)
    rig.start()
    turret_y = rig.model.joint("Tank/TURRET_Y").qposadr[0]
    handed = []
    render_and_publish = rig.controller.render_and_publish
    rig.controller.render_and_publish = lambda s: (handed.append(s), render_and_publish(s))
    try:
        rig.data.time = 0.0
        rig.data.qpos[turret_y] = 0.7
        assert rig.step()
        raw = rig.node.publishers[RAW]
        assert wait_until(lambda: raw.count() == 1, timeout=10)
        rig.data.qpos[turret_y] = -0.2  # the next step changes qpos in place: the snapshot kept its copy
    finally:
        rig.close()
    first = handed[0]
    assert (first.time, first.step, first.qpos[turret_y]) == (0.0, 0, 0.7)
    final = handed[-1]
    assert (final.time, final.step, final.qpos[turret_y]) == (0.001, 1, -0.2)  # stop(): where it stopped
    scene = FakeRenderer.made[0].scenes[1]
    assert scene["time"] == 0.0 and scene["qpos"][turret_y] == 0.7
    # the camera posed from the snapshot's qpos: kinematics and camera poses recomputed
    expected = mujoco.MjData(rig.model)
    expected.qpos[turret_y] = 0.7
    mujoco.mj_kinematics(rig.model, expected)
    mujoco.mj_comPos(rig.model, expected)
    mujoco.mj_camlight(rig.model, expected)
    np.testing.assert_allclose(scene["cam_xpos"], expected.cam_xpos[0], atol=1e-12)
    assert not np.allclose(scene["cam_xpos"], mujoco.MjData(rig.model).cam_xpos[0])  # not the unposed camera


@pytest.mark.unit
def test_stop_hands_the_final_state_over_only_when_it_was_not_handed_already(monkeypatch):
    rig = StandInRig(monkeypatch)
    rig.start()
    assert rig.controller.control()  # due at t = 0 and handed over; time not advanced: stopped right here
    rig.close()
    assert rig.controller.loop.posted == 1
    assert [m["stamp"] for m in rig.node.publishers[RAW].sent] == [0.0]
    rig = StandInRig(monkeypatch)
    rig.start()
    assert rig.step()
    assert wait_until(lambda: rig.node.publishers[RAW].count() == 1, timeout=10)  # else the final replaces it
    for _ in range(9):
        assert rig.step()
    rig.close()
    assert rig.controller.loop.posted == 2
    sent = rig.node.publishers[RAW].sent
    assert [m["stamp"] for m in sent] == [0.0, pytest.approx(0.010)]
    assert [int(m["pixels"][0, 0, 0]) for m in sent] == [0, 10]  # each picture is its own snapshot's


@pytest.mark.unit
def test_compressed_pictures_are_encoded_only_for_a_subscriber_and_summarised(monkeypatch):
    from tutorial.interfaces.compressed_image import encode_picture

    node = StandInNode(subscribers=0)
    rig = StandInRig(monkeypatch, {"rate": 30.0, "jpeg_quality": 5}, node=node)
    rig.start()
    raw, compressed = node.publishers[RAW], node.publishers[COMPRESSED]
    assert rig.step()  # t = 0: nobody subscribes to .../compressed
    assert wait_until(lambda: raw.count() == 1, timeout=10)
    node.subscribers = 1
    while rig.controller.loop.posted < 2:
        assert rig.step()
    assert wait_until(lambda: compressed.count() == 1, timeout=10)
    rig.close()  # the final picture, where it stopped (t = 0.035 s): also compressed
    assert [m["stamp"] for m in raw.sent] == [0.0, pytest.approx(0.034), pytest.approx(0.035)]
    assert [m["stamp"] for m in compressed.sent] == [pytest.approx(0.034), pytest.approx(0.035)]
    for m, r, step in zip(compressed.sent, raw.sent[1:], (34, 35), strict=True):
        assert m["format"] == "rgb8; jpeg compressed bgr8" and m["frame_id"] == "Kinect"
        assert int(r["pixels"][0, 0, 0]) == step
        assert m["data"] == encode_picture(r["pixels"], "jpeg", 5) and m["size"] == len(m["data"])  # quality 5
    c = rig.controller
    summary = c.summary()
    assert summary["compressed"] == {
        "topic": COMPRESSED, "format": "rgb8; jpeg compressed bgr8", "published": 2,
        "mean_bytes": round((compressed.sent[0]["size"] + compressed.sent[1]["size"]) / 2),
        "encode_ms": round(1000 * c.encode_seconds / 2, 2),
    }  # fmt: skip
    assert 0 < c.encode_seconds < 5
    assert (summary["handed_over"], summary["skipped"], summary["rendered"], summary["published"]) == (3, 0, 3, 3)
    assert summary["render_ms"] == round(1000 * c.render_seconds / 3, 1) and 0 < c.render_seconds < 5
    assert c.sim_span == pytest.approx(0.035)
    assert summary["published_per_sim_s"] == round(3 / c.sim_span, 2) == 85.71
    assert summary["published_per_wall_s"] == round(3 / c.wall_span, 2) and c.wall_span > 0
    assert "error" not in summary and summary["topic"] == RAW and summary["rate"] == 30.0


@pytest.mark.unit
def test_png_pictures_come_back_exactly(monkeypatch):
    node = StandInNode(subscribers=1)
    rig = StandInRig(monkeypatch, {"rate": 30.0, "compressed_format": "png"}, node=node)
    rig.start()
    for k in range(40):
        assert rig.step()
        if k in (0, 34):  # a picture was due: let it be published before the next replaces it
            assert wait_until(lambda n=(1 if k == 0 else 2): node.publishers[RAW].count() == n, timeout=10)
    rig.close()
    raw, compressed = node.publishers[RAW].sent, node.publishers[COMPRESSED].sent
    assert len(raw) == len(compressed) == 3  # t = 0, 0.034 and the final 0.040
    for r, m in zip(raw, compressed, strict=True):
        assert m["format"] == "rgb8; png compressed bgr8"
        np.testing.assert_array_equal(m["pixels"], r["pixels"])
    assert rig.controller.summary()["compressed"]["format"] == "rgb8; png compressed bgr8"


@pytest.mark.unit
def test_a_summary_before_any_picture_says_only_what_happened(monkeypatch):
    rig = StandInRig(monkeypatch)
    rig.controller.unconfigure()  # configured, never started
    assert rig.controller.summary() == {
        "topic": RAW, "rate": 30.0, "handed_over": 0, "skipped": 0, "rendered": 0, "published": 0,
    }  # fmt: skip


@pytest.mark.unit
@pytest.mark.parametrize("gl", [None, "osmesa"])
def test_a_renderer_that_cannot_be_made_refuses_the_configure_saying_why(monkeypatch, caplog, gl):
    import logging

    def no_context(model, height, width):
        raise RuntimeError("no OpenGL context")

    thread_errors = []
    monkeypatch.setattr(threading, "excepthook", thread_errors.append)  # an exception that ends the thread

    if gl is None:
        monkeypatch.delenv("MUJOCO_GL", raising=False)
    else:
        monkeypatch.setenv("MUJOCO_GL", gl)
    monkeypatch.setattr(mujoco, "Renderer", no_context)
    model = build_world(load_project(PROJECT / "step6.yaml").models, time_step=0.001)
    node = StandInNode()
    controller = RttCameraImagePublisher()
    config = ControllerConfig(
        name="C", body=Body(model, mujoco.MjData(model), "Tank"), node=node, parameters={"rate": 30.0},
        log=logging.getLogger("test.camera"),
    )  # fmt: skip
    with caplog.at_level(logging.ERROR, logger="test.camera"):
        assert controller.configure(config) is False
    says = (
        f"cannot render camera Kinect offscreen (MUJOCO_GL={gl or 'unset'}; without a display, use egl): "
        "RuntimeError: no OpenGL context"
    )
    assert caplog.messages == [says]
    assert node.destroyed == [RAW, COMPRESSED]  # nothing left behind
    assert not controller.thread.is_alive()
    assert controller.summary() == {
        "topic": RAW, "rate": 30.0, "handed_over": 0, "skipped": 0, "rendered": 0, "published": 0, "error": says,
    }  # fmt: skip
    assert thread_errors == []


@pytest.mark.unit
def test_a_picture_that_fails_stops_the_controller_at_its_next_due_step_and_is_summarised(monkeypatch):
    rig = StandInRig(monkeypatch)
    assert rig.configured
    rig.start()
    rig.node.fail = "link down"
    assert rig.step()  # due: handed over; the render thread fails to publish it
    assert wait_until(lambda: rig.controller.error is not None, timeout=10)
    says = "rendering or publishing failed: RuntimeError: link down"
    assert rig.controller.error == says
    assert all(rig.step() for _ in range(33))  # t = 0.001 .. 0.033 s: no picture due, the simulation goes on
    assert rig.step() is False  # t = 0.034 s: a picture is due, and the render thread failed: drop out
    rig.close()  # stop() hands nothing more to a failed render thread
    summary = rig.controller.summary()
    assert summary["error"] == says and rig.controller.loop.posted == 1
    assert (summary["rendered"], summary["published"]) == (1, 0)


@pytest.mark.unit
@pytest.mark.parametrize(("resolution", "accepted"), [("1 1", False), ("2 1", True), ("1 2", True)])
def test_a_camera_of_one_pixel_is_refused_and_of_two_accepted(monkeypatch, tmp_path, resolution, accepted):
    from tutorial.core.world import ModelEntry

    monkeypatch.setattr(mujoco, "Renderer", FakeRenderer)
    path = tmp_path / "cams.xml"
    path.write_text(
        '<mujoco><worldbody><body name="head"><geom type="sphere" size="0.1"/>'
        f'<camera name="eye" resolution="{resolution}"/></body></worldbody></mujoco>'
    )
    model = build_world([ModelEntry("Bot", path)])
    controller = RttCameraImagePublisher()
    config = ControllerConfig(
        name="C", body=Body(model, mujoco.MjData(model), "Bot"), node=StandInNode(), parameters={"rate": 30.0}
    )
    assert controller.configure(config) is accepted
    if accepted:
        width, height = (int(v) for v in resolution.split())
        assert (controller.width, controller.height, controller.camera_name) == (width, height, "eye")
        controller.unconfigure()


class FakeTime:
    """Stands in for the module ``time``: ``monotonic()`` gives 10.0 then 12.0 (the wall clock at start() and at
    stop()); ``perf_counter()`` makes each render take 250.12 ms and each encoding 1.2345 ms.

    The render thread alone reads ``perf_counter``, four times a picture: before and after the render, before
    and after the encoding.
    """

    STEPS = (0.001, 0.25012, 0.001, 0.0012345)  # s added by each call: a gap, a render, a gap, an encoding

    def __init__(self):
        self.counter, self.calls = 0.0, 0
        self.walls = [10.0, 12.0]

    def perf_counter(self):
        self.counter += self.STEPS[self.calls % 4]
        self.calls += 1
        return self.counter

    def monotonic(self):
        return self.walls.pop(0)


@pytest.mark.unit
def test_the_summary_gives_the_measured_render_and_encode_times_and_the_rates_over_the_run(monkeypatch):
    from tutorial.controllers import camera_image_publisher as module

    node = StandInNode(subscribers=1)
    rig = StandInRig(monkeypatch, node=node)
    monkeypatch.setattr(module, "time", FakeTime())
    rig.data.time = 5.0  # a run that starts at 5 s of simulated time
    rig.start()
    raw = node.publishers[RAW]
    for k in range(35):
        rig.data.time = 5.0 + 0.001 * k
        assert rig.controller.control()
        if k in (0, 34):  # a picture was due: let it be published before the next replaces it
            assert wait_until(lambda n=(1 if k == 0 else 2): raw.count() == n, timeout=10)
    rig.data.time = 5.035
    rig.close()
    summary = rig.controller.summary()
    assert (summary["rendered"], summary["compressed"]["published"]) == (3, 3)
    assert summary["render_ms"] == 250.1 and summary["compressed"]["encode_ms"] == 1.23  # the means, measured
    assert summary["published_per_sim_s"] == round(3 / 0.035, 2)  # 3 pictures in 35 ms of simulated time
    assert summary["published_per_wall_s"] == 1.5  # and in 2 s of wall time


@pytest.mark.unit
def test_a_render_thread_that_never_starts_is_given_up_saying_so(monkeypatch, caplog):
    import logging

    from tutorial.controllers import camera_image_publisher as module

    gate = threading.Event()

    class StuckRenderer(FakeRenderer):
        def __init__(self, *args):
            gate.wait(30)  # making the OpenGL context hangs
            super().__init__(*args)

    monkeypatch.setattr(module, "START_TIMEOUT", 0.2)
    monkeypatch.setattr(module, "STOP_TIMEOUT", 0.2)
    model = build_world(load_project(PROJECT / "step6.yaml").models, time_step=0.001)
    node = StandInNode()
    controller = RttCameraImagePublisher()
    config = ControllerConfig(
        name="C", body=Body(model, mujoco.MjData(model), "Tank"), node=node, parameters={"rate": 30.0},
        log=logging.getLogger("test.camera"),
    )  # fmt: skip
    monkeypatch.setattr(mujoco, "Renderer", StuckRenderer)
    try:
        with caplog.at_level(logging.WARNING, logger="test.camera"):
            assert controller.configure(config) is False
    finally:
        gate.set()
    assert caplog.messages == ["the render thread did not start in 0.2 s", "the render thread did not end in 0.2 s"]
    assert node.destroyed == [RAW, COMPRESSED]
    controller.thread.join(10)
    assert not controller.thread.is_alive()  # once its context came, it saw the error and ended


@pytest.mark.unit
def test_the_final_picture_handed_over_while_the_renderer_is_busy_is_still_published(monkeypatch):
    rig = StandInRig(monkeypatch)
    c = rig.controller
    gate, busy = threading.Event(), threading.Event()
    render_and_publish = c.render_and_publish

    def slow(snapshot):
        busy.set()
        gate.wait(30)
        render_and_publish(snapshot)

    c.render_and_publish = slow
    rig.start()
    try:
        assert rig.step()  # t = 0: the render thread takes it and is held
        assert busy.wait(10)
        for _ in range(9):
            assert rig.step()
        c.stop()  # the final state (t = 0.010 s) waits, and the thread is told to finish
    finally:
        gate.set()
    c.thread.join(10)
    assert [m["stamp"] for m in rig.node.publishers[RAW].sent] == [0.0, pytest.approx(0.010)]
    c.unconfigure()


@pytest.mark.unit
@pytest.mark.parametrize(
    "parameters", [{"rate": 0.5}, {"rate": 30.0, "jpeg_quality": 1}, {"rate": 30.0, "jpeg_quality": 100}]
)
def test_the_edges_of_the_parameters_are_accepted(monkeypatch, parameters):
    rig = StandInRig(monkeypatch, parameters)
    assert rig.configured
    rig.controller.unconfigure()


def without_opengl_libraries(command: list[str]) -> subprocess.CompletedProcess:
    """``command`` run where libEGL and libOpenGL cannot be loaded (each hidden by an empty file, in a mount
    namespace of its own), as on a minimal server or container, with ``MUJOCO_GL`` unset."""
    found = subprocess.run(["ldconfig", "-p"], capture_output=True, text=True, check=True).stdout
    libraries = sorted({line.split(" => ")[1] for line in found.splitlines() if "libEGL.so.1 " in line or
                        "libOpenGL.so.0 " in line})  # fmt: skip
    assert len(libraries) >= 2, found
    hide = " && ".join(f"mount --bind /dev/null {path}" for path in libraries)
    script = f"mount --make-rprivate / && {hide} && exec {' '.join(map(shlex.quote, command))}"
    env = {k: v for k, v in os.environ.items() if k != "MUJOCO_GL"}
    return subprocess.run(["unshare", "--mount", "sh", "-c", script], capture_output=True, text=True, timeout=120,
                          cwd=ROOT, env=env)  # fmt: skip


@pytest.mark.cross_process
def test_without_opengl_libraries_step_2_runs_and_the_camera_says_what_to_install():
    from tutorial import NO_OPENGL

    if os.geteuid() != 0:
        pytest.skip("hiding a library needs a mount namespace (root)")
    step2 = without_opengl_libraries(
        module_command("tutorial.tools.rtt_run", str(PROJECT / "step2.yaml"), "--headless", "--json", "--duration", "1")
    )
    assert step2.returncode == 0, step2.stderr[-2000:]
    summary = [line for line in step2.stdout.splitlines() if '"event": "summary"' in line]
    assert summary and '"simulated_time": 1.0' in summary[0], step2.stdout[-2000:]
    step6 = without_opengl_libraries(
        module_command("tutorial.tools.rtt_run", str(PROJECT / "step6.yaml"), "--headless", "--duration", "1")
    )
    assert step6.returncode == 1, step6.stdout + step6.stderr
    first = step6.stderr.strip().splitlines()[0]
    said = "cannot render camera Kinect offscreen (MUJOCO_GL=disable; without a display, use egl): "
    assert first == said + NO_OPENGL
    assert "Traceback" not in step6.stdout + step6.stderr
