"""Camera pictures received over ROS 2: the newest one kept, checked, and written as PNG.

:class:`ImageReceiver` subscribes a camera topic in one of image_transport's
two transports: ``raw`` (``sensor_msgs/Image``, checked by
:func:`tutorial.interfaces.image.image_to_array`) or ``compressed``
(``sensor_msgs/CompressedImage`` on ``<topic>/compressed``, decoded by
:func:`tutorial.interfaces.compressed_image.compressed_to_array`); it keeps
the newest picture accepted, counting the rest; ``rtt-image`` and the notebooks' live picture
(:mod:`tutorial.notebook.live_image`) show what it holds.
:class:`PngWriter` writes pictures to files, whole or not at all.
"""

from __future__ import annotations

import io
import os
import threading
import time
from dataclasses import dataclass
from pathlib import Path

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


class PngWriter:
    """Writes pictures to ``path``: one file replaced each time, or numbered files.

    Args:
        path: a file name, or a pattern with ``{n}`` (``frames/image_{n:04d}.png``)
            for numbered files.
        max_files: with a pattern, the most files written; later writes are refused.

    Raises:
        ValueError: ``path`` is a directory, or a pattern that does not format.

    One thread only (the main thread of ``rtt-image``).
    """

    def __init__(self, path: str, max_files: int = 100):
        self.pattern = "{n" in path
        if os.path.isdir(path):
            raise ValueError(f"--output {path} is a directory: give a file name or a pattern with {{n}}")
        if self.pattern:
            try:
                path.format(n=0)
            except (KeyError, IndexError, ValueError) as exc:
                raise ValueError(f"--output {path}: not a pattern of {{n}}: {exc}") from None
        self.path = path
        self.max_files = max_files
        self.written = 0

    def write(self, pixels: np.ndarray) -> str | None:
        """Write one ``(H, W, 3)`` uint8 picture; the file name, or None when the limit is reached."""
        if self.pattern and self.written >= self.max_files:
            return None
        target = Path(self.path.format(n=self.written) if self.pattern else self.path)
        target.parent.mkdir(parents=True, exist_ok=True)
        tmp = target.with_name(f".{target.name}.tmp")
        tmp.write_bytes(png_bytes(pixels))
        os.replace(tmp, target)  # whole or not at all: a reader never sees half a PNG
        self.written += 1
        return str(target)


def format_image_status(received: dict, rate: float, newest: ReceivedImage | None) -> str:
    """The once-a-second status line of ``rtt-image`` (without its node prefix)."""
    rejected = received["rejected"]
    reject_text = "none" if not rejected else f"{rejected} (last: {received['last_error']})"
    if newest is None:
        return f"{rate:.1f} img/s, no picture yet, rejected: {reject_text}"
    h, w, _ = newest.pixels.shape
    size = f" ({newest.size / 1000:.1f} kB)" if "compressed" in newest.encoding else ""
    return (
        f"{rate:.1f} img/s, {w}x{h} {newest.encoding}{size} frame {newest.frame_id or '(none)'}, "
        f"newest stamp {newest.stamp:.3f} s, {received['accepted']} accepted, rejected: {reject_text}"
    )


def png_bytes(pixels: np.ndarray) -> bytes:
    """An ``(H, W, 3)`` uint8 RGB array as PNG bytes (for ``ipywidgets.Image`` or a file).

    Any thread may call it (it draws no figure).

    Raises:
        ValueError: the array is not ``(H, W, 3)`` uint8.
    """
    from matplotlib.image import imsave

    if pixels.ndim != 3 or pixels.shape[2] != 3 or pixels.dtype != np.uint8:
        raise ValueError(f"expected an (H, W, 3) uint8 array, got {pixels.shape} {pixels.dtype}")
    buf = io.BytesIO()
    imsave(buf, pixels, format="png")
    return buf.getvalue()
