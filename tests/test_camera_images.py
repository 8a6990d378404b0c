"""Reading a received sensor_msgs/Image: every field is checked; a bad message is counted, never drawn.

Also the notebooks' live picture (:class:`tutorial.notebook.live_image.LiveImage`).
"""

from array import array

import numpy as np
import pytest
from sensor_msgs.msg import Image

from tutorial.interfaces.image import ImageError, image_to_array
from tutorial.tools.image_files import PngWriter, format_image_status, png_bytes
from tutorial.view.images import ImageReceiver

from conftest import wait_until


def make_image(pixels: np.ndarray, encoding: str = "rgb8", pad: int = 0) -> Image:
    """A sensor_msgs/Image of an (H, W, C) uint8 array, each row followed by ``pad`` bytes."""
    h, w, c = pixels.shape
    rows = pixels.reshape(h, w * c)
    if pad:
        rows = np.concatenate([rows, np.full((h, pad), 77, np.uint8)], axis=1)
    msg = Image()
    msg.height, msg.width, msg.encoding, msg.step = h, w, encoding, w * c + pad
    msg.data = array("B", rows.tobytes())
    return msg


def picture(h=4, w=5, c=3) -> np.ndarray:
    return np.arange(h * w * c, dtype=np.uint8).reshape(h, w, c)


def test_rgb8_is_read_as_it_is_and_shares_no_memory():
    pixels = picture()
    msg = make_image(pixels)
    out = image_to_array(msg)
    assert out.shape == (4, 5, 3) and out.dtype == np.uint8
    np.testing.assert_array_equal(out, pixels)
    msg.data[0] = 255  # the message changes afterwards: the array does not
    assert out[0, 0, 0] == 0


def test_row_padding_is_skipped():
    pixels = picture()
    np.testing.assert_array_equal(image_to_array(make_image(pixels, pad=3)), pixels)


@pytest.mark.parametrize(
    "encoding, channels, expected",
    [
        ("bgr8", 3, lambda p: p[:, :, ::-1]),
        ("rgba8", 4, lambda p: p[:, :, :3]),
        ("bgra8", 4, lambda p: p[:, :, 2::-1]),
        ("mono8", 1, lambda p: np.repeat(p, 3, axis=2)),
    ],
)
def test_other_encodings_become_rgb(encoding, channels, expected):
    pixels = picture(c=channels)
    np.testing.assert_array_equal(image_to_array(make_image(pixels, encoding)), expected(pixels))


def hostile_messages():
    good = make_image(picture())
    cases = {}

    def case(name, **fields):
        msg = make_image(picture())
        for k, v in fields.items():
            setattr(msg, k, v)
        cases[name] = msg

    case("unknown encoding", encoding="yuv422")
    case("16-bit encoding", encoding="rgb16")
    case("empty encoding", encoding="")
    case("short data", data=array("B", bytes(len(good.data) - 1)))
    case("long data", data=array("B", bytes(len(good.data) + 1)))
    case("no data", data=array("B"))
    case("step shorter than a row", step=14)
    case("step longer than the data", step=16)
    case("zero height", height=0)
    case("zero width", width=0)
    case("huge width", width=100_000, step=300_000)
    case("height and width swapped", height=5, width=4)
    return cases


@pytest.mark.parametrize("name", list(hostile_messages()))
def test_a_hostile_image_raises_image_error_naming_the_field(name):
    msg = hostile_messages()[name]
    with pytest.raises(ImageError) as info:
        image_to_array(msg)
    field = {
        "unknown encoding": "encoding",
        "16-bit encoding": "encoding",
        "empty encoding": "encoding",
        "short data": "data",
        "long data": "data",
        "no data": "data",
        "step shorter than a row": "step",
        "step longer than the data": "data",
        "zero height": "height",
        "zero width": "width",
        "huge width": "width",
        "height and width swapped": "data",
    }[name]
    assert str(info.value).startswith(field), str(info.value)


def test_the_receiver_counts_rejections_and_keeps_the_newest_good_picture(node):
    receiver = ImageReceiver(node, "/test_camera_images/image")
    assert receiver.newest() is None
    good = make_image(picture())
    good.header.stamp.sec, good.header.stamp.nanosec = 3, 250_000_000
    good.header.frame_id = "Kinect"
    receiver.on_image(good)
    hostile = hostile_messages()
    for msg in hostile.values():
        receiver.on_image(msg)  # no exception escapes: the spin thread would stop
    counts = receiver.counts()
    assert counts["accepted"] == 1 and counts["rejected"] == len(hostile)
    assert counts["last_error"].startswith("data has 60 bytes")  # the last one: height and width swapped
    newest = receiver.newest()
    assert (newest.stamp, newest.frame_id, newest.encoding, newest.number) == (3.25, "Kinect", "rgb8", 1)
    np.testing.assert_array_equal(newest.pixels, picture())
    line = format_image_status(counts, 1.0, newest)
    assert "5x4 rgb8 frame Kinect" in line and f"rejected: {len(hostile)} (last: data has 60" in line


