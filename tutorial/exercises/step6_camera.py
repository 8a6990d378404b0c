"""Checks for the exercises of notebook 06 (Step 6, the camera).

Exercise 6.1, a gray camera: a ``RttCameraImagePublisher`` subclass that
publishes ``mono8`` pictures (luma, ITU-R BT.601) instead of ``rgb8``.
Exercise 6.2, publish the CameraInfo: a subclass that also publishes the
camera's ``sensor_msgs/CameraInfo`` (pinhole calibration from the field of
view) on ``/<body>/camera/camera_info``, one with each picture, stamped alike.

Each check drives the learner's controller on the tank, picture by picture
(:mod:`tutorial.exercises.camera_rig`): no picture is skipped, and each is
compared with one rendered from the same pose, so every run gets the same
answer.  While grading, each check also drives a camera drawn per learner
(:func:`_random_camera`, its hidden cases): another size, field of view and
name, on a tank of another name, from a start past a second, the turret at
random poses.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from tutorial.exercises.camera_rig import KINECT, Camera, drive, image_publisher, references
from tutorial.exercises.capture import RecordedNode, publishers_record
from tutorial.exercises.grader import (
    Case,
    CaseFailed,
    Result,
    expect_qos,
    experiments,
    grade,
    hidden_random,
    observe,
    show,
)

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


def _random_camera(rng) -> Camera:
    """Another camera, by the statements' rules: its size (landscape or portrait), field of view and name, its
    body's name, and a start of a second or more, past the half second (where rounding the seconds fails), below
    four (where a whole time in nanosec would not fit its 32 bits: it is judged, not refused by the message)."""
    start = rng.randrange(1, 4) + round(rng.uniform(0.5, 0.7), 3)
    size = rng.randrange(64, 241), rng.randrange(48, 181)
    return Camera(rng.choice(("Scout", "Rover")), rng.choice(("Eye", "Xtion")), *size, rng.uniform(30, 100), start)


def _hidden_poses(rng) -> list[tuple[str, float, float]]:
    """6.1's hidden turret poses: three ``("", yaw, pitch)``, rad, the yaw anywhere (-pi to pi), the pitch within
    the turret's range (-10 to 45 deg) with a margin (-0.15 to 0.75)."""
    return [("", rng.uniform(-math.pi, math.pi), rng.uniform(-0.15, 0.75)) for _ in range(3)]


def _stamp_fault(header, t: float) -> str | None:
    """What is wrong with ``header``'s stamp for ``t`` s, or None: whole seconds in ``sec``, the rest in
    ``nanosec`` (below a second), to the nanosecond (truncated or rounded)."""
    from tutorial.interfaces.timing import stamp_parts

    sec, nanosec = header.stamp.sec, header.stamp.nanosec
    if 0 <= nanosec < 1_000_000_000 and abs(sec * 1e9 + nanosec - t * 1e9) <= 1:
        return None
    return f"stamped sec={sec}, nanosec={nanosec}, expected {t:.3f} s as sec, nanosec = {stamp_parts(t)}"


