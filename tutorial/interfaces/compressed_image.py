"""``/<body>/camera/image/compressed`` (``sensor_msgs/CompressedImage``): the camera's pictures, JPEG or PNG.

Topic :func:`compressed_image_topic`, QoS :func:`compressed_image_qos`;
:func:`fill_compressed_image` encodes a picture into a message and
:func:`compressed_to_array` decodes one back, trusting nothing.

**image_transport's convention.**  ROS's ``image_transport`` publishes
every camera topic ``<base>`` in several *transports*; its ``compressed``
plugin publishes ``<base>/compressed``, a ``sensor_msgs/CompressedImage``
whose ``format`` says what was compressed and how, e.g.
``"rgb8; jpeg compressed bgr8"``: the raw picture's encoding, the codec,
and the channel order the plugin hands to OpenCV (whose encoder writes a
standard JPEG or PNG from it).  :func:`compressed_format` writes that
string the same way, so ``image_transport``'s own subscribers, ``rqt`` and
Foxglove decode our pictures; ``data`` holds the JPEG or PNG file, whole.

* JPEG (the default): lossy, a few kB a picture; ``quality`` 1..100
  (:data:`DEFAULT_JPEG_QUALITY`).  For watching a robot.
* PNG: lossless (every pixel exact), ten times bigger and slower to make.
  For pictures that are measured.

**The encoder** is Pillow, which bundles libjpeg-turbo (and zlib).
simplejpeg (another libjpeg-turbo binding) encodes and decodes this
tutorial's pictures a little faster, but the difference is lost in the time
a picture takes to *render* (``benchmarks/RESULTS.md``, *Choices measured*).
Pillow also writes PNG, is already installed (matplotlib needs it) and is
one of Python's best-kept libraries: Pillow it is.  (PyTurboJPEG needs the
system's libjpeg-turbo 3, which Debian 12 does not have.)
``python -m benchmarks.experiments.network --encoders`` measures them.

**Sharing a thin link with the joint states.**  A raw 320 x 240 rgb8 picture
is 230 400 bytes: 55 Mbit/s at 30 Hz, ten times a 5 Mbit/s link; the link's
queue fills, every state waits in it, and hardly a picture arrives whole.
What keeps the joint states flowing is a budget of three parts, each
measured by ``python -m benchmarks.experiments.network``:

1. *Only what is subscribed crosses the link.*  DDS sends a sample only to
   the readers that matched it, and the publisher encodes a compressed
   picture only while the compressed topic has a subscriber (as
   ``image_transport`` does): a remote viewer of ``.../compressed`` never
   pulls the raw pictures over the link.
2. *Size sets the wait.*  A picture holds the link for
   ``8 x bytes / bandwidth``: a 4 kB JPEG on 5 Mbit/s, 6.4 ms, the longest
   a joint state queues behind it; ``quality`` and ``rate`` set the
   camera's share (3 to 4 kB a picture at quality 80: 0.7 to 1 Mbit/s at
   30 Hz).  The joint states' age at a remote monitor on 5 Mbit/s, with
   this camera and with the raw one, is on the Benchmarks page, *Across
   hosts*.
3. *Best effort, keep last 1* (:func:`compressed_image_qos`): a picture
   that is lost is never sent again, and none waits in a queue behind a
   newer one; a reliable picture topic would resend lost fragments into
   the same link.
"""

from __future__ import annotations

import io
from array import array

import numpy as np

from tutorial.interfaces.image import MAX_SIDE, ImageError, camera_image_qos, camera_image_topic
from tutorial.interfaces.timing import stamp_parts

CODECS = ("jpeg", "png")
DEFAULT_CODEC = "jpeg"
DEFAULT_JPEG_QUALITY = 80  # 1..100: 3 to 4 kB a picture here (image_transport names its parameter jpeg_quality too)
PNG_LEVEL = 1  # zlib level 1..9: 1 is fast (2.6 ms here) and about as small as 9 on rendered pictures
MAX_COMPRESSED_BYTES = 16 * 1024 * 1024  # a bigger message is refused before it is decoded


def compressed_image_topic(body_name: str) -> str:
    """``/<body name>/camera/image/compressed``: image_transport's ``compressed`` transport of the camera."""
    return camera_image_topic(body_name) + "/compressed"


def compressed_image_qos():
    """Best effort, keep last 1, volatile: the raw camera's QoS, for the reasons it gives, and one more.

    On a thin link a lost picture resent (reliable) would compete with the
    joint states for the same link; a picture is worth nothing once the
    next one exists.  See this module's "Sharing a thin link".
    """
    return camera_image_qos()


def compressed_format(codec: str, encoding: str = "rgb8") -> str:
    """The ``format`` image_transport's compressed plugin writes: ``"rgb8; jpeg compressed bgr8"``.

    Args:
        codec: ``"jpeg"`` or ``"png"``.
        encoding: the raw picture's encoding (colour: ``bgr8`` after
            "compressed"; ``mono8``: ``mono8``).

    Raises:
        ValueError: an unknown codec.
    """
    if codec not in CODECS:
        raise ValueError(f"codec {codec!r}: use one of {', '.join(CODECS)}")
    target = "mono8" if encoding == "mono8" else "bgr8"
    return f"{encoding}; {codec} compressed {target}"


