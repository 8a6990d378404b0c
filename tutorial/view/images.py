"""Camera pictures received over ROS 2: the newest one kept, checked.

:class:`ImageReceiver` subscribes a camera topic in one of image_transport's
two transports: ``raw`` (``sensor_msgs/Image``, checked by
:func:`tutorial.interfaces.image.image_to_array`) or ``compressed``
(``sensor_msgs/CompressedImage`` on ``<topic>/compressed``, decoded by
:func:`tutorial.interfaces.compressed_image.compressed_to_array`); it keeps
the newest picture accepted, counting the rest; ``rtt-image`` and the notebooks' live picture
(:mod:`tutorial.notebook.live_image`) show what it holds (``rtt-image`` writes it with
:mod:`tutorial.tools.image_files`).
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass

import numpy as np

from tutorial.interfaces.compressed_image import compressed_image_qos, compressed_to_array
from tutorial.interfaces.image import ImageError, camera_image_qos, image_to_array
from tutorial.interfaces.timing import stamp_seconds

DEFAULT_TOPIC = "/Tank/camera/image"
TRANSPORTS = ("raw", "compressed")  # image_transport's names


@dataclass(frozen=True)
class ReceivedImage:
    """One accepted picture.

    Attributes:
        pixels: ``(height, width, 3)`` uint8 RGB; nobody writes to it after it is made.
        stamp: the message's stamp, s (simulation time for the tutorial's camera).
        frame_id: the message's frame.
        encoding: the message's encoding, or a compressed message's format
            (``pixels`` is RGB whatever it was).
        number: how many pictures were accepted up to this one (1 for the first).
        arrival: when its callback ran, ``time.monotonic()`` s (one clock for
            every process on the machine).
        size: the message's data, bytes.
    """

    pixels: np.ndarray
    stamp: float
    frame_id: str
    encoding: str
    number: int
    arrival: float = 0.0
    size: int = 0


def transport_topic(topic: str, transport: str) -> str:
    """The topic a transport is published on: ``topic`` for raw, ``topic/compressed`` for compressed.

    A topic that already ends in ``/compressed`` is taken as it is.

    Raises:
        ValueError: an unknown transport.
    """
    if transport not in TRANSPORTS:
        raise ValueError(f"transport {transport!r}: use one of {', '.join(TRANSPORTS)}")
    if transport == "raw" or topic.endswith("/compressed"):
        return topic
    return topic.rstrip("/") + "/compressed"


class ImageReceiver:
    """Subscribes a camera topic and keeps the newest valid picture.

    Args:
        node: the ``rclpy`` node; its callbacks must be spun by the caller.
        topic: e.g. ``/Tank/camera/image``.
        transport: ``raw`` (an Image topic) or ``compressed`` (a
            CompressedImage topic: ``topic/compressed``, or ``topic`` itself
            when it ends in ``/compressed``).  A topic ending in
            ``/compressed`` is compressed whatever is given.

    Raises:
        ValueError: an unknown transport.

    The subscription callback (spin thread) converts and checks each message
    and swaps the newest picture in under a lock; :meth:`newest` and
    :meth:`counts` may be called from any thread.  A message that
    :func:`tutorial.interfaces.image.image_to_array` refuses is counted in ``rejected``
    with its reason, and the newest picture stays what it was.
    """

    def __init__(self, node, topic: str = DEFAULT_TOPIC, transport: str = "raw"):
        from sensor_msgs.msg import CompressedImage, Image

        if topic.endswith("/compressed"):
            transport = "compressed"
        self.transport = transport
        self.topic = transport_topic(topic, transport)
        self._lock = threading.Lock()
        self._newest: ReceivedImage | None = None
        self._accepted = 0
        self._rejected = 0
        self._last_error: str | None = None
        if transport == "raw":
            self._convert, self._describe = image_to_array, lambda msg: str(msg.encoding)
            self.subscription = node.create_subscription(Image, self.topic, self.on_image, camera_image_qos())
        else:
            self._convert, self._describe = compressed_to_array, lambda msg: str(msg.format)
            self.subscription = node.create_subscription(
                CompressedImage, self.topic, self.on_image, compressed_image_qos()
            )

    def on_image(self, msg) -> None:
        """Subscription callback (spin thread): check, convert, keep the newest."""
        arrival = time.monotonic()
        try:
            pixels = self._convert(msg)
        except ImageError as exc:
            with self._lock:
                self._rejected += 1
                self._last_error = str(exc)
            return
        stamp = stamp_seconds(msg.header.stamp)
        with self._lock:
            self._accepted += 1
            self._newest = ReceivedImage(
                pixels,
                stamp,
                str(msg.header.frame_id),
                self._describe(msg)[:80],
                self._accepted,
                arrival,
                len(msg.data),
            )

    def newest(self) -> ReceivedImage | None:
        """The newest accepted picture, or None before the first (any thread)."""
        with self._lock:
            return self._newest

    def counts(self) -> dict:
        """``{"accepted": n, "rejected": n, "last_error": str | None}`` (any thread)."""
        with self._lock:
            return {"accepted": self._accepted, "rejected": self._rejected, "last_error": self._last_error}
