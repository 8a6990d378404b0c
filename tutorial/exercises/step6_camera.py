"""Checks for the exercises of notebook 06 (Step 6, the camera).

Exercise 6.1, a gray camera: a ``RttCameraImagePublisher`` subclass that
publishes ``mono8`` pictures (luma, ITU-R BT.601) instead of ``rgb8``.
Exercise 6.2, publish the CameraInfo: a subclass that also publishes the
camera's ``sensor_msgs/CameraInfo`` (pinhole calibration from the field of
view) on ``/<body>/camera/camera_info``, one with each picture, stamped alike.

The learner's controller is configured on the tank and this thread plays
the simulation thread, as ``tests/test_camera_publisher.py`` does: it poses
the turret, calls ``control()`` up to the step a picture is due, and waits
until the controller's own render thread has published it (captured
in-process, :mod:`tutorial.exercises.capture`) before going on.  So no
picture is skipped, and each is compared with one this check renders from
the same pose: the same answer on every run.
"""

from __future__ import annotations

import math
import time

import numpy as np

from tutorial.exercises.capture import CapturingNode
from tutorial.exercises.grader import Case, CaseFailed, Result, grade, show

STEP = 0.001  # s, the simulation step
RATE = 10.0  # pictures per simulated second in the checks: one every 100 steps
WAIT = 20.0  # s of wall time for a picture to be published
IMAGE_TOPIC, INFO_TOPIC = "/Tank/camera/image", "/Tank/camera/camera_info"
LUMA = (0.299, 0.587, 0.114)  # ITU-R BT.601 weights of R, G, B
OFF_BY_ONE = 0.01  # share of a gray picture's pixels that may be off by one (rounding at .5 done otherwise)
# Where the turret points for each picture: (label, TURRET_Y, TURRET_P), rad.
# TURRET_Y turns about -Z: positive turns right, towards Room/crate_1 at (1.8, -1.2).
CRATE = -math.atan2(-1.2, 1.8 + 0.04)
POSES = [
    (f"the turret turned {CRATE:.2f} rad right, towards the crate", CRATE, 0.0),
    ("turned 1.2 rad left, the barrel raised 0.4 rad", -1.2, 0.4),
    ("turned round, the barrel lowered 0.1 rad", 3.0, -0.1),
]


class _Rig:
    """The learner's camera controller on the tank; the calling thread plays the simulation thread.

    Args:
        cls: the controller class; it is configured with ``rate`` = :data:`RATE`
            and its other parameters' defaults.

    Raises:
        CaseFailed: ``configure``, ``initialize`` or ``start`` refused.
        NotImplementedError: the learner's code is not written yet.
    """

    def __init__(self, cls):
        import mujoco
        import rclpy

        from tutorial.core.body import Body
        from tutorial.core.controller import ControllerConfig, ControllerIO
        from tutorial.core.world import build_world
        from tutorial.notebook.runs import load

        self.name = cls.__name__
        self.model = build_world(load("tank_world.yaml").models, time_step=STEP)
        self.node = CapturingNode(rclpy.create_node("exercise_check_camera"))
        self.controller = cls()
        self.configured = False
        parameters = {name: default for name, (_, default, _) in cls.PARAMETERS.items()}
        parameters["rate"] = RATE
        main_body = Body(self.model, mujoco.MjData(self.model), "Tank")
        config = ControllerConfig(name=self.name, body=main_body, node=self.node, parameters=parameters)
        try:
            self.configured = bool(self.controller.configure(config))
        finally:
            if not self.configured:
                self.close()
        if not self.configured:
            raise CaseFailed(
                f"{self.name}.configure returned False.",
                "return what RttCameraImagePublisher.configure returned, and True after your own setup.",
            )
        self.data = mujoco.MjData(self.model)  # the simulation's
        io = ControllerIO(body=Body(self.model, self.data, "Tank"), time_step=STEP, node=self.node, data=self.data)
        if not self.controller.initialize(io) or not self.controller.start():
            self.close()
            raise CaseFailed(f"{self.name}.initialize or start returned False.")
        self.turret = [self.model.joint(f"Tank/{j}").qposadr[0] for j in ("TURRET_Y", "TURRET_P")]
        self.steps = 0
        self.poses: list[tuple[float, np.ndarray]] = []  # (time, qpos) of each picture due

    def images(self):
        """The capturing publisher of the camera's Image topic (the first one made)."""
        pubs = self.node.published(IMAGE_TOPIC)
        if not pubs:
            topics = [p.topic for p in self.node.published()]
            raise CaseFailed(
                f"{self.name} made no publisher of {IMAGE_TOPIC} (it made {topics}).",
                "let RttCameraImagePublisher.configure create it: call super().configure(config).",
            )
        return pubs[0]

    def picture(self, turret_y: float, turret_p: float) -> None:
        """Pose the turret, step to the next picture, and wait until it is published."""
        self.data.qpos[self.turret[0]], self.data.qpos[self.turret[1]] = turret_y, turret_p
        steps = 1 if self.steps == 0 else round(1 / (RATE * STEP))  # due at t = 0, then every 0.1 s
        for _ in range(steps):
            t = self.data.time
            if not self.controller.control():
                raise CaseFailed(
                    f"{self.name}.control() returned False at t = {t:.3f} s: {self._error() or 'no error was set'}."
                )
            self.steps += 1
            self.data.time = self.steps * STEP
        self.poses.append((t, self.data.qpos.copy()))
        wanted = len(self.poses)
        deadline = time.monotonic() + WAIT
        while len(self.images().sent) < wanted:
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
        from tutorial.controllers.camera_image_publisher import RttCameraImagePublisher

        c = self.controller
        try:
            if getattr(self, "steps", 0):
                c.stop()
            if self.configured:
                c.unconfigure()
        finally:
            if getattr(c, "thread", None) is not None and c.thread.is_alive():
                RttCameraImagePublisher.finish_rendering(c)  # a broken unconfigure must not leave it running
                c.thread.join(5.0)
            self.node.destroy_node()


