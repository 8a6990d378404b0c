"""The camera's compressed transport: image_transport's format string, JPEG and PNG both ways, hostile messages."""

from __future__ import annotations

import io

import numpy as np
import pytest
from PIL import Image as PilImage

from tutorial.interfaces.compressed_image import (
    codec_of,
    compressed_format,
    compressed_image_topic,
    compressed_to_array,
    encode_picture,
    fill_compressed_image,
)
from tutorial.interfaces.image import ImageError
from tutorial.tools.image_files import format_image_status
from tutorial.view.images import ImageReceiver, transport_topic


def picture(h: int = 48, w: int = 64) -> np.ndarray:
    """A smooth colour picture (JPEG keeps it within a few levels)."""
    y, x = np.mgrid[0:h, 0:w]
    return np.stack([x * 255 // w, y * 255 // h, (x + y) * 255 // (w + h)], axis=-1).astype(np.uint8)


def message(fmt: str, data) -> object:
    from sensor_msgs.msg import CompressedImage

    msg = CompressedImage()
    msg.format = fmt
    msg.data = bytes(data)
    return msg


def file_bytes(pixels: np.ndarray, fmt: str) -> bytes:
    out = io.BytesIO()
    PilImage.fromarray(pixels).save(out, format=fmt)
    return out.getvalue()


def test_topic_and_format_follow_image_transport():
    assert compressed_image_topic("Tank") == "/Tank/camera/image/compressed"
    # compressed_image_transport writes "<raw encoding>; <codec> compressed <what it gave OpenCV>".
    assert compressed_format("jpeg") == "rgb8; jpeg compressed bgr8"
    assert compressed_format("png") == "rgb8; png compressed bgr8"
    assert compressed_format("jpeg", "mono8") == "mono8; jpeg compressed mono8"
    with pytest.raises(ValueError):
        compressed_format("h264")
    assert transport_topic("/Tank/camera/image", "compressed") == "/Tank/camera/image/compressed"
    assert transport_topic("/Tank/camera/image/compressed", "compressed") == "/Tank/camera/image/compressed"
    assert transport_topic("/Tank/camera/image", "raw") == "/Tank/camera/image"


@pytest.mark.parametrize(
    "fmt, codec",
    [
        ("rgb8; jpeg compressed bgr8", "jpeg"),
        ("rgb8; png compressed bgr8", "png"),
        ("bgr8; jpeg compressed bgr8", "jpeg"),
        ("jpeg", "jpeg"),  # what older publishers write
        ("png", "png"),
        ("JPG", "jpeg"),
    ],
)
def test_codec_is_read_from_the_format(fmt, codec):
    assert codec_of(fmt) == codec


def test_jpeg_round_trip_is_close_and_small():
    from sensor_msgs.msg import CompressedImage

    pixels = picture(240, 320)
    msg = CompressedImage()
    msg.header.frame_id = "Kinect"
    size = fill_compressed_image(msg, pixels, 2.5)
    assert (msg.format, msg.header.stamp.sec, msg.header.stamp.nanosec, msg.header.frame_id) == (
        "rgb8; jpeg compressed bgr8",
        2,
        500_000_000,
        "Kinect",
    )
    assert size == len(msg.data) < pixels.nbytes / 20
    back = compressed_to_array(msg)
    assert back.shape == pixels.shape and back.dtype == np.uint8
    assert np.abs(back.astype(int) - pixels).mean() < 3
    # A lower quality makes a smaller file.
    assert len(encode_picture(pixels, "jpeg", 30)) < len(encode_picture(pixels, "jpeg", 95))


def test_png_round_trip_is_exact():
    from sensor_msgs.msg import CompressedImage

    pixels = np.random.default_rng(7).integers(0, 256, (24, 32, 3), dtype=np.uint8)
    msg = CompressedImage()
    fill_compressed_image(msg, pixels, 0.0, "png")
    assert msg.format == "rgb8; png compressed bgr8"
    np.testing.assert_array_equal(compressed_to_array(msg), pixels)


def test_encode_refuses_bad_arguments():
    with pytest.raises(ValueError, match="quality"):
        encode_picture(picture(), "jpeg", 0)
    with pytest.raises(ValueError, match="codec"):
        encode_picture(picture(), "gif")
    with pytest.raises(ValueError, match="uint8"):
        encode_picture(picture().astype(np.float32))


def hostile_messages() -> dict[str, tuple[object, str]]:
    """name -> (message, how the error begins)."""
    jpeg = file_bytes(picture(), "JPEG")
    return {
        "unknown codec": (message("rgb8; h264 compressed bgr8", jpeg), "format"),
        "no codec": (message("", jpeg), "format"),
        "compressedDepth": (message("16UC1; compressedDepth png", jpeg), "format"),
        "empty data": (message("rgb8; jpeg compressed bgr8", b""), "data has 0 bytes"),
        "png said, jpeg sent": (message("rgb8; png compressed bgr8", jpeg), "format says png but data is jpeg"),
        "garbage": (message("rgb8; jpeg compressed bgr8", b"\xff\xd8" + bytes(200)), "jpeg data does not decode"),
        "truncated": (message("rgb8; jpeg compressed bgr8", jpeg[: len(jpeg) // 2]), "jpeg data does not decode"),
        "too wide": (
            message("rgb8; png compressed bgr8", file_bytes(np.zeros((1, 9000, 3), np.uint8), "PNG")),
            "width 9000",
        ),
    }


@pytest.mark.parametrize("name", list(hostile_messages()))
def test_hostile_messages_are_rejected_with_a_reason(name):
    msg, start = hostile_messages()[name]
    with pytest.raises(ImageError) as info:
        compressed_to_array(msg)
    assert str(info.value).startswith(start), str(info.value)


def test_the_receiver_takes_the_compressed_topic_and_counts_rejections(node):
    receiver = ImageReceiver(node, "/test_compressed/image", "compressed")
    assert receiver.topic == "/test_compressed/image/compressed" and receiver.transport == "compressed"
    assert ImageReceiver(node, "/test_compressed/other/compressed").transport == "compressed"
    good = message("rgb8; png compressed bgr8", file_bytes(picture(), "PNG"))
    good.header.frame_id = "Kinect"
    receiver.on_image(good)
    hostile = hostile_messages()
    for msg, _ in hostile.values():
        receiver.on_image(msg)  # no exception escapes: the spin thread would stop
    counts = receiver.counts()
    assert counts["accepted"] == 1 and counts["rejected"] == len(hostile)
    newest = receiver.newest()
    np.testing.assert_array_equal(newest.pixels, picture())
    assert newest.encoding == "rgb8; png compressed bgr8" and newest.size == len(good.data)
    line = format_image_status(counts, 1.0, newest)
    assert "64x48 rgb8; png compressed bgr8 (" in line and "kB) frame Kinect" in line
