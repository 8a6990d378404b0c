"""``/tf`` and ``/tf_static`` (``tf2_msgs/msg/TFMessage``): frames, as the stock ROS 2 tools read them.

TF is how RViz2, Foxglove and every ROS 2 program know where each frame is:
each ``geometry_msgs/TransformStamped`` gives the pose of ``child_frame_id``
in ``header.frame_id`` at ``header.stamp`` (translation in m, rotation a unit
quaternion x, y, z, w).  Transforms that never change (a robot's fixed
joints) go once on ``/tf_static``; moving ones on ``/tf``, at the rate they
change.

There is no ``tf2_msgs`` wheel on PyPI, so rclpy cannot publish these here.
They are written into recordings (``rtt-bag record --tf``) and served to
Foxglove (``rtt-foxglove``) as CDR bytes encoded with ``mcap-ros2-support``
from the message definition (``tutorial/interfaces/share/tf2_msgs/msg/TFMessage.msg``,
found by :func:`tutorial.interfaces.definitions.full_text`): byte for byte what a
ROS 2 publisher sends.

QoS, as tf2's broadcasters offer it (what ``ros2 bag play`` republishes
with): ``/tf`` reliable, volatile, keep last 100; ``/tf_static`` reliable,
transient local, keep last 1 (one message holding every static transform:
a late joiner gets them all).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import numpy as np

TF_TOPIC = "/tf"
TF_STATIC_TOPIC = "/tf_static"
TF_MESSAGE_TYPE = "tf2_msgs/msg/TFMessage"


def tf_qos(static: bool = False):
    """The QoS tf2's broadcasters offer: ``/tf`` reliable, volatile, keep last 100;
    ``/tf_static`` (``static``) reliable, transient local, keep last 1."""
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

    return QoSProfile(
        depth=1 if static else 100,
        history=HistoryPolicy.KEEP_LAST,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if static else DurabilityPolicy.VOLATILE,
    )


@dataclass(frozen=True)
class Transform:
    """One ``geometry_msgs/TransformStamped``.

    Attributes:
        stamp: ``(sec, nanosec)``.
        parent: ``header.frame_id``.
        child: ``child_frame_id``.
        translation: (3,) m, the child's origin in the parent frame.
        rotation: (4,) x, y, z, w (ROS's order), the child's axes in the parent frame.
    """

    stamp: tuple[int, int]
    parent: str
    child: str
    translation: tuple[float, float, float]
    rotation: tuple[float, float, float, float]

    @staticmethod
    def from_matrix(stamp: tuple[int, int], parent: str, child: str, matrix: np.ndarray) -> Transform:
        """From a 4x4 transform (the child's pose in the parent frame, m)."""
        import mujoco

        q = np.zeros(4)
        mujoco.mju_mat2Quat(q, np.ascontiguousarray(matrix[:3, :3]).reshape(9))
        w, x, y, z = (float(v) for v in q)
        t = matrix[:3, 3]
        return Transform(stamp, parent, child, (float(t[0]), float(t[1]), float(t[2])), (x, y, z, w))

    def as_dict(self) -> dict:
        """The message as the ``mcap-ros2-support`` encoder takes it."""
        (sec, nanosec), (tx, ty, tz), (x, y, z, w) = self.stamp, self.translation, self.rotation
        return {
            "header": {"stamp": {"sec": sec, "nanosec": nanosec}, "frame_id": self.parent},
            "child_frame_id": self.child,
            "transform": {
                "translation": {"x": tx, "y": ty, "z": tz},
                "rotation": {"x": x, "y": y, "z": z, "w": w},
            },
        }


@cache
def tf_definition() -> tuple[str, str]:
    """``(encoding, text)`` of ``tf2_msgs/msg/TFMessage``, as rosbag2 stores it (any thread)."""
    from tutorial.interfaces.definitions import full_text

    return full_text(TF_MESSAGE_TYPE)


@cache
def _encoder():
    from mcap_ros2._dynamic import serialize_dynamic

    return serialize_dynamic(TF_MESSAGE_TYPE, tf_definition()[1])[TF_MESSAGE_TYPE]


def encode_tf_message(transforms) -> bytes:
    """A ``tf2_msgs/msg/TFMessage`` of ``transforms`` (:class:`Transform`) as CDR bytes (any thread)."""
    return bytes(_encoder()({"transforms": [t.as_dict() for t in transforms]}))


def decode_tf_message(data: bytes) -> list[Transform]:
    """CDR bytes of a ``TFMessage`` back into :class:`Transform` objects (any thread).

    Raises:
        ValueError: the bytes are not a ``TFMessage``.
    """
    from mcap_ros2._dynamic import generate_dynamic

    decoder = generate_dynamic(TF_MESSAGE_TYPE, tf_definition()[1])[TF_MESSAGE_TYPE]
    try:
        msg = decoder(data)
    except Exception as exc:  # noqa: BLE001 - the decoder fails in many ways on bad bytes
        raise ValueError(f"not a TFMessage: {exc!r}") from None
    out = []
    for t in msg.transforms:
        tr, r = t.transform.translation, t.transform.rotation
        stamp = (t.header.stamp.sec, t.header.stamp.nanosec)
        out.append(Transform(stamp, t.header.frame_id, t.child_frame_id, (tr.x, tr.y, tr.z), (r.x, r.y, r.z, r.w)))
    return out