def _gray_fault(msg, t: float, colour: np.ndarray, camera: Camera) -> tuple[str, str, str] | None:
    """The first way a gray picture is wrong, ``(rule, what, hint)``, or None.

    ``rule``: ``layout`` (encoding, size, step, is_bigendian), ``frame``, ``stamp`` or ``pixels``.
    """
    expected = {
        "encoding": ("mono8", "a gray picture of one byte a pixel is mono8."),
        "height": (
            camera.height,
            "height is the number of rows, width the pixels in a row: gray.shape is (rows, columns).",
        ),
        "width": (camera.width, "height is the number of rows, width the pixels in a row."),
        "step": (camera.width, "step is the bytes in one row: one byte a pixel, so the width."),
        "is_bigendian": (0, "set is_bigendian to 0."),
    }
    for name, (want, hint) in expected.items():
        if getattr(msg, name) != want:
            return "layout", f"{name} was {getattr(msg, name)!r}, expected {want!r}", hint
    if msg.header.frame_id != camera.name:
        hint = "keep the frame_id RttCameraImagePublisher.configure set: reuse self.msg."
        return "frame", f"frame_id was {msg.header.frame_id!r}, expected {camera.name!r}", hint
    size = camera.width * camera.height
    if len(msg.data) != size:
        return (
            "layout",
            f"data has {len(msg.data)} bytes, expected step x height = {size}",
            "one byte a pixel: the gray array as uint8.",
        )
    stamp = _stamp_fault(msg.header, t)
    if stamp:
        return "stamp", stamp, "stamp each picture with its time_s: stamp_parts(time_s)."
    gray = np.frombuffer(bytes(msg.data), np.uint8).reshape(camera.height, camera.width).astype(int)
    want = np.round(colour @ np.array(LUMA)).astype(int)
    off = np.abs(gray - want)
    # Off by one: integer arithmetic (OpenCV's) may round a luma a hair from .5 the other way, a
    # pixel in a thousand; truncating instead of rounding puts about half the pixels there.
    few_ones = np.count_nonzero(off == 1) <= OFF_BY_ONE * gray.size
    wrong = np.argwhere(off > 1) if (off > 1).any() or few_ones else np.argwhere(off == 1)
    if not len(wrong):
        return None
    r, c = (int(v) for v in wrong[0])
    return (
        "pixels",
        f"{len(wrong)} of {gray.size} pixels are off by {'more than ' if off[r, c] > 1 else ''}1, e.g. row {r}, "
        f"column {c} is {gray[r, c]}, expected {want[r, c]} (R, G, B = {show([int(v) for v in colour[r, c]])})",
        "gray = 0.299 R + 0.587 G + 0.114 B, rounded (np.round: astype alone cuts the fraction off): "
        "green counts most, blue least.",
    )


def check_gray_camera(cls) -> Result:
    """Check a ``RttCameraImagePublisher`` subclass that publishes ``mono8`` pictures.

    Each picture: ``encoding`` ``mono8``, the camera's size (320 x 240 for
    the Kinect), ``step`` = width (one byte a pixel), ``is_bigendian`` 0,
    ``frame_id`` the camera's name (``Kinect``), stamped with the simulation
    time it was due at (whole seconds in ``sec``, the rest in ``nanosec``),
    each pixel ``0.299 R + 0.587 G + 0.114 B`` of the colour picture, rounded
    (within 1, and off by 1 in at most 1 % of the pixels).  Hidden cases: the
    same rules for a random camera (:func:`_random_camera`) at random poses.
    """
    from sensor_msgs.msg import Image

    runs: dict = {}  # one drive a camera serves every case

    def shots(camera: Camera, poses):
        if camera not in runs:
            rig = _Drove(cls.__name__, camera, observe(_drove, cls, dataclasses.asdict(camera), poses, True))
            pub = rig.images()
            if pub.msg_type is not Image:
                raise CaseFailed(f"{rig.name} publishes {pub.msg_type.__name__} on {pub.topic}, expected an Image.")
            runs[camera] = [(m, t, c) for m, t, c in zip(pub.messages(), rig.times, rig.references)]
        return runs[camera]

    def picture(k: int, label: str) -> Case:
        call = f"{cls.__name__}, picture {k + 1} ({label}, t = {0.1 * k:.1f} s)"

        def run():
            fault = _gray_fault(*shots(KINECT, POSES)[k], KINECT)
            if fault:
                raise CaseFailed(f"{call}: {fault[1]}.", fault[2])

        return Case(call, run)

    def hidden_case(camera: Camera, poses, rule: str, call: str, hint: str) -> Case:
        def run():  # a picture's first fault names the rule it breaks: that rule's case fails
            for shot in shots(camera, poses):
                fault = _gray_fault(*shot, camera)
                if fault and fault[0] == rule:
                    raise CaseFailed(call, hint)

        return Case(call, run, hint, hidden=True)

    cases = [picture(k, label) for k, (label, _, _) in enumerate(POSES)]
    rng = hidden_random("6.1")  # while grading: this learner's own camera and poses
    if rng:
        camera = _random_camera(rng)
        poses = _hidden_poses(rng)
        for rule, call, hint in [
            ("layout", "a camera of another size: encoding, height, width, step", "take the size from the picture."),
            ("frame", "a camera of another name: the frame_id", "reuse self.msg: its frame_id is the camera's."),
            ("stamp", "stamps of a second or more: sec and nanosec", "whole seconds in sec, the rest in nanosec."),
            ("pixels", "the turret at random poses: each pixel's luma", "the luma of each pixel, rounded."),
        ]:
            cases.append(hidden_case(camera, poses, rule, call, hint))
    return grade("Exercise 6.1, a gray camera", cases)


