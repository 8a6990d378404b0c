"""The project's Fast DDS profile (tutorial/ros/fastdds_profiles.xml): named by default, the user's kept, what it
sets, and that Fast DDS reads it without an error.

Unit tier, but for the last test (a ROS 2 node in a process of its own: cross-process).  What the profile does
on a lossy link is tested across hosts: tests/test_network.py, the monitor's rate at 20 % loss."""

from __future__ import annotations

import os
import subprocess
import sys
import xml.etree.ElementTree as ET

import pytest

from tutorial.controllers.joint_state_publisher import DEFAULT_RATE
from tutorial.ros.env import PROFILES_VARIABLE, PROJECT_PROFILES, use_project_profiles_by_default

NS = {"p": "http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles"}


def test_the_project_profile_is_the_default():
    env = {}
    assert use_project_profiles_by_default(env) == str(PROJECT_PROFILES)
    assert env == {"FASTRTPS_DEFAULT_PROFILES_FILE": str(PROJECT_PROFILES)}
    assert PROJECT_PROFILES.is_file()
    empty = {PROFILES_VARIABLE: ""}  # set but empty: Fast DDS would fail to open ""
    assert use_project_profiles_by_default(empty) == str(PROJECT_PROFILES)


def test_a_profile_the_user_named_is_kept():
    env = {PROFILES_VARIABLE: "/home/me/my_profiles.xml"}
    assert use_project_profiles_by_default(env) == "/home/me/my_profiles.xml"
    assert env == {PROFILES_VARIABLE: "/home/me/my_profiles.xml"}


@pytest.mark.cross_process
def test_importing_tutorial_names_it():
    """In a process of its own whose environment has no profiles file."""
    env = {k: v for k, v in os.environ.items() if k != PROFILES_VARIABLE}
    code = "import os, tutorial; print(os.environ['FASTRTPS_DEFAULT_PROFILES_FILE'])"
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=60)
    assert done.returncode == 0 and done.stdout.strip() == str(PROJECT_PROFILES), done.stderr


def seconds(element) -> float:
    return int(element.find("p:sec", NS).text) + int(element.find("p:nanosec", NS).text) * 1e-9


def test_a_lost_joint_state_gets_several_chances_to_be_repaired_before_the_next_one():
    root = ET.parse(PROJECT_PROFILES).getroot()
    [writer] = root.findall("p:data_writer", NS)
    [reader] = root.findall("p:data_reader", NS)
    assert writer.get("is_default_profile") == reader.get("is_default_profile") == "true"
    heartbeat = seconds(writer.find("p:times/p:heartbeatPeriod", NS))
    assert heartbeat <= 1 / DEFAULT_RATE / 4  # at least four heartbeats between two states
    assert seconds(writer.find("p:times/p:nackResponseDelay", NS)) == 0
    assert seconds(reader.find("p:times/p:heartbeatResponseDelay", NS)) == 0
    # The QoS policies stay the code's: no <qos> here, and the camera stays best effort.
    assert root.findall(".//p:qos", NS) == []


def test_a_newcomer_finds_a_running_node_within_a_quarter_second():
    """Fast DDS's 3 s announcement period made a late viewer wait up to 3 s (benchmarks.experiments.late_join)."""
    root = ET.parse(PROJECT_PROFILES).getroot()
    [participant] = root.findall("p:participant", NS)
    assert participant.get("is_default_profile") == "true"
    config = participant.find("p:rtps/p:builtin/p:discovery_config", NS)
    assert seconds(config.find("p:leaseAnnouncement", NS)) <= 0.25
    assert config.find("p:leaseDuration", NS) is None  # the lease stays Fast DDS's 20 s: a pause is no departure


NODE_WITH_A_RELIABLE_PUBLISHER = """
import rclpy
from std_msgs.msg import String
rclpy.init()
node = rclpy.create_node("rtt_profile_check")
node.create_publisher(String, "rtt_profile_check", 1)
node.create_subscription(String, "rtt_profile_check", lambda m: None, 1)
node.destroy_node()
rclpy.shutdown()
print("done")
"""


@pytest.mark.cross_process
@pytest.mark.parametrize("profile", ["ours", "broken"])
def test_fast_dds_reads_the_profile_without_an_error(tmp_path, profile):
    """The broken case proves the check: Fast DDS's XML parser says so (on stdout) and carries on."""
    path = PROJECT_PROFILES
    if profile == "broken":
        path = tmp_path / "broken.xml"
        path.write_text(
            PROJECT_PROFILES.read_text().replace("<nanosec>", "<nanosecs>", 1).replace("</nanosec>", "</nanosecs>", 1)
        )
    env = dict(os.environ, FASTRTPS_DEFAULT_PROFILES_FILE=str(path))
    done = subprocess.run(
        [sys.executable, "-c", NODE_WITH_A_RELIABLE_PUBLISHER], env=env, capture_output=True, text=True, timeout=60
    )
    output = done.stdout + done.stderr  # Fast DDS's log goes to stdout
    assert done.returncode == 0 and done.stdout.endswith("done\n"), output
    if profile == "ours":
        assert "XMLPARSER" not in output and "Error" not in output, output
    else:
        assert "XMLPARSER Error" in output.replace("\x1b[31;1m", "").replace("\x1b[37;1m", "")
