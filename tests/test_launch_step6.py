"""Step 6's launch file: the simulation's camera pictures reach rtt-image; Ctrl-C ends every node cleanly."""

import re
import signal
import sys
import time

import pytest
from matplotlib.image import imread

from conftest import ROOT, wait_until
from test_camera_publisher import egl  # noqa: F401 - the fixture that skips where EGL is missing

pytestmark = pytest.mark.launch


def gone(pid: int) -> bool:
    """Whether a process has ended (a zombie waiting for its parent counts as ended)."""
    try:
        with open(f"/proc/{pid}/status") as f:
            return "State:\tZ" in f.read()
    except FileNotFoundError:
        return True


def test_step6_launch_shows_camera_pictures_and_stops_cleanly(procs, tmp_path, egl):  # noqa: F811
    image = tmp_path / "step6.png"
    launch = procs(
        [
            sys.executable,
            "-u",
            str(ROOT / "launch_py" / "step6_launch.py"),
            "--demo",
            "--headless",
            "--image-output",
            str(image),
        ]
    )
    status = re.compile(
        r"^\[rtt_image\] \[/rtt_image\] [\d.]+ img/s, 320x240 rgb8 frame Kinect, "
        r"newest stamp [\d.]+ s, (\d+) accepted, rejected: none$"
    )
    launch.wait_for_line(lambda line: bool(status.match(line)) and int(status.match(line).group(1)) >= 10, timeout=60)
    assert wait_until(image.exists, timeout=5)  # written once a second
    pids = [int(p) for p in re.findall(r"^\[launch\] started \w+ \(pid (\d+)\)$", launch.out, re.M)]
    assert len(pids) == 3  # rtt_joy, rtt, rtt_image
    started = time.monotonic()
    launch.p.send_signal(signal.SIGINT)
    code = launch.wait(15)
    assert code == 0, launch.out + launch.err
    assert time.monotonic() - started < 5.0 + 1.0
    assert "[launch] all nodes stopped cleanly" in launch.out
    assert "Traceback" not in launch.out + launch.err, launch.out + launch.err
    assert wait_until(lambda: all(gone(p) for p in pids), timeout=2)
    summary = re.search(r"^\[rtt\] RttCameraImagePublisher: .*published=(\d+),", launch.out, re.M)
    assert summary and int(summary.group(1)) >= 10, launch.out
    assert re.search(
        r"^\[rtt_image\] \[/rtt_image\] done: \d+ pictures accepted, 0 rejected, \S+\.png written \d+ times?, "
        r"holding the newest picture$",
        launch.out,
        re.M,
    ), launch.out
    picture = imread(image)
    assert picture.shape[:2] == (240, 320)
