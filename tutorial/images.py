"""Camera images as numpy arrays: read a ``sensor_msgs/Image`` safely, write a PNG.

A received image is never trusted.  :func:`image_to_array` checks every field
that decides how the bytes are read (encoding, height, width, step, data
length) and raises :class:`ImageError` naming the first one that is wrong,
so a bad message is rejected and counted by the receiver, never drawn half
or read out of bounds.  ``rtt-image`` and the notebooks use it.

A ``sensor_msgs/Image`` stores ``height`` rows of ``step`` bytes each, top row
first; a row holds ``width`` pixels of the ``encoding`` and may end in
padding (``step`` > ``width`` x bytes per pixel).  The data is exactly
``step * height`` bytes.
"""

from __future__ import annotations

import io

import numpy as np

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
