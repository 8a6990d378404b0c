"""Step 6 across processes: rtt-run publishes camera pictures that another process receives whole."""

import threading

import numpy as np
import pytest

from tutorial.interfaces.compressed_image import compressed_image_qos, compressed_to_array
from tutorial.interfaces.image import camera_image_qos, image_to_array
from tutorial.ros import spin as ros_spin

from conftest import module_command, wait_until
from test_camera_publisher import egl  # noqa: F401 - the fixture that skips where EGL is missing

RATE = 10.0  # Hz of simulated time, set with -p: the parameter reaches the controller
DURATION = 5.0  # s of simulated time
PICTURES = 51  # handed to the render thread: t = 0.0, 0.1, ..., 4.9, and the final picture at 5.0


def test_pictures_arrive_stamped_with_simulation_time_at_the_rate_asked(procs, node, egl):  # noqa: F811
    from sensor_msgs.msg import CompressedImage, Image

    lock = threading.Lock()
    received: list[dict] = []
    compressed: list[dict] = []

    def on_compressed(msg):
        record = {
            "stamp": msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9,
            "frame_id": msg.header.frame_id,
            "format": msg.format,
            "bytes": len(msg.data),
            "pixels": compressed_to_array(msg),
        }
        with lock:
            compressed.append(record)

    def on_image(msg):
        record = {
            "stamp": msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9,
            "frame_id": msg.header.frame_id,
            "fields": (msg.encoding, msg.height, msg.width, msg.step, msg.is_bigendian, len(msg.data)),
            "pixels": image_to_array(msg),
        }
        with lock:
            received.append(record)

    node.create_subscription(Image, "/Tank/camera/image", on_image, camera_image_qos())
    node.create_subscription(CompressedImage, "/Tank/camera/image/compressed", on_compressed, compressed_image_qos())
    spin = ros_spin.SpinThread(node).start()
    try:
        sim = procs(
            module_command(
                "tutorial.tools.rtt_run",
                "project/step6.yaml",
                "--headless",
                "--json",
                "--duration",
                str(DURATION),
                "--ros-args",
                "-p",
                f"RttCameraImagePublisher.rate:={RATE}",
            )
        )
        assert sim.wait(60) == 0, sim.out + sim.err
        assert wait_until(lambda: len(received) > 0 and received[-1]["stamp"] == pytest.approx(DURATION), timeout=5), (
            "the final picture did not arrive"
        )
    finally:
        spin.stop()
    summary = sim.summary()
    camera = summary["controllers"]["RttCameraImagePublisher"]
    assert summary["real_time_factor"] > 0.9  # rendering did not hold the simulation back
    # A picture takes well under the 100 ms period to render, so hardly any is skipped (replaced while waiting).
    assert camera["handed_over"] == PICTURES, camera
    assert camera["published"] + camera["skipped"] == PICTURES and camera["skipped"] <= 4, camera
    assert camera["published_per_sim_s"] == pytest.approx(camera["published"] / DURATION, abs=0.01)
    with lock:
        got = list(received)
    first = round(got[0]["stamp"] * RATE)  # discovery may take the first second or so
    stamps = [r["stamp"] for r in got]
    sent = PICTURES - first - camera["skipped"]  # published from the first that arrived on (skips counted as early)
    assert len(got) >= 0.9 * sent, f"{len(got)} of {sent} pictures arrived"
    assert stamps == sorted(stamps)
    for r in got:
        assert abs(r["stamp"] * RATE - round(r["stamp"] * RATE)) < 1e-6, r["stamp"]  # simulation time, k / 10 s
        assert r["frame_id"] == "Kinect"
        assert r["fields"] == ("rgb8", 240, 320, 960, 0, 240 * 960)
    assert max(float(np.std(r["pixels"])) for r in got) > 20  # pictures, not blank frames
    # The same pictures, JPEG-compressed (image_transport's compressed transport), while subscribed.
    with lock:
        small = {r["stamp"]: r for r in compressed}
    assert camera["compressed"]["format"] == "rgb8; jpeg compressed bgr8"
    assert len(small) >= 0.9 * sent and camera["compressed"]["published"] >= len(small)
    both = [r for r in got if r["stamp"] in small]
    assert len(both) >= 0.8 * len(got)
    for r in both:
        c = small[r["stamp"]]
        assert (c["frame_id"], c["format"]) == ("Kinect", "rgb8; jpeg compressed bgr8")
        assert c["bytes"] < 240 * 960 / 20  # twenty times smaller at least
        assert np.abs(c["pixels"].astype(int) - r["pixels"]).mean() < 4  # the same picture, within JPEG's loss
