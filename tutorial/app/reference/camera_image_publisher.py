# Frozen from notebooks/06_step6_camera.ipynb by scripts/freeze_reference.py: the later steps
# stand on this copy, so editing that notebook changes its own step only.

"""Step 6: publish what the tank's camera sees, without slowing the simulation.

Built in ``notebooks/06_step6_camera.ipynb``: edit it there, then run
``make export``.  The camera ``Kinect`` on the turret is rendered offscreen
by MuJoCo.  On a CPU (Mesa's software OpenGL) one 320 x 240 picture takes
4 to 30 ms, up to thirty 1 ms simulation steps, so it is never rendered in
``control()``.  The work is split between two threads:

* ``control()`` (simulation thread, every step) stays cheap.  When a picture
  is due (``PeriodAccumulator`` of :mod:`tutorial.core.period`, met in
  Step 2; 30 Hz of simulated time by default) it copies ``qpos`` and the
  time into a ``Snapshot`` (a few hundred bytes) and hands it to the
  render thread.
* The render thread owns an ``MjData`` and a ``mujoco.Renderer`` (an OpenGL
  context belongs to the thread that made it).  It poses its ``MjData`` from
  the snapshot, renders the camera, and publishes a ``sensor_msgs/Image``
  stamped with the snapshot's simulation time.

The hand-off is Step 3's coalescing ``call_later`` (``MainLoop``), run by the
render thread: while one snapshot waits, a newer one replaces it and the
older is counted as skipped.  Nothing queues up: the simulation never waits
for the renderer, and each picture published is the newest that could be made.

Topic ``/<body>/camera/image``, ``rgb8``, QoS
:func:`tutorial.interfaces.image.camera_image_qos`.  The same pictures go,
compressed, to ``/<body>/camera/image/compressed`` (image_transport's
``compressed`` transport: a ``sensor_msgs/CompressedImage``, JPEG by
default, PNG where every pixel must be exact), encoded on the render thread
and only while that topic has a subscriber: the topic for a viewer across a
thin link (:mod:`tutorial.interfaces.compressed_image` says why it fits).  The
``frame_id`` is the camera's name (``Kinect``): MuJoCo's camera frame, which
looks along its -z with +y up (a ROS optical frame looks along +z, +y down).
Rendering without a window needs an OpenGL backend: MuJoCo reads
``MUJOCO_GL`` when ``mujoco`` is first imported, and importing ``tutorial``
first makes it ``egl`` (Mesa's, on the CPU where there is no GPU) unless you
chose another.  When none works, the controller refuses to configure and
says why.
"""

from __future__ import annotations

import os
import threading
import time

import mujoco
import numpy as np

from tutorial.interfaces.compressed_image import (
    CODECS,
    DEFAULT_JPEG_QUALITY,
    compressed_image_qos,
    compressed_image_topic,
    fill_compressed_image,
)

from ... import NO_OPENGL
from ...core.call_later import MainLoop
from ...core.controller import ControllerConfig, ControllerIO, SimpleController
from ...core.period import PeriodAccumulator
from ...core.simulator import Snapshot
from ...interfaces.image import camera_image_qos, camera_image_topic, fill_image

DEFAULT_RATE = 30.0  # pictures per second of simulated time
START_TIMEOUT = 20.0  # s for the render thread to make its OpenGL context
STOP_TIMEOUT = 5.0  # s for the render thread to finish its last picture


def body_cameras(model: mujoco.MjModel, body_name: str) -> list[tuple[int, str]]:
    """The cameras of one body, in model order: ``(camera id, name in the body)``.

    The world names a body's camera ``<body>/<camera>`` (``Tank/Kinect``).
    """
    prefix = f"{body_name}/"
    names = [(i, model.camera(i).name) for i in range(model.ncam)]
    return [(i, name[len(prefix) :]) for i, name in names if name.startswith(prefix)]


def render_snapshot(renderer: mujoco.Renderer, data: mujoco.MjData, snapshot: Snapshot, camera_id: int) -> np.ndarray:
    """Pose ``data`` as in ``snapshot`` and render one camera.

    Returns:
        The picture, ``(height, width, 3)`` uint8 RGB, rows top to bottom.

    Call it on the thread that made ``renderer``; ``data`` is that thread's.
    Only positions are needed for a picture: no physics runs here.
    """
    model = renderer.model
    data.qpos[:] = snapshot.qpos
    data.time = snapshot.time
    mujoco.mj_kinematics(model, data)  # link poses from qpos
    mujoco.mj_comPos(model, data)  # centres of mass, for tracking cameras
    mujoco.mj_camlight(model, data)  # camera and light poses
    renderer.update_scene(data, camera=camera_id)
    return renderer.render()


__all__ = [
    "DEFAULT_RATE",
    "START_TIMEOUT",
    "STOP_TIMEOUT",
    "body_cameras",
    "render_snapshot",
    "RttCameraImagePublisher",
]