def _drove(cls, camera: dict, poses, pictures: bool) -> dict:
    """:func:`~tutorial.exercises.camera_rig.drive` of ``cls`` with ``camera`` (its fields) at ``poses``, as data:
    ``{"publishers"`` (:func:`~tutorial.exercises.capture.publishers_record`), ``"destroyed"`` (their indices, in
    the order they were destroyed), ``"times"`` (s, of each picture due), ``"references"`` (each picture's own
    rendering, (H, W, 3) uint8, if ``pictures``)``}``."""
    rig = drive(cls, Camera(**camera), poses)
    return {
        "publishers": publishers_record(rig.node),
        "destroyed": [rig.node.publishers.index(p) for p in rig.node.destroyed],
        "times": [t for t, _ in rig.poses],
        "references": references(rig) if pictures else [],
    }


class _Drove:
    """A drive of the learner's camera controller as :func:`_drove` recorded it: what a check reads of a rig."""

    def __init__(self, name: str, camera: Camera, record: dict):
        self.name, self.camera = name, camera
        self.node = RecordedNode(record["publishers"])
        self.destroyed = [self.node.publishers[int(k)] for k in record["destroyed"]]  # as the rig's node has them
        self.times, self.references = list(record["times"]), list(record["references"])

    def images(self):
        """The publisher of the camera's Image topic (the first one made); CaseFailed when there is none."""
        return image_publisher(self.node, self.camera, self.name)


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
    last 1, volatile), one CameraInfo with each Image, with its stamp and
    ``frame_id``; the camera's size (320 x 240 for the Kinect), ``plumb_bob``
    with five zero distortion coefficients, and ``k``, ``r``, ``p`` as
    :func:`expected_camera_info` gives them for the camera's size and field of
    view.  Hidden cases: the same rules for a random camera (:func:`_random_camera`).
    """
    from sensor_msgs.msg import CameraInfo

    from tutorial.interfaces.image import camera_image_qos

    runs: dict = {}  # one drive a camera serves every case
    name = cls.__name__

    def published(camera: Camera):
        if camera not in runs:
            rig = _Drove(name, camera, observe(_drove, cls, dataclasses.asdict(camera), POSES, False))
            pubs = rig.node.published(camera.topic("camera_info"))
            if len(pubs) != 1:
                raise CaseFailed(
                    f"{name} made publishers of {[p.topic for p in rig.node.published()]}, expected one of "
                    f"{camera.topic('camera_info')}.",
                    'name it after the body: f"/{config.body_name}/camera/camera_info".',
                )
            image = rig.images()  # destroyed by super().unconfigure(), after the render thread has ended
            first = next((p for p in rig.destroyed if p is image or p is pubs[0]), None)
            runs[camera] = (image.messages(), pubs[0], pubs[0].messages(), first is image)
        return runs[camera]

    def one_with_each(call, camera):
        images, pub, infos, _ = published(camera)
        if pub.msg_type is not CameraInfo:
            raise CaseFailed(f"{call}: it publishes {pub.msg_type.__name__} on {pub.topic}, expected a CameraInfo.")
        expect_qos(
            f"{call}: the CameraInfo",
            pub.qos_profile,
            camera_image_qos(),
            "a subscriber takes the Image and its CameraInfo together: use camera_image_qos().",
        )
        if len(infos) != len(images):
            raise CaseFailed(
                f"{call}: {len(infos)} CameraInfo were published with {len(images)} pictures.",
                "publish one in publish_image, after the Image.",
            )

    def stamps(call, camera):
        images, _, infos, _ = published(camera)
        for k, (image, info) in enumerate(zip(images, infos)):
            got, want = (info.header.stamp, info.header.frame_id), (image.header.stamp, image.header.frame_id)
            if got != want:
                raise CaseFailed(
                    f"{call}: CameraInfo {k + 1} is stamped {show((got[0].sec, got[0].nanosec))}, frame "
                    f"{got[1]!r}; its Image {show((want[0].sec, want[0].nanosec))}, frame {want[1]!r}.",
                    "give each CameraInfo its Image's header: the same stamp and frame_id.",
                )

    def size(call, camera):
        info = published(camera)[2][0]
        got = [info.width, info.height, info.distortion_model, [float(v) for v in info.d]]
        want = [camera.width, camera.height, "plumb_bob", [0.0] * 5]
        if got != want:
            raise CaseFailed(
                f"{call}: width, height, distortion_model, d were {show(got)}, expected {show(want)}.",
                "a simulated camera has no lens distortion: plumb_bob with five zero coefficients.",
            )

    def matrix(key: str):
        def run(call, camera):
            info = published(camera)[2][0]
            want = expected_camera_info(camera.width, camera.height, camera.fovy)[key]
            got = [float(v) for v in getattr(info, key)]
            if not np.allclose(got, want, rtol=0, atol=1e-6):
                raise CaseFailed(f"{call}: {key} was {show([round(v, 3) for v in got])}, expected {show(want)}.")

        return run

    def removed(call, camera):  # the drive ended with unconfigure()
        _, pub, _, in_order = published(camera)
        hint = "super().unconfigure() first (it ends the render thread), then destroy_publisher()."
        pub.require_destroyed(f"{name}.unconfigure()", hint)
        if not in_order:
            raise CaseFailed(f"{call}: the CameraInfo publisher was destroyed before super().unconfigure().", hint)

    def case(what: str, check, hint: str = "", camera: Camera = KINECT) -> Case:
        call = f"{name}: {what}" if camera is KINECT else what
        return Case(call, lambda: check(call, camera), hint, camera is not KINECT)

    fovy_hint = "fy = (height / 2) / tan(fovy / 2), fovy in radians; fx = fy (square pixels); "
    cases = [
        case(
            f"one CameraInfo on {KINECT.topic('camera_info')} with each Image",
            one_with_each,
            "a publisher of CameraInfo (rclpy refuses any other message on it), one message in publish_image.",
        ),
        case("each CameraInfo has its Image's stamp and frame", stamps),
        case("size and distortion", size),
        case(
            "k, from the vertical field of view",
            matrix("k"),
            fovy_hint + "cx = (width - 1) / 2, cy = (height - 1) / 2.",
        ),
        case("r, the identity", matrix("r"), "a single camera needs no rectifying rotation."),
        case(
            "p, k with a fourth column of zeros",
            matrix("p"),
            "p is the 3 x 4 matrix [k | 0], row by row: a single camera has no baseline.",
        ),
        case("unconfigure() removes the CameraInfo publisher", removed),
    ]
    rng = hidden_random("6.2")  # while grading: this learner's own camera
    if rng:
        camera = _random_camera(rng)
        topic = "name the topic after the body, with the camera's QoS."
        header = "give each CameraInfo its Image's header: the same stamp and frame_id."
        for what, check, hint in [
            (
                "a tank of another name: one CameraInfo with each Image on its camera_info topic, the camera's QoS",
                one_with_each,
                topic,
            ),
            ("stamps of a second or more, a camera of another name: each CameraInfo's header", stamps, header),
            ("a camera of another size: width and height", size, "the picture's size: self.width, self.height."),
            ("another size and field of view: k", matrix("k"), "the camera's own field of view and size."),
            ("another size and field of view: p", matrix("p"), "the camera's own field of view and size."),
        ]:
            cases.append(case(what, check, hint, camera))
    return grade("Exercise 6.2, publish the CameraInfo", cases)


# The experiments these checks have the kernel that holds the class run while grading (grader.EXPERIMENTS),
# listed here rather than decorated: make mutate leaves a decorated function alone.
experiments(_drove)