def _drive(cls, poses=POSES) -> _Rig:
    """Configure ``cls``, take one picture per pose, close; the rig, with everything captured."""
    rig = _Rig(cls)
    try:
        for _, turret_y, turret_p in poses:
            rig.picture(turret_y, turret_p)
    finally:
        rig.close()
    return rig


def _references(model, poses: list[tuple[float, np.ndarray]]) -> list[np.ndarray]:
    """``(H, W, 3)`` uint8 pictures of the Kinect at each ``(time, qpos)``, rendered on this thread."""
    import mujoco

    from tutorial.controllers.camera_image_publisher import render_snapshot
    from tutorial.core.simulator import Snapshot

    cam = model.camera("Tank/Kinect").id
    width, height = (int(v) for v in model.cam_resolution[cam])
    renderer = mujoco.Renderer(model, height, width)
    try:
        data = mujoco.MjData(model)
        return [render_snapshot(renderer, data, Snapshot(t, q, 0), cam).copy() for t, q in poses]
    finally:
        renderer.close()


def _stamp(msg) -> float:
    return msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9


def check_gray_camera(cls) -> Result:
    """Check a ``RttCameraImagePublisher`` subclass that publishes ``mono8`` pictures.

    Each picture: ``encoding`` ``mono8``, 320 x 240, ``step`` = width (one
    byte a pixel), ``is_bigendian`` 0, ``frame_id`` ``Kinect``, stamped with
    the simulation time it was due at, each pixel ``0.299 R + 0.587 G +
    0.114 B`` of the colour picture, rounded (within 1, and off by 1 in at most 1 % of the pixels).
    """
    from sensor_msgs.msg import Image

    runs: list = []  # one drive serves every case

    def drive():
        if not runs:
            rig = _drive(cls)
            pub = rig.images()
            if pub.msg_type is not Image:
                raise CaseFailed(
                    f"{rig.name} publishes {pub.msg_type.__name__} on {IMAGE_TOPIC}, expected sensor_msgs/Image."
                )
            runs.append((pub.messages(), rig.poses, _references(rig.model, rig.poses)))
        return runs[0]

    def picture(k: int, label: str):
        call = f"{cls.__name__}, picture {k + 1} ({label}, t = {0.1 * k:.1f} s)"

        def run():
            messages, poses, references = drive()
            msg, (t, _), colour = messages[k], poses[k], references[k]
            fields = {
                "encoding": msg.encoding,
                "height": msg.height,
                "width": msg.width,
                "step": msg.step,
                "is_bigendian": msg.is_bigendian,
                "frame_id": msg.header.frame_id,
            }
            expected = {
                "encoding": "mono8",
                "height": 240,
                "width": 320,
                "step": 320,
                "is_bigendian": 0,
                "frame_id": "Kinect",
            }
            hints = {
                "encoding": "a gray picture of one byte a pixel is mono8.",
                "step": "step is the bytes in one row: one byte a pixel, so the width.",
                "height": "height is the number of rows, width the pixels in a row: gray.shape is (rows, columns).",
                "width": "height is the number of rows, width the pixels in a row.",
                "is_bigendian": "set is_bigendian to 0.",
                "frame_id": "keep the frame_id RttCameraImagePublisher.configure set: reuse self.msg.",
            }
            for name, want in expected.items():
                if fields[name] != want:
                    raise CaseFailed(f"{call}: {name} was {fields[name]!r}, expected {want!r}.", hints[name])
            if len(msg.data) != 320 * 240:
                raise CaseFailed(
                    f"{call}: data has {len(msg.data)} bytes, expected step x height = 76800.",
                    "one byte a pixel: the gray array as uint8.",
                )
            if abs(_stamp(msg) - t) > 1e-9:
                raise CaseFailed(
                    f"{call}: stamped {_stamp(msg):.3f} s, expected {t:.3f} s.",
                    "stamp each picture with its time_s: stamp_parts(time_s).",
                )
            gray = np.frombuffer(bytes(msg.data), np.uint8).reshape(240, 320).astype(int)
            want = np.round(colour @ np.array(LUMA)).astype(int)
            off = np.abs(gray - want)
            # Off by one: integer arithmetic (OpenCV's) may round a luma a hair from .5 the other way, a
            # pixel in a thousand; truncating instead of rounding puts about half the pixels there.
            few_ones = np.count_nonzero(off == 1) <= OFF_BY_ONE * gray.size
            wrong = np.argwhere(off > 1) if (off > 1).any() or few_ones else np.argwhere(off == 1)
            if len(wrong):
                r, c = (int(v) for v in wrong[0])
                raise CaseFailed(
                    f"{call}: {len(wrong)} of {gray.size} pixels are off by {'more than ' if off[r, c] > 1 else ''}1,"
                    f" e.g. row {r}, column {c} is {gray[r, c]}, expected {want[r, c]} (R, G, B = "
                    f"{show([int(v) for v in colour[r, c]])}).",
                    "gray = 0.299 R + 0.587 G + 0.114 B, rounded (np.round: astype alone cuts the fraction off): "
                    "green counts most, blue least.",
                )

        return Case(call, run)

    return grade("Exercise 6.1, a gray camera", [picture(k, label) for k, (label, _, _) in enumerate(POSES)])


