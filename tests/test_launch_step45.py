"""Steps 4 and 5 launch files: every node starts, the IMU flows, and Ctrl-C stops them all cleanly."""

import sys

import pytest

from conftest import ROOT

pytestmark = pytest.mark.launch


def launch(procs, step, *args):
    return procs([sys.executable, "-u", str(ROOT / "launch_py" / f"step{step}_launch.py"), *args])


@pytest.mark.more  # make test: Step 5's launch starts Step 4's IMU publisher too (below), and stops every node
def test_step4_launch_publishes_the_imu_for_its_duration(procs):
    run = launch(procs, 4, "--demo", "--headless", "--duration", "3")
    assert run.wait(60) == 0, run.out
    assert "[rtt] RttImuStatePublisher: topic=/Tank/imu, rate=20.0, frame_id=CHASSIS, published=60" in run.out
    assert "[launch] all nodes stopped cleanly" in run.out


def test_step5_launch_shows_the_imu_in_the_viewer_and_stops_on_ctrl_c(procs):
    import signal

    run = launch(procs, 5, "--demo", "--headless")
    # A status line of the viewer's IMU subscriber with messages arriving: "... /Tank/imu: 20.0 msg/s, ..."
    run.wait_for_line(
        lambda line: (
            line.startswith("[rtt_viewer]") and "/Tank/imu: " in line and "msg/s" in line and " 0.0 msg/s" not in line
        ),
        timeout=60,
    )
    run.p.send_signal(signal.SIGINT)
    assert run.wait(15) == 0, run.out
    assert "[launch] all nodes stopped cleanly" in run.out
    assert "Traceback" not in run.out + run.err
    assert "[rtt_viewer] --- summary: project step5, node /rtt_viewer ---" in run.out
    assert "[rtt_viewer] RttImuStateSubscriber: topic=/Tank/imu" in run.out
    assert "[rtt] RttImuStatePublisher: topic=/Tank/imu" in run.out
