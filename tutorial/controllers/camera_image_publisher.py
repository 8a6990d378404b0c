"""Step 6: publish what the tank's camera sees, without slowing the simulation.

The camera ``Kinect`` on the turret is rendered by MuJoCo's offscreen
renderer.  On a CPU (Mesa's software OpenGL) one 320 x 240 picture takes
4 to 30 ms, depending on the scene and on what else the CPU is doing: up to
thirty simulation steps.  Rendered inside ``control()``, every picture would
stall the 1 ms physics, and the simulation would fall behind real time.

So the work is split between two threads:

* ``control()`` (simulation thread, every step) stays cheap.  When a period
  has passed (Step 2's ``PeriodAccumulator``; 30 Hz of simulated time by
  default) it copies the joint positions ``qpos`` and the time into a
  ``Snapshot`` (a few hundred bytes) and hands it to the render thread.
* The render thread has an ``MjData`` and an OpenGL context of its own (an
  OpenGL context belongs to the thread that made it).  It poses its
  ``MjData`` from the snapshot, renders the camera, fills a
  ``sensor_msgs/Image`` stamped with the snapshot's simulation time and
  publishes it.

The hand-off is Step 3's coalescing ``call_later`` (``MainLoop``), run by
the render thread instead of the main thread: while one snapshot waits, a
newer one replaces it.  When rendering cannot keep up, pictures are skipped
(and counted), never queued: the simulation never waits for the renderer,
and each picture published is the newest that could be made.

Topic ``/<body>/camera/image`` (``/Tank/camera/image``), type
``sensor_msgs/Image``: ``rgb8``, rows top to bottom, ``step`` = 3 x width
bytes, ``frame_id`` = the camera's name (``Kinect``).  That frame is
MuJoCo's camera frame: it looks along its -z with +y up (ROS's optical
frames look along +z with +y down).

QoS: best effort, keep last 1, volatile: the sensor-data convention, with
depth 1 where rclpy's ``qos_profile_sensor_data`` keeps 5.  A picture that
arrives late is worth nothing (the next one is 33 ms behind it), so none is
resent, and only the newest is kept.  A subscriber must ask for best effort
too: a reliable subscription does not match a best-effort publisher.

Rendering offscreen needs an OpenGL context without a window.  MuJoCo picks
its backend from ``MUJOCO_GL`` when ``mujoco`` is first imported; importing
``tutorial`` first makes it ``egl`` (Mesa's, on the CPU, where there is no
GPU) unless you chose another.  When none works, the controller refuses to
configure and says why.
"""

from __future__ import annotations

import os
import threading
import time
from array import array

import mujoco
import numpy as np

from tutorial.call_later import MainLoop
from tutorial.controller import ControllerConfig, ControllerIO, SimpleController
from tutorial.controllers.joint_state_publisher import PeriodAccumulator
from tutorial.simulator import Snapshot

DEFAULT_RATE = 30.0  # Hz of simulated time
START_TIMEOUT = 20.0  # s for the render thread to make its OpenGL context
STOP_TIMEOUT = 5.0  # s for the render thread to finish its last picture


def camera_image_topic(body_name: str) -> str:
    """``/<body name>/camera/image``, e.g. ``/Tank/camera/image``."""
    return f"/{body_name}/camera/image"


def camera_image_qos():
    """Best effort, keep last 1, volatile (see the module text for why)."""
    from rclpy.qos import (DurabilityPolicy, HistoryPolicy, QoSProfile,
                           ReliabilityPolicy)

    return QoSProfile(depth=1, history=HistoryPolicy.KEEP_LAST,
                      reliability=ReliabilityPolicy.BEST_EFFORT,
                      durability=DurabilityPolicy.VOLATILE)


def body_cameras(model: mujoco.MjModel, body_name: str) -> list[tuple[int, str]]:
    """The cameras of one body, in model order: ``(camera id, name in the body)``."""
    prefix = f"{body_name}/"
    names = [(i, model.camera(i).name) for i in range(model.ncam)]
    return [(i, name[len(prefix):]) for i, name in names if name.startswith(prefix)]