def expected_camera_info(width: int, height: int, fovy_deg: float) -> dict:
    """The pinhole calibration of a MuJoCo camera: ``{"k": 9 numbers, "r": 9, "p": 12}``.

    MuJoCo's pixels are square (``fx = fy``), ``fovy`` is the vertical field
    of view in degrees, and the optical axis passes through the middle of
    the picture, where ROS (and OpenCV) put the centre of pixel (0, 0) at (0, 0).
    """
    fy = (height / 2) / math.tan(math.radians(fovy_deg) / 2)
    fx, cx, cy = fy, (width - 1) / 2, (height - 1) / 2
    return {
        "k": [fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0],
        "r": [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        "p": [fx, 0.0, cx, 0.0, 0.0, fy, cy, 0.0, 0.0, 0.0, 1.0, 0.0],
    }


def check_camera_info(cls) -> Result:
    """Check a ``RttCameraImagePublisher`` subclass that also publishes ``sensor_msgs/CameraInfo``.

    Topic ``/<body>/camera/camera_info``, the camera's QoS (best effort, keep
    last 1), one CameraInfo with each Image, with its stamp and ``frame_id``;
    320 x 240, ``plumb_bob`` with five zero distortion coefficients, and
    ``k``, ``r``, ``p`` as :func:`expected_camera_info` gives them.
    """
    from rclpy.qos import ReliabilityPolicy
    from sensor_msgs.msg import CameraInfo

    runs: list = []  # one drive serves every case
    name = cls.__name__

    def drive():
        if not runs:
            rig = _drive(cls)
            images = rig.images().messages()
            pubs = rig.node.published(INFO_TOPIC)
            if len(pubs) != 1:
                topics = [p.topic for p in rig.node.published()]
                raise CaseFailed(
                    f"{name} made publishers of {topics}, expected one of {INFO_TOPIC}.",
                    'name it after the body: f"/{config.body_name}/camera/camera_info".',
                )
            cam = rig.model.camera("Tank/Kinect").id
            runs.append((images, pubs[0], float(rig.model.cam_fovy[cam])))
        return runs[0]

    def case(what: str, check, hint: str = "") -> Case:
        call = f"{name}: {what}"
        return Case(call, lambda: check(call), hint)

    def one_with_each(call):
        images, pub, _ = drive()
        if pub.msg_type is not CameraInfo:
            raise CaseFailed(
                f"{call}: it publishes {pub.msg_type.__name__} on {INFO_TOPIC}, expected sensor_msgs/CameraInfo."
            )
        qos = pub.real.qos_profile
        if qos.reliability != ReliabilityPolicy.BEST_EFFORT or qos.depth != 1:
            raise CaseFailed(
                f"{call}: it is published {qos.reliability.name.lower()}, depth {qos.depth}; "
                "expected the camera's QoS (best effort, keep last 1).",
                "a subscriber takes the Image and its CameraInfo together: use camera_image_qos().",
            )
        infos = pub.messages()
        if len(infos) != len(images):
            raise CaseFailed(
                f"{call}: {len(infos)} CameraInfo were published with {len(images)} pictures.",
                "publish one in publish_image, after the Image.",
            )

    def stamps(call):
        images, pub, _ = drive()
        for k, (image, info) in enumerate(zip(images, pub.messages())):
            if (_stamp(info), info.header.frame_id) != (_stamp(image), image.header.frame_id):
                raise CaseFailed(
                    f"{call}: CameraInfo {k + 1} is stamped {_stamp(info):.3f} s, frame "
                    f"{info.header.frame_id!r}; its Image {_stamp(image):.3f} s, frame "
                    f"{image.header.frame_id!r}.",
                    "give each CameraInfo its Image's header: the same stamp and frame_id.",
                )

    def size(call):
        _, pub, _ = drive()
        info = pub.messages()[0]
        got = [info.width, info.height, info.distortion_model, [float(v) for v in info.d]]
        want = [320, 240, "plumb_bob", [0.0] * 5]
        if got != want:
            raise CaseFailed(
                f"{call}: width, height, distortion_model, d were {show(got)}, expected {show(want)}.",
                "a simulated camera has no lens distortion: plumb_bob with five zero coefficients.",
            )

    def matrix(key: str):
        def run(call):
            _, pub, fovy = drive()
            info = pub.messages()[0]
            want = expected_camera_info(320, 240, fovy)[key]
            got = [float(v) for v in getattr(info, key)]
            if not np.allclose(got, want, rtol=0, atol=1e-6):
                raise CaseFailed(
                    f"{call}: {key} was {show([round(v, 3) for v in got])}, expected "
                    f"{show([round(v, 3) for v in want])}."
                )

        return run

    def removed(call):  # the drive ended with unconfigure(); super().unconfigure() ends the render thread
        drive()[1].require_destroyed(f"{name}.unconfigure()", "super().unconfigure() first, then destroy_publisher().")

    return grade(
        "Exercise 6.2, publish the CameraInfo",
        [
            case(f"one CameraInfo on {INFO_TOPIC} with each Image", one_with_each),
            case("each CameraInfo has its Image's stamp and frame", stamps),
            case("size and distortion", size),
            case(
                "k, from the vertical field of view",
                matrix("k"),
                "fy = (height / 2) / tan(fovy / 2), fovy in radians; fx = fy (square pixels); "
                "cx = (width - 1) / 2, cy = (height - 1) / 2.",
            ),
            case("r, the identity", matrix("r"), "a single camera needs no rectifying rotation."),
            case(
                "p, k with a fourth column of zeros",
                matrix("p"),
                "p is the 3 x 4 matrix [k | 0], row by row: a single camera has no baseline.",
            ),
            case("unconfigure() removes the CameraInfo publisher", removed),
        ],
    )
