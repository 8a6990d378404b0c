"""The viewer's meshcat page in a real browser (headless Chromium): the tank is drawn and follows the joint state."""

import json

import numpy as np
import pytest

from browser import chromium, greenish_pixels, screenshot
from conftest import module_command, publish_and_wait_applied, publishers_seen, wait_until

pytestmark = [
    pytest.mark.browser,
    pytest.mark.skipif(chromium() is None, reason="chromium is not installed (make test installs it)"),
]


def test_viewer_page_draws_the_tank_and_follows_the_turret(procs, node, tmp_path):
    from sensor_msgs.msg import JointState

    from tutorial.interfaces.joint_state import joint_state_qos

    view = procs(
        module_command(
            "tutorial.tools.rtt_run", "project/step3.yaml", "--json", "--ros-args", "-r", "__node:=rtt_viewer"
        )
    )
    url = json.loads(view.wait_for_line(lambda line: '"event": "meshcat"' in line, timeout=60))["url"]
    assert url.startswith("http://127.0.0.1:")
    pub = node.create_publisher(JointState, "/Tank/joint_state", joint_state_qos())
    assert wait_until(lambda: pub.get_subscription_count() >= 1, timeout=30)
    # and the viewer's side: until it has matched the publisher, what is sent is dropped
    assert wait_until(lambda: publishers_seen(view) >= 1, timeout=30), view.out

    publish_and_wait_applied(pub, view, ["TURRET_Y", "TURRET_P"], [0.0, 0.0], 1)
    before = screenshot(url, tmp_path / "before.png")
    publish_and_wait_applied(pub, view, ["TURRET_Y", "TURRET_P"], [1.2, 0.6], 2)
    after = screenshot(url, tmp_path / "after.png")

    assert greenish_pixels(before) > 500, "the tank's olive hull is not on the page"
    changed = np.count_nonzero(np.abs(before - after).max(axis=2) > 0.1)
    assert changed > 300, f"only {changed} pixels changed when the turret turned"
    # a broken message changes nothing on the page
    publish_and_wait_applied(pub, view, ["TURRET_Y", "TURRET_P"], [float("nan"), 1e9], 3)
    broken = screenshot(url, tmp_path / "broken.png")
    assert np.count_nonzero(np.abs(after - broken).max(axis=2) > 0.1) < 50


@pytest.mark.more  # make test: the viewer's meshcat page in Chromium (test_viewer_page_draws_the_tank_...)
def test_simulation_page_shows_the_tank_driving(procs, tmp_path):
    joy = procs(module_command("tutorial.tools.rtt_joy", "--demo"))
    sim = procs(module_command("tutorial.tools.rtt_run", "project/step1.yaml", "--json", "--duration", "30"))
    url = json.loads(sim.wait_for_line(lambda line: '"event": "meshcat"' in line, timeout=60))["url"]
    joy.wait_for_line(lambda line: "the demo starts" in line, timeout=30)
    first = screenshot(url, tmp_path / "first.png")
    # the demo drives forward at 0.8 m/s from 0.5 s on: wait for the tank to cover ground (simulated time is real time)
    import time

    time.sleep(2.0)  # not synchronisation: letting the simulation run, so that there is motion to see
    second = screenshot(url, tmp_path / "second.png")
    assert greenish_pixels(first) > 100, "the tank is not on the simulation page"
    changed = np.count_nonzero(np.abs(first - second).max(axis=2) > 0.1)
    assert changed > 100, f"only {changed} pixels changed while the tank drove"
