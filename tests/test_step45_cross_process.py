"""Steps 4 and 5 across real processes: the IMU published by the simulation, shown by the viewer."""

import json
import math
import signal

import pytest

from tutorial.ros.spin import SpinThread

from conftest import module_command, wait_until

GRAVITY = 9.80665  # m/s^2
PERIOD_NS = 50_000_000  # 20 Hz


def viewer(procs):
    return procs(
        module_command(
            "tutorial.tools.rtt_run",
            "project/step5.yaml",
            "--headless",
            "--json",
            "--ros-args",
            "-r",
            "__node:=rtt_viewer",
        )
    )


def imu_publishers_seen(view) -> int:
    """The newest count of ``/Tank/imu`` publishers the viewer reported matched (0 before any)."""
    seen = [r for r in view.records("publishers") if r["topic"] == "/Tank/imu"]
    return seen[-1]["count"] if seen else 0


def stamp_ns(msg) -> int:
    return msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec


def stop(proc) -> dict:
    proc.p.send_signal(signal.SIGINT)
    assert proc.wait(30) == 0, proc.err
    return proc.summary()


def test_step4_publishes_the_imu_at_20_hz_of_simulated_time(procs, node):
    from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
    from sensor_msgs.msg import Imu

    received = []
    # Reliable like the publisher, and a deep queue: this test wants every message.
    qos = QoSProfile(depth=100, history=HistoryPolicy.KEEP_LAST, reliability=ReliabilityPolicy.RELIABLE)
    node.create_subscription(Imu, "/Tank/imu", received.append, qos)
    spin = SpinThread(node).start()
    try:
        # No --duration: discovery takes a varying time (one of Fast DDS's ~3 s announcement periods on a
        # loaded machine), so the test does not count on a number of messages within a fixed run. It waits
        # until 41 have arrived from whenever the subscription matched, then stops the simulation.
        sim = procs(module_command("tutorial.tools.rtt_run", "project/step4.yaml", "--headless", "--json"))
        assert wait_until(lambda: len(received) >= 41, timeout=60), (len(received), sim.err)
        summary = stop(sim)
    finally:
        spin.stop()
    assert spin.error is None, spin.error
    imu = summary["controllers"]["RttImuStatePublisher"]
    assert imu["published"] == (summary["steps"] + 49) // 50  # steps 0, 50, 100, ...: one per 0.05 s
    assert imu["frame_id"] == "CHASSIS"
    stamps = [stamp_ns(m) for m in received]
    assert stamps[0] % PERIOD_NS == 0
    assert stamps == list(range(stamps[0], stamps[-1] + 1, PERIOD_NS))  # every 0.05 s, none lost
    assert stamps[-1] <= (imu["published"] - 1) * PERIOD_NS  # nothing received that was not published
    for msg in received:
        assert msg.header.frame_id == "CHASSIS"
        assert msg.orientation_covariance[0] == -1.0
        if msg.header.stamp.sec >= 1:  # resting on the floor, nobody driving
            a = msg.linear_acceleration
            assert (a.x, a.y, a.z) == pytest.approx((0.0, 0.0, GRAVITY), abs=0.01)


def test_driving_into_a_wall_shakes_the_viewer_and_it_ends_where_it_was(procs, node):
    from sensor_msgs.msg import Joy

    view = viewer(procs)
    sim = procs(
        module_command("tutorial.tools.rtt_run", "project/step4.yaml", "--headless", "--duration", "30", "--json")
    )
    stick = [0.0] * 8
    joy = node.create_publisher(Joy, "/joy", 10)

    def publish():
        msg = Joy()
        msg.axes = list(stick)
        msg.buttons = [0] * 8
        joy.publish(msg)

    node.create_timer(0.05, publish)  # the stick state, repeated at 20 Hz like rtt-joy
    spin = SpinThread(node).start()
    try:
        # The viewer must have matched the IMU's publisher before the crash, or it misses it.
        assert wait_until(lambda: imu_publishers_seen(view) >= 1, timeout=30), view.out
        stick[1] = 1.0  # left stick full up: 2 m/s forward, into the east wall 2.7 m ahead
        hit = view.wait_for_line(lambda line: '"event": "shake"' in line, timeout=30)
        stick[1] = 0.0  # stop pushing, so the hits stop and the shake can end
        end = view.wait_for_line(lambda line: '"event": "shake_end"' in line, timeout=30)
    finally:
        spin.stop()
    assert spin.error is None, spin.error  # the Joy timer's callback did not raise
    sim_summary = stop(sim)
    view_summary = stop(view)
    assert view.records("shake")[0]["horizontal_acceleration"] > 20.0, hit
    assert sim_summary["bodies"]["Tank"]["root_position"][0] > 2.4  # the tank is at the wall (x = 3 m)
    shown = view_summary["controllers"]["RttImuStateSubscriber"]
    assert shown["shakes"] >= 1 and not shown["shaking"]
    assert 0.0 < shown["max_shake_offset"] <= 0.02
    assert view.records("shake_end")[0]["position"] == [0.0, 0.0, 0.107], end  # exactly where it was
    assert view_summary["bodies"]["Tank"]["root_position"] == [0.0, 0.0, 0.107]
    assert shown["rejected"] == {}