def encode_picture(pixels: np.ndarray, codec: str = DEFAULT_CODEC, quality: int = DEFAULT_JPEG_QUALITY) -> bytes:
    """A picture as a JPEG or PNG file's bytes.

    Args:
        pixels: ``(height, width, 3)`` uint8 RGB, rows top to bottom (or ``(height, width)`` gray).
        codec: ``"jpeg"`` or ``"png"``.
        quality: JPEG quality 1..100 (PNG ignores it: it is exact).

    Raises:
        ValueError: an unknown codec, a quality outside 1..100, or not a uint8 picture.

    Pure: any thread may call it.
    """
    from PIL import Image as PilImage

    if codec not in CODECS:
        raise ValueError(f"codec {codec!r}: use one of {', '.join(CODECS)}")
    if not 1 <= int(quality) <= 100:
        raise ValueError(f"JPEG quality must be 1..100, got {quality}")
    if pixels.dtype != np.uint8 or pixels.ndim not in (2, 3) or (pixels.ndim == 3 and pixels.shape[2] != 3):
        raise ValueError(f"expected an (H, W, 3) or (H, W) uint8 array, got {pixels.shape} {pixels.dtype}")
    picture = PilImage.fromarray(pixels)
    out = io.BytesIO()
    if codec == "jpeg":
        picture.save(out, format="JPEG", quality=int(quality))  # 4:2:0 chroma, as OpenCV's default
    else:
        picture.save(out, format="PNG", compress_level=PNG_LEVEL)
    return out.getvalue()


def fill_compressed_image(
    msg, pixels: np.ndarray, time_s: float, codec: str = DEFAULT_CODEC, quality: int = DEFAULT_JPEG_QUALITY
) -> int:
    """Encode a picture into a ``sensor_msgs/CompressedImage`` stamped ``time_s``; its size in bytes.

    ``msg.header.frame_id`` is left as it is.  Any thread may call it, on a
    message no other thread is using.

    Raises:
        ValueError: as :func:`encode_picture`.
    """
    data = encode_picture(pixels, codec, quality)
    msg.header.stamp.sec, msg.header.stamp.nanosec = stamp_parts(time_s)
    msg.format = compressed_format(codec, "mono8" if pixels.ndim == 2 else "rgb8")
    msg.data = array("B", data)  # taken as it is (bytes would be checked byte by byte)
    return len(data)


def codec_of(format_: str) -> str:
    """The codec a ``format`` names: ``"jpeg"`` or ``"png"``.

    Reads image_transport's ``"<encoding>; <codec> compressed <target>"`` and
    the bare ``"jpeg"``/``"png"`` that older publishers write.

    Raises:
        ImageError: the format names no codec this module reads.
    """
    text = str(format_).strip().lower()
    head, _, rest = text.partition(";")
    words = (rest if rest else head).split()
    codec = words[0] if words else ""
    codec = {"jpg": "jpeg"}.get(codec, codec)
    if codec not in CODECS or (rest and words[1:2] != ["compressed"]):
        raise ImageError(
            f"format {str(format_)[:80]!r} is not image_transport's compressed format "
            "('rgb8; jpeg compressed bgr8' or 'rgb8; png compressed bgr8')"
        )
    return codec


def compressed_to_array(msg, max_side: int = MAX_SIDE, max_bytes: int = MAX_COMPRESSED_BYTES) -> np.ndarray:
    """The picture of a ``sensor_msgs/CompressedImage`` as an RGB array.

    Args:
        msg: a ``sensor_msgs.msg.CompressedImage`` (or anything with ``format`` and ``data``).
        max_side: the largest height or width accepted, pixels (checked
            from the file's header, before its pixels are decoded).
        max_bytes: the largest ``data`` accepted.

    Returns:
        A new ``(height, width, 3)`` uint8 array, rows top to bottom, R, G, B.

    Raises:
        ImageError: the format names no known codec, ``data`` is empty, too
            big or not bytes, the file is not the codec the format names, its
            size is outside 1..``max_side``, or it does not decode.

    Pure: any thread may call it.
    """
    from PIL import Image as PilImage

    codec = codec_of(msg.format)
    try:
        data = memoryview(msg.data)
    except TypeError:
        raise ImageError(f"data is a {type(msg.data).__name__}, not a buffer of bytes") from None
    if data.itemsize != 1 or not data.contiguous:
        raise ImageError(f"data is not contiguous bytes (item size {data.itemsize})")
    if not 0 < data.nbytes <= max_bytes:
        raise ImageError(f"data has {data.nbytes} bytes, expected 1..{max_bytes}")
    try:
        with PilImage.open(io.BytesIO(data.tobytes())) as picture:
            found = (picture.format or "").lower()
            if found != codec:
                raise ImageError(f"format says {codec} but data is {found or 'not an image file'}")
            width, height = picture.size
            for name, value in (("height", height), ("width", width)):
                if not 1 <= value <= max_side:
                    raise ImageError(f"{name} {value} is outside 1..{max_side}")
            return np.array(picture.convert("RGB"), dtype=np.uint8)
    except ImageError:
        raise
    except Exception as exc:  # noqa: BLE001 - Pillow raises many kinds on a bad file; each is a rejection
        raise ImageError(f"{codec} data does not decode: {type(exc).__name__}: {exc}") from None