def render_snapshot(renderer: mujoco.Renderer, data: mujoco.MjData,
                    snapshot: Snapshot, camera_id: int) -> np.ndarray:
    """Pose ``data`` as in ``snapshot`` and render one camera.

    Returns:
        The picture, ``(height, width, 3)`` uint8 RGB, rows top to bottom.

    Call it on the thread that made ``renderer``; ``data`` is that thread's.
    """
    model = renderer.model
    data.qpos[:] = snapshot.qpos
    data.time = snapshot.time
    mujoco.mj_kinematics(model, data)  # link poses from qpos
    mujoco.mj_comPos(model, data)  # centres of mass, for tracking cameras
    mujoco.mj_camlight(model, data)  # camera and light poses
    renderer.update_scene(data, camera=camera_id)
    return renderer.render()


def fill_image(msg, pixels: np.ndarray, time_s: float) -> None:
    """Write an ``(H, W, 3)`` uint8 RGB picture and its stamp (s) into an Image."""
    height, width, _ = pixels.shape
    # In whole nanoseconds, so a time of 7.9999999999 s is stamped 8 s, not 7.999999999.
    sec, nanosec = divmod(round(time_s * 1e9), 1_000_000_000)
    msg.header.stamp.sec, msg.header.stamp.nanosec = sec, nanosec
    msg.height, msg.width = height, width
    msg.encoding = "rgb8"
    msg.is_bigendian = 0
    msg.step = 3 * width  # bytes per row
    # An array('B') is taken as it is; a list or bytes would be checked byte by byte.
    msg.data = array("B", pixels.tobytes())