class RttCameraImagePublisher(SimpleController):
    """Step 6 controller: publishes the body's camera on ``/<body>/camera/image``.

    The body's first camera, at the ``resolution`` its model gives, ``rate``
    pictures per second of simulated time, plus the picture where the
    simulation stopped.  Pictures the renderer cannot keep up with are
    skipped and counted, never queued.  Each picture is also published
    compressed on ``/<body>/camera/image/compressed`` while that topic has
    a subscriber (``compressed_format`` jpeg or png, ``jpeg_quality``).
    """

    PARAMETERS = {
        "rate": (float, DEFAULT_RATE, "pictures per second of simulated time"),
        "compressed_format": (str, "jpeg", ".../compressed: jpeg or png"),
        "jpeg_quality": (int, DEFAULT_JPEG_QUALITY, "JPEG quality, 1..100"),
    }

    # ---- main thread -------------------------------------------------------------
    def configure(self, config: ControllerConfig) -> bool:
        """The publishers, and the render thread with its OpenGL context."""
        from sensor_msgs.msg import CompressedImage, Image

        self.log, self.node = config.log, config.node
        self.rate = config.parameters["rate"]
        if not self.rate > 0:
            config.log.error("rate must be > 0 Hz, got %s", self.rate)
            return False
        self.codec = config.parameters.get("compressed_format", "jpeg")
        self.quality = config.parameters.get("jpeg_quality", DEFAULT_JPEG_QUALITY)
        if self.codec not in CODECS or not 1 <= self.quality <= 100:
            config.log.error(
                "compressed_format: one of %s, jpeg_quality: 1..100; got %r, %s",
                CODECS,
                self.codec,
                self.quality,
            )
            return False
        self.model = config.body.model
        cameras = body_cameras(self.model, config.body_name)
        if not cameras:
            config.log.error("body %s has no camera", config.body_name)
            return False
        self.camera_id, self.camera_name = cameras[0]
        width, height = self.model.cam_resolution[self.camera_id]
        self.width, self.height = int(width), int(height)
        if self.width * self.height <= 1:
            config.log.error('camera %s: give it resolution="W H" in its model', self.camera_name)
            return False
        self.topic = camera_image_topic(config.body_name)
        self.msg = Image()  # the render thread's alone once it runs
        self.msg.header.frame_id = self.camera_name
        self.publisher = config.node.create_publisher(Image, self.topic, camera_image_qos())
        self.compressed_topic = compressed_image_topic(config.body_name)
        self.compressed_msg = CompressedImage()  # the render thread's, as self.msg
        self.compressed_msg.header.frame_id = self.camera_name
        self.compressed_publisher = config.node.create_publisher(
            CompressedImage, self.compressed_topic, compressed_image_qos()
        )
        # Written by the render thread, read after it has ended (summary):
        self.rendered = self.published = 0
        self.render_seconds = 0.0
        self.compressed = self.compressed_bytes = 0
        self.encode_seconds = 0.0
        # Set once, by the render thread, when it fails; control() reads it.
        # A single assignment of a str: no lock needed.
        self.error: str | None = None
        self.loop: MainLoop | None = None  # the render thread's; made there
        self.finishing = False  # set by stop() or unconfigure(); ends the thread
        self.sim_span = self.wall_span = None
        self.ready = threading.Event()
        self.thread = threading.Thread(target=self.render_loop, name="camera-render", daemon=True)
        self.thread.start()
        if not self.ready.wait(START_TIMEOUT):
            self.error = f"the render thread did not start in {START_TIMEOUT} s"
        if self.error is not None:
            config.log.error("%s", self.error)
            self.unconfigure()
            return False
        return True

    def unconfigure(self) -> None:
        """Wait for the render thread to end, then remove the publishers."""
        self.finish_rendering()
        self.thread.join(STOP_TIMEOUT)
        if self.thread.is_alive():
            self.log.warning("the render thread did not end in %s s", STOP_TIMEOUT)
        self.node.destroy_publisher(self.publisher)
        self.node.destroy_publisher(self.compressed_publisher)

    # ---- simulation thread -------------------------------------------------------
    def initialize(self, io: ControllerIO) -> bool:
        """The accumulator that says when a picture is due."""
        self.io = io
        self.accumulator = PeriodAccumulator(io.time_step, self.rate)
        self.last_handed = None  # simulation time of the last snapshot handed over
        return True

    def start(self) -> bool:
        self.sim_start, self.wall_start = self.io.current_time, time.monotonic()
        return True

    def control(self) -> bool:
        """Every step: hand a snapshot over when a picture is due."""
        if self.accumulator.tick():
            if self.error is not None:
                return False  # the render thread failed: drop out; summary says why
            self.hand_over()
        return True

    def hand_over(self) -> None:
        """Copy the pose into a snapshot and hand it to the render thread.

        ``call_later`` only puts the snapshot in the render thread's queue,
        under a lock held for a few instructions; it never waits for a
        picture.  A snapshot still waiting there is replaced (and counted).
        The copy matters: the next step changes ``data.qpos`` in place.
        """
        data = self.io.data
        t = float(data.time)
        snapshot = Snapshot(t, data.qpos.copy(), round(t / self.io.time_step))
        self.loop.call_later(self.render_and_publish, snapshot)
        self.last_handed = t

    def stop(self) -> None:
        """One last picture, where the simulation stopped; then the thread may end."""
        # As Step 2 sends the final state: a viewer keeps showing where it stopped.
        if self.io.current_time != self.last_handed and self.error is None:
            self.hand_over()
        self.sim_span = self.io.current_time - self.sim_start
        self.wall_span = time.monotonic() - self.wall_start
        self.finish_rendering()

    # ---- render thread -----------------------------------------------------------
    def render_loop(self) -> None:
        """Make the OpenGL context, then render and publish what is handed over."""
        self.renderer = None
        try:
            self.renderer = mujoco.Renderer(self.model, self.height, self.width)
            self.data = mujoco.MjData(self.model)  # this thread's own
            # The first picture costs about ten times a later one (shaders
            # are compiled): render one now, before the simulation starts.
            warm_up = Snapshot(0.0, self.model.qpos0.copy(), 0)
            render_snapshot(self.renderer, self.data, warm_up, self.camera_id)
            self.loop = MainLoop()  # owned by this thread: runs what is handed over
        except Exception as exc:  # noqa: BLE001 - configure() reports it
            gl = os.environ.get("MUJOCO_GL", "unset")
            # "disable": `import tutorial` found no EGL library
            why = NO_OPENGL if gl == "disable" else f"{type(exc).__name__}: {exc}"
            self.error = (
                f"cannot render camera {self.camera_name} offscreen (MUJOCO_GL={gl}; without a display, use egl): {why}"
            )
        self.ready.set()
        try:
            while self.error is None and not self.finishing:
                self.loop.run_once(timeout=1.0)
            if self.error is None:
                self.loop.process_pending()  # the last snapshot, from stop()
        finally:
            if self.renderer is not None:
                self.renderer.close()  # frees the OpenGL context on its own thread

    def render_and_publish(self, snapshot: Snapshot) -> None:
        """Render the camera as it was at ``snapshot``, then publish the picture."""
        if self.error is not None:
            return
        try:
            started = time.perf_counter()
            pixels = render_snapshot(self.renderer, self.data, snapshot, self.camera_id)
            self.render_seconds += time.perf_counter() - started
            self.rendered += 1
            self.publish_image(pixels, snapshot.time)
            self.published += 1
            self.publish_compressed(pixels, snapshot.time)
        except Exception as exc:  # noqa: BLE001 - control() drops out, summary says why
            self.error = f"rendering or publishing failed: {type(exc).__name__}: {exc}"

    def publish_image(self, pixels: np.ndarray, time_s: float) -> None:
        """Publish one ``(H, W, 3)`` uint8 RGB picture stamped ``time_s`` (s)."""
        fill_image(self.msg, pixels, time_s)
        self.publisher.publish(self.msg)

    def publish_compressed(self, pixels: np.ndarray, time_s: float) -> None:
        """Encode and publish the picture on ``.../compressed``, if anyone subscribes.

        As image_transport does, nothing is encoded for nobody.  The
        encoding runs on this thread, never the simulation's.  Only
        subscribed topics cross a link (DDS sends to matched readers
        only), so a remote viewer of the compressed topic never pulls the
        230 kB raw pictures.
        """
        if self.compressed_publisher.get_subscription_count() == 0:
            return
        started = time.perf_counter()
        size = fill_compressed_image(self.compressed_msg, pixels, time_s, self.codec, self.quality)
        self.encode_seconds += time.perf_counter() - started
        self.compressed_publisher.publish(self.compressed_msg)
        self.compressed += 1
        self.compressed_bytes += size

    # ---- any thread --------------------------------------------------------------
    def finish_rendering(self) -> None:
        """Let the render thread render what is pending, then end."""
        self.finishing = True
        if self.loop is not None:
            self.loop.wake()

    def summary(self) -> dict:
        """Counts and rates (main thread, after ``unconfigure``)."""
        loop = self.loop
        record = {
            "topic": self.topic,
            "rate": self.rate,
            "handed_over": loop.posted if loop else 0,
            "skipped": loop.coalesced if loop else 0,
            "rendered": self.rendered,
            "published": self.published,
        }
        if self.rendered:
            mean = self.render_seconds / self.rendered
            record["render_ms"] = round(1000 * mean, 1)
        if self.sim_span:
            record["published_per_sim_s"] = round(self.published / self.sim_span, 2)
        if self.wall_span:
            record["published_per_wall_s"] = round(self.published / self.wall_span, 2)
        if self.compressed:
            record["compressed"] = {
                "topic": self.compressed_topic,
                "format": self.compressed_msg.format,
                "published": self.compressed,
                "mean_bytes": round(self.compressed_bytes / self.compressed),
                "encode_ms": round(1000 * self.encode_seconds / self.compressed, 2),
            }
        if self.error:
            record["error"] = self.error
        return record
