"""Step 6's camera publisher, in this process: what the picture shows, and the hand-off to the render thread.

The controller runs here without a Simulator: the test plays the simulation
thread, setting the turret's joint and the time in the simulation's MjData and
calling ``control()``; the controller's own render thread renders and publishes.
"""

from __future__ import annotations

import functools
import math
import os
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
        ({"rate": 30.0, "compressed_format": "gif"}, "one of ('jpeg', 'png'), jpeg_quality: 1..100; got 'gif', 80"),
        ({"rate": 30.0, "jpeg_quality": 0}, "got 'jpeg', 0"),
        ({"rate": 30.0, "jpeg_quality": 101}, "got 'jpeg', 101"),
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
    assert says in caplog.text


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
            assert says in caplog.text, caplog.text