# (sent acceleration m/s^2, angular velocity rad/s, frame_id) and what the viewer must show after it:
# acceleration arrow (length m, visible), angular-velocity arrow (length m, visible), or the rejection.
ARROWS = [
    ((3.0, 4.0, 9.8), (0.0, 0.0, 0.5), "CHASSIS", (0.5, True), (0.2, True)),
    ((0.0, 0.0, 10.1), (0.02, 0.0, 0.0), "", (0.03, False), (0.008, False)),  # short: hidden
    ((math.nan, 0.0, 9.8), (0.0, 0.0, 0.0), "CHASSIS", "not_finite", None),
    ((0.0, 0.0, 9.8), (0.0, math.inf, 0.0), "CHASSIS", "not_finite", None),
    ((0.0, 0.0, 9806.65), (0.0, 0.0, 0.0), "CHASSIS", "absurd", None),  # mm/s^2
    ((0.0, 0.0, 9.8), (0.0, 0.0, 0.0), "imu_link", "wrong_frame", None),
    ((0.0, 0.0, 4.8), (-1.0, 0.0, 0.0), "CHASSIS", (0.5, True), (0.4, True)),
]


@pytest.mark.more  # make test: the arrows and the rejections in-process (test_imu), the wall's shake across
def test_the_arrows_follow_the_numbers_sent_and_bad_ones_are_counted(procs, node):
    from sensor_msgs.msg import Imu

    from tutorial.interfaces.imu import imu_qos

    view = viewer(procs)
    pub = node.create_publisher(Imu, "/Tank/imu", imu_qos())
    assert wait_until(lambda: pub.get_subscription_count() >= 1, timeout=30)
    assert wait_until(lambda: imu_publishers_seen(view) >= 1, timeout=30), view.out
    shown = ((0.0, False), (0.0, False))
    rejected = {}
    for sent, (accel, gyro, frame, accel_arrow, gyro_arrow) in enumerate(ARROWS, start=1):
        msg = Imu()
        msg.header.frame_id = frame
        msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z = accel
        msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z = gyro
        pub.publish(msg)
        # The next one goes out only when the viewer has handled this one: keep-last-1 cannot drop it.
        line = view.wait_for_line(lambda line: '"event": "imu_status"' in line and handled(line) >= sent, timeout=30)  # noqa: B023
        status = json.loads(line)
        if isinstance(accel_arrow, str):
            rejected[accel_arrow] = rejected.get(accel_arrow, 0) + 1
        else:
            shown = (accel_arrow, gyro_arrow)
        arrows = status["arrows"]
        for arrow, (length, visible) in zip((arrows["acceleration"], arrows["angular_velocity"]), shown):
            assert arrow["length"] == pytest.approx(length, abs=1e-6), line
            assert arrow["visible"] is visible, line
        assert status["rejected"] == dict(sorted(rejected.items())), line
    summary = stop(view)["controllers"]["RttImuStateSubscriber"]
    assert summary["received"] == len(ARROWS)
    assert summary["accepted"] == 3
    assert summary["shakes"] == 0  # 5 m/s^2 sideways is no collision


def handled(line: str) -> int:
    record = json.loads(line)
    return record["accepted"] + sum(record["rejected"].values())


def arrow_pixels(image):
    """Pixels of the red and of the blue arrow (half transparent, over meshcat's blue background)."""
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    red = (r > g + 0.3) & (r > b + 0.3)
    blue = (b > 0.7) & (b > r + 0.4) & (b > g + 0.4) & (g < 0.5)
    return int(red.sum()), int(blue.sum())


@pytest.mark.more  # make test: a recording's arrows appear and hide in Chromium, test_imu
def test_the_viewers_page_draws_the_arrows_and_hides_them(procs, node, tmp_path):
    from sensor_msgs.msg import Imu

    from tutorial.interfaces.imu import imu_qos

    from browser import chromium, screenshot

    if chromium() is None:
        pytest.skip("chromium is not installed (make test installs it)")
    view = procs(
        module_command(
            "tutorial.tools.rtt_run", "project/step5.yaml", "--json", "--ros-args", "-r", "__node:=rtt_viewer"
        )
    )
    url = json.loads(view.wait_for_line(lambda line: '"event": "meshcat"' in line, timeout=60))["url"]
    pub = node.create_publisher(Imu, "/Tank/imu", imu_qos())
    assert wait_until(lambda: pub.get_subscription_count() >= 1, timeout=30)
    assert wait_until(lambda: imu_publishers_seen(view) >= 1, timeout=30), view.out
    pictures = []
    for sent, (accel, gyro) in enumerate(
        [
            ((3.0, 0.0, 12.8), (0.0, 0.0, 1.0)),  # 0.42 m red, 0.4 m blue
            ((0.0, 0.0, 9.8), (0.0, 0.0, 0.0)),
        ],
        start=1,
    ):  # at rest: none
        msg = Imu()
        msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z = accel
        msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z = gyro
        pub.publish(msg)
        view.wait_for_line(lambda line: '"event": "imu_status"' in line and handled(line) >= sent, timeout=30)  # noqa: B023
        pictures.append(arrow_pixels(screenshot(url, tmp_path / f"arrows{sent}.png")))
    (red, blue), (red_after, blue_after) = pictures
    assert red > 100 and blue > 100, pictures
    assert red_after < 10 and blue_after < 10, pictures