def test_png_bytes_round_trip():
    import io

    from matplotlib.image import imread

    pixels = picture(6, 7)
    back = imread(io.BytesIO(png_bytes(pixels)), format="png")
    np.testing.assert_array_equal((back[:, :, :3] * 255).round().astype(np.uint8), pixels)
    with pytest.raises(ValueError):
        png_bytes(pixels[:, :, 0])


def test_png_writer_keeps_disk_use_bounded(tmp_path):
    single = PngWriter(str(tmp_path / "one.png"))
    for _ in range(5):
        assert single.write(picture()) == str(tmp_path / "one.png")
    numbered = PngWriter(str(tmp_path / "frames" / "f_{n:02d}.png"), max_files=3)
    written = [numbered.write(picture()) for _ in range(5)]
    assert written[3:] == [None, None]
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["f_00.png", "f_01.png", "f_02.png", "frames", "one.png"]
    with pytest.raises(ValueError, match="directory"):
        PngWriter(str(tmp_path))
    with pytest.raises(ValueError, match="pattern"):
        PngWriter(str(tmp_path / "f_{n:xyz}.png"))


@pytest.mark.filterwarnings("ignore:FigureCanvasAgg is non-interactive")
def test_the_window_shows_the_newest_picture_and_its_stamp():
    import time

    import matplotlib

    matplotlib.use("Agg")  # the window's code, drawn off screen
    import matplotlib.pyplot as plt

    from tutorial.tools.rtt_image import _Viewer, build_parser
    from tutorial.view.images import ReceivedImage

    class Receiver:  # what the subscription would have received
        topic = "/Tank/camera/image"
        image = ReceivedImage(picture(24, 32), 1.5, "Kinect", "rgb8", 7)

        def newest(self):
            return self.image

        def counts(self):
            return {"accepted": 7, "rejected": 0, "last_error": None}

    viewer = _Viewer(Receiver(), build_parser().parse_args([]), None)
    try:
        viewer.run_window(deadline=time.monotonic() + 0.3)
        ax = plt.gcf().axes[0]
        np.testing.assert_array_equal(ax.images[0].get_array(), picture(24, 32))
        assert ax.get_title() == "/Tank/camera/image  t = 1.500 s  (Kinect)"
        assert viewer.shown == 7
    finally:
        plt.close("all")


def test_the_notebook_live_image_redraws_in_place_and_keeps_the_last_picture_when_closed(node, monkeypatch):
    """LiveImage (notebook 06): subscribes best effort, redraws when a picture arrives, says stopped on reset()."""
    import IPython.display

    from tutorial.interfaces.image import camera_image_qos
    from tutorial.notebook import session
    from tutorial.notebook.live_image import LiveImage

    class Handle:  # what display(..., display_id=True) returns in a kernel
        def __init__(self):
            self.updates = 0

        def update(self, obj):
            self.updates += 1

    handle = Handle()
    monkeypatch.setattr(IPython.display, "display", lambda obj, display_id=False: handle)
    topic = "/test_live_image/image"
    live = LiveImage(topic, node_name="test_live_image")
    drawn: list[str] = []  # the state of each picture drawn into the output
    render = live.render
    monkeypatch.setattr(live, "render", lambda state="live": (drawn.append(state), render(state))[1])
    try:
        assert live in session._active  # reset() will close it
        live.show()
        assert live.newest() is None
        assert live.figure().axes[0].get_title() == f"{topic} (live)"
        publisher = node.create_publisher(Image, topic, camera_image_qos())
        msg = make_image(picture(24, 32))
        msg.header.stamp.sec, msg.header.stamp.nanosec = 2, 500_000_000
        msg.header.frame_id = "Kinect"

        def arrived():
            publisher.publish(msg)  # best effort: sent again until one arrives
            return live.received() >= 1

        assert wait_until(arrived, timeout=20, poll=0.1)
        np.testing.assert_array_equal(live.newest().pixels, picture(24, 32))
        assert live.figure().axes[0].get_title() == f"{topic}  t = 2.50 s\n(live)"
        assert wait_until(lambda: handle.updates >= 1, timeout=5)  # the refresh thread redrew it
        node.destroy_publisher(publisher)
    finally:
        session.reset()
    assert live.closed and live not in session._active
    assert not live._thread.is_alive()
    updates = handle.updates
    assert updates >= 2 and drawn[-1] == "stopped: the last picture received", drawn
    assert drawn.count("live") == updates  # shown once, then redrawn only for a new picture
    live.close()  # a second close does nothing
    assert handle.updates == updates
