"""Step 6's checks' rig: a learner's camera controller driven on the tank, picture by picture.

One job: :class:`Rig` configures the controller on a world whose tank
carries a given :class:`Camera` (its name, size and field of view, the
tank's name, the simulation's start time), and this thread plays the
simulation thread, as ``tests/test_camera_publisher.py`` does: it poses the
turret, calls ``control()`` up to the step a picture is due, and waits until
the controller's own render thread has published it (captured in-process,
:mod:`tutorial.exercises.capture`) before going on.  So no picture is
skipped, and :func:`references` renders the same poses on this thread: the
same pictures on every run.  Used by :mod:`tutorial.exercises.step6_camera`.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from tutorial.exercises.capture import CapturingNode
from tutorial.exercises.grader import CaseFailed

STEP = 0.001  # s, the simulation step
RATE = 10.0  # pictures per simulated second in the checks: one every 100 steps
WAIT = 20.0  # s of wall time for a picture to be published


@dataclasses.dataclass(frozen=True)
class Camera:
    """The camera a check drives: its body's name and its own, its size (pixels) and vertical field of view, and
    the simulation time of its first picture.  The default is the tank's own Kinect, from 0 s."""

    body: str = "Tank"
    name: str = "Kinect"
    width: int = 320
    height: int = 240
    fovy: float = 62.0  # degrees, the vertical field of view
    start: float = 0.0  # s

    def topic(self, kind: str) -> str:
        return f"/{self.body}/camera/{kind}"


KINECT = Camera()


def world(camera: Camera):
    """The tank's world, the tank named ``camera.body``, its camera ``camera``'s name, size and field of view."""
    from pathlib import Path

    from tutorial.core.world import build_world
    from tutorial.notebook.runs import load

    entries = load("tank_world.yaml").models
    if camera != KINECT:
        tank = next(e for e in entries if e.name == "Tank")
        xml = Path(tank.file).read_text().replace('camera name="Kinect"', f'camera name="{camera.name}"')
        entries = [dataclasses.replace(e, name=camera.body, text=xml) if e is tank else e for e in entries]
    model = build_world(entries, time_step=STEP)
    cam = model.camera(f"{camera.body}/{camera.name}").id
    model.cam_resolution[cam], model.cam_fovy[cam] = (camera.width, camera.height), camera.fovy
    return model, cam