class RttCameraImagePublisher(SimpleController):
    """Step 6 controller: publishes the body's camera on ``/<body>/camera/image``.

    It uses the body's first camera, at the ``resolution`` its model gives.
    """

    PARAMETERS = {
        "rate": (float, DEFAULT_RATE, "camera image rate, Hz of simulated time"),
    }

    def configure(self, config: ControllerConfig) -> bool:
        """Main thread: the publisher, and the render thread with its OpenGL context."""
        from sensor_msgs.msg import Image

        self.log, self.node = config.log, config.node
        self.rate = config.parameters["rate"]
        if not self.rate > 0:
            config.log.error("rate must be > 0 Hz, got %s", self.rate)
            return False
        self.model = config.body.model
        cameras = body_cameras(self.model, config.body_name)
        if not cameras:
            config.log.error("body %s has no camera", config.body_name)
            return False
        self.camera_id, self.camera_name = cameras[0]
        resolution = self.model.cam_resolution[self.camera_id]  # (width, height)
        self.width, self.height = int(resolution[0]), int(resolution[1])
        if self.width * self.height <= 1:
            config.log.error('camera %s: give it resolution="W H" in its model',
                             self.camera_name)
            return False
        self.topic = camera_image_topic(config.body_name)
        self.msg = Image()
        self.msg.header.frame_id = self.camera_name
        self.publisher = config.node.create_publisher(Image, self.topic,
                                                      camera_image_qos())
        self.rendered = self.published = 0
        self.render_seconds = 0.0
        self.error: str | None = None  # set by the render thread
        self.loop: MainLoop | None = None  # the render thread's; made there
        self.finishing = False
        self.sim_span = self.wall_span = None
        self.ready = threading.Event()
        self.thread = threading.Thread(target=self.render_loop, name="camera-render",
                                       daemon=True)
        self.thread.start()
        if not self.ready.wait(START_TIMEOUT):
            self.error = f"the render thread did not start in {START_TIMEOUT} s"
        if self.error is not None:
            config.log.error("%s", self.error)
            self.unconfigure()
            return False
        return True

    def initialize(self, io: ControllerIO) -> bool:
        """Simulation thread: the accumulator that says when a picture is due."""
        self.io = io
        self.accumulator = PeriodAccumulator(io.time_step, self.rate)
        self.last_handed = None
        return True

    def start(self) -> bool:
        self.sim_start, self.wall_start = self.io.current_time, time.monotonic()
        return True

    def control(self) -> bool:
        """Simulation thread, every step: hand a snapshot over when one is due."""
        if self.accumulator.tick():
            if self.error is not None:
                return False  # the renderer failed: drop out; the summary says why
            self.hand_over()
        return True

    def hand_over(self) -> None:
        """Copy the pose into a snapshot and hand it to the render thread.

        ``call_later`` only puts the snapshot in the render thread's queue,
        under a lock held for a few instructions; it never waits for a
        picture.  A snapshot still waiting there is replaced (and counted).
        """
        data = self.io.data
        t = float(data.time)
        snapshot = Snapshot(t, data.qpos.copy(), round(t / self.io.time_step))
        self.loop.call_later(self.render_and_publish, snapshot)
        self.last_handed = t

    def stop(self) -> None:
        """Simulation thread: one last picture, then let the render thread end."""
        # The picture where the simulation ended, as Step 2 sends the final
        # state: a viewer keeps showing where the tank stopped.
        if self.io.current_time != self.last_handed and self.error is None:
            self.hand_over()
        self.sim_span = self.io.current_time - self.sim_start
        self.wall_span = time.monotonic() - self.wall_start
        self.finish_rendering()

    def unconfigure(self) -> None:
        """Main thread: wait for the render thread, then remove the publisher."""
        self.finish_rendering()
        self.thread.join(STOP_TIMEOUT)
        if self.thread.is_alive():
            self.log.warning("the render thread did not end in %s s", STOP_TIMEOUT)
        self.node.destroy_publisher(self.publisher)

    # ---- the render thread ------------------------------------------------------
    def render_loop(self) -> None:
        """The render thread: make an OpenGL context, render what it is handed."""
        self.renderer = None
        try:
            self.renderer = mujoco.Renderer(self.model, self.height, self.width)
            self.data = mujoco.MjData(self.model)  # this thread's own
            # The first picture costs about ten times a later one (shaders are
            # compiled): render one now, before the simulation starts.
            render_snapshot(self.renderer, self.data,
                            Snapshot(0.0, self.model.qpos0.copy(), 0), self.camera_id)
            self.loop = MainLoop()  # owned by this thread: runs what is handed over
        except Exception as exc:  # noqa: BLE001 - configure() reports it
            self.error = (f"cannot render camera {self.camera_name} offscreen "
                          f"(MUJOCO_GL={os.environ.get('MUJOCO_GL', 'unset')}; "
                          f"without a display, use egl): {type(exc).__name__}: {exc}")
        self.ready.set()
        try:
            while self.error is None and not self.finishing:
                self.loop.run_once(timeout=1.0)
            if self.error is None:
                self.loop.process_pending()  # the last snapshot, handed over by stop()
        finally:
            if self.renderer is not None:
                self.renderer.close()  # frees the OpenGL context on its own thread

    def render_and_publish(self, snapshot: Snapshot) -> None:
        """Render the camera at ``snapshot`` and publish the picture (render thread)."""
        if self.error is not None:
            return
        try:
            started = time.perf_counter()
            pixels = render_snapshot(self.renderer, self.data, snapshot, self.camera_id)
            self.render_seconds += time.perf_counter() - started
            self.rendered += 1
            fill_image(self.msg, pixels, snapshot.time)
            self.publisher.publish(self.msg)
            self.published += 1
        except Exception as exc:  # noqa: BLE001 - control() drops out, summary says why
            self.error = f"rendering failed: {type(exc).__name__}: {exc}"

    def finish_rendering(self) -> None:
        """Let the render thread render what is pending, then end (any thread)."""
        self.finishing = True
        if self.loop is not None:
            self.loop.wake()

    def summary(self) -> dict:
        """Counts and the rate achieved (main thread, after ``unconfigure``)."""
        loop = self.loop
        record = {"topic": self.topic, "rate": self.rate,
                  "handed_over": loop.posted if loop else 0,
                  "skipped": loop.coalesced if loop else 0,
                  "rendered": self.rendered, "published": self.published}
        if self.rendered:
            record["render_ms"] = round(1000 * self.render_seconds / self.rendered, 1)
        if self.sim_span:
            record["published_per_sim_s"] = round(self.published / self.sim_span, 2)
        if self.wall_span:
            record["published_per_wall_s"] = round(self.published / self.wall_span, 2)
        if self.error:
            record["error"] = self.error
        return record
