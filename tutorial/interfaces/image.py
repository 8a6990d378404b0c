"""``/<body>/camera/image`` (``sensor_msgs/Image``): the camera's raw pictures.

Topic :func:`camera_image_topic`, QoS :func:`camera_image_qos`;
:func:`fill_image` writes a picture into a message and
:func:`image_to_array` reads one back, trusting nothing.

A ``sensor_msgs/Image`` stores ``height`` rows of ``step`` bytes each, top row
first; a row holds ``width`` pixels of the ``encoding`` and may end in
padding (``step`` > ``width`` x bytes per pixel).  The data is exactly
``step * height`` bytes.  A received image is never trusted:
:func:`image_to_array` checks every field that decides how the bytes are
read (encoding, height, width, step, data length) and raises
:class:`ImageError` naming the first one that is wrong, so a bad message is
rejected and counted by the receiver, never drawn half or read out of bounds.
"""

from __future__ import annotations

from array import array

import numpy as np

from tutorial.interfaces.timing import stamp_parts

# encoding -> (channels, channel order to get R, G, B).  8 bits per channel only:
# ``is_bigendian`` does not matter for single bytes.
ENCODINGS = {
    "rgb8": (3, (0, 1, 2)),
    "bgr8": (3, (2, 1, 0)),
    "rgba8": (4, (0, 1, 2)),
    "bgra8": (4, (2, 1, 0)),
    "mono8": (1, (0, 0, 0)),
}
MAX_SIDE = 8192  # pixels: a bigger height or width is rejected before anything is allocated


def camera_image_topic(body_name: str) -> str:
    """``/<body name>/camera/image``, e.g. ``/Tank/camera/image``."""
    return f"/{body_name}/camera/image"


def camera_image_qos():
    """The camera's QoS: best effort, keep last 1, volatile.

    * best effort: a picture that arrives late is worth nothing (the next
      one is 33 ms behind it), so none is resent;
    * keep last 1: only the newest picture matters; a slow subscriber skips
      to it instead of working through a queue of old ones;
    * volatile: a subscriber that joins later waits for the next picture.

    It is ROS's sensor-data convention with depth 1 (rclpy's
    ``qos_profile_sensor_data`` keeps 5).  A subscriber must ask for best
    effort too: a reliable subscription does not match a best-effort publisher.
    """
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

    return QoSProfile(
        depth=1,
        history=HistoryPolicy.KEEP_LAST,
        reliability=ReliabilityPolicy.BEST_EFFORT,
        durability=DurabilityPolicy.VOLATILE,
    )


def fill_image(msg, pixels: np.ndarray, time_s: float) -> None:
    """Write a picture and its stamp into a ``sensor_msgs/Image``.

    Args:
        msg: the Image to fill (its ``header.frame_id`` is left as it is).
        pixels: ``(height, width, 3)`` uint8 RGB, rows top to bottom.
        time_s: the stamp, s of simulation time.

    ``rgb8`` is 3 bytes a pixel, so a row is ``step`` = 3 x width bytes;
    ``is_bigendian`` does not matter for single bytes but is set (0).
    Any thread may call it, on a message no other thread is using.
    """
    height, width, _ = pixels.shape
    msg.header.stamp.sec, msg.header.stamp.nanosec = stamp_parts(time_s)
    msg.height, msg.width = height, width
    msg.encoding = "rgb8"
    msg.is_bigendian = 0
    msg.step = 3 * width  # bytes per row
    # An array('B') is taken as it is; a list or bytes would be checked byte by byte.
    msg.data = array("B", pixels.tobytes())


class ImageError(ValueError):
    """A ``sensor_msgs/Image`` that cannot be read as an RGB picture; the text says which field."""


def image_to_array(msg, max_side: int = MAX_SIDE) -> np.ndarray:
    """The picture of a ``sensor_msgs/Image`` as an RGB array.

    Args:
        msg: a ``sensor_msgs.msg.Image`` (or anything with its fields).
        max_side: the largest height or width accepted, pixels.

    Returns:
        A new ``(height, width, 3)`` uint8 array, rows top to bottom, channels
        R, G, B (``mono8`` is repeated into the three; alpha is dropped).  It
        shares no memory with the message.

    Raises:
        ImageError: an unsupported encoding (supported: :data:`ENCODINGS`),
            a height or width outside 1..``max_side``, a ``step`` shorter than a
            row, or data that is not ``step * height`` bytes.

    Pure: any thread may call it.
    """
    encoding = str(msg.encoding)
    if encoding not in ENCODINGS:
        raise ImageError(f"encoding {encoding!r} is not supported (supported: {', '.join(ENCODINGS)})")
    channels, order = ENCODINGS[encoding]
    height, width, step = int(msg.height), int(msg.width), int(msg.step)
    for name, value in (("height", height), ("width", width)):
        if not 1 <= value <= max_side:
            raise ImageError(f"{name} {value} is outside 1..{max_side}")
    row = width * channels
    if step < row:
        raise ImageError(f"step {step} is shorter than a row of {width} {encoding} pixels ({row} bytes)")
    try:
        data = memoryview(msg.data)  # a received message holds array('B'): no copy here
    except TypeError:
        raise ImageError(f"data is a {type(msg.data).__name__}, not a buffer of bytes") from None
    if data.itemsize != 1 or not data.contiguous:
        raise ImageError(f"data is not contiguous bytes (item size {data.itemsize})")
    if data.nbytes != step * height:
        raise ImageError(f"data has {data.nbytes} bytes, expected step x height = {step} x {height} = {step * height}")
    raw = np.frombuffer(data, dtype=np.uint8)
    pixels = raw.reshape(height, step)[:, :row].reshape(height, width, channels)
    return np.ascontiguousarray(pixels[:, :, list(order)])