class Rig:
    """The learner's camera controller on the tank; the calling thread plays the simulation thread.

    Args:
        cls: the controller class; it is configured with ``rate`` = :data:`RATE`
            and its other parameters' defaults.
        camera: the camera it finds on the body, and the simulation's start time.

    Raises:
        CaseFailed: ``configure``, ``initialize`` or ``start`` refused.
        NotImplementedError: the learner's code is not written yet.
    """

    def __init__(self, cls, camera: Camera):
        import mujoco
        import rclpy

        from tutorial.core.body import Body
        from tutorial.core.controller import ControllerConfig, ControllerIO

        self.name, self.camera = cls.__name__, camera
        self.model, self.camera_id = world(camera)
        self.node = CapturingNode(rclpy.create_node("exercise_check_camera"))
        self.controller = cls()
        self.configured = False
        parameters = {name: default for name, (_, default, _) in cls.PARAMETERS.items()}
        parameters["rate"] = RATE
        main_body = Body(self.model, mujoco.MjData(self.model), camera.body)
        config = ControllerConfig(name=self.name, body=main_body, node=self.node, parameters=parameters)
        self._step(
            "configure",
            lambda: self.controller.configure(config),
            "return what RttCameraImagePublisher.configure returned, and True after your own setup.",
        )
        self.configured = True
        self.data = mujoco.MjData(self.model)  # the simulation's
        self.data.time = camera.start
        io = ControllerIO(body=Body(self.model, self.data, camera.body), time_step=STEP, node=self.node, data=self.data)
        self._step("initialize", lambda: self.controller.initialize(io))
        self._step("start", self.controller.start)
        self.turret = [self.model.joint(f"{camera.body}/{j}").qposadr[0] for j in ("TURRET_Y", "TURRET_P")]
        self.steps = 0
        self.poses: list[tuple[float, np.ndarray]] = []  # (time, qpos) of each picture due

    def _step(self, step: str, call, hint: str = "") -> None:
        """One step of the controller's lifecycle, ``call()``; on a refusal or an error the rig is closed (its
        render thread ended, the node removed), so nothing the learner's class started is left running.

        Raises:
            CaseFailed: ``call()`` gave back something false (named, with ``hint``, by default to return
                what ``super()``'s step returns).
            BaseException: what ``call()`` raised, as it was.
        """
        answer = None
        try:
            answer = call()
        finally:
            if not answer:
                self.close()
        if not answer:
            raise CaseFailed(
                f"{self.name}.{step} returned {answer!r}.",
                hint or f"return what super().{step}() returns: True when all is well.",
            )

    def images(self):
        """The capturing publisher of the camera's Image topic (the first one made)."""
        return image_publisher(self.node, self.camera, self.name)

    def picture(self, turret_y: float, turret_p: float) -> None:
        """Pose the turret, step to the next picture, and wait until it is published."""
        self.data.qpos[self.turret[0]], self.data.qpos[self.turret[1]] = turret_y, turret_p
        steps = 1 if self.steps == 0 else round(1 / (RATE * STEP))  # due at the start, then every 0.1 s
        for _ in range(steps):
            t = self.data.time
            went_on = self.controller.control()
            if not went_on:
                raise CaseFailed(
                    f"{self.name}.control() returned {went_on!r} at t = {t:.3f} s: "
                    f"{self._error() or 'no error was set'}.",
                    "return what super().control() returns: True while all is well.",
                )
            self.steps += 1
            self.data.time = self.camera.start + self.steps * STEP
        self.poses.append((t, self.data.qpos.copy()))
        deadline = time.monotonic() + WAIT
        while len(self.images().sent) < len(self.poses):
            if self._error():
                raise CaseFailed(f"{self.name}: the render thread failed: {self._error()}.")
            if time.monotonic() > deadline:
                raise CaseFailed(
                    f"{self.name}: the picture due at t = {t:.3f} s was not published within {WAIT:.0f} s.",
                    "publish_image must publish the message it fills.",
                )
            time.sleep(0.005)

    def _error(self) -> str | None:
        error = getattr(self.controller, "error", None)
        if error and "NotImplementedError" in error:
            raise NotImplementedError(error)
        return error

    def close(self) -> None:
        """Stop the controller as the simulation would, end its render thread, remove the node."""
        c = self.controller
        try:
            if getattr(self, "steps", 0):
                c.stop()
            if self.configured:
                c.unconfigure()
        finally:
            if getattr(c, "thread", None) is not None and c.thread.is_alive():
                c.finishing = True  # a broken unconfigure must not leave it running: as finish_rendering() does,
                if getattr(c, "loop", None) is not None:  # the answer's own override left out
                    c.loop.wake()
                c.thread.join(5.0)
            self.node.destroy_node()


def image_publisher(node, camera: Camera, name: str):
    """The first publisher of ``camera``'s Image topic that ``node`` (capturing or recorded) has.

    Raises:
        CaseFailed: the learner's class ``name`` made none.
    """
    topic = camera.topic("image")
    pubs = node.published(topic)
    if not pubs:
        raise CaseFailed(
            f"{name} made no publisher of {topic} (it made {[p.topic for p in node.published()]}).",
            "let RttCameraImagePublisher.configure create it: call super().configure(config).",
        )
    return pubs[0]


def drive(cls, camera: Camera, poses) -> Rig:
    """Configure ``cls``, take one picture per pose, close; the rig, with everything captured."""
    rig = Rig(cls, camera)
    try:
        for _, turret_y, turret_p in poses:
            rig.picture(turret_y, turret_p)
    finally:
        rig.close()
    return rig


def references(rig: Rig) -> list[np.ndarray]:
    """``(H, W, 3)`` uint8 pictures of the rig's camera at each of its poses, rendered on this thread."""
    import mujoco

    renderer = mujoco.Renderer(rig.model, rig.camera.height, rig.camera.width)
    try:
        data = mujoco.MjData(rig.model)
        pictures = []
        for t, qpos in rig.poses:  # posed from qpos alone, as the lesson's render_snapshot() does: no physics
            data.qpos[:], data.time = qpos, t
            mujoco.mj_kinematics(rig.model, data)
            mujoco.mj_comPos(rig.model, data)  # centres of mass, for tracking cameras
            mujoco.mj_camlight(rig.model, data)
            renderer.update_scene(data, camera=rig.camera_id)
            pictures.append(renderer.render().copy())
        return pictures
    finally:
        renderer.close()
