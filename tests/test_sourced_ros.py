"""A ROS 2 installation sourced in the same shell as this environment is detected, with a clear message.

Unit tier, but for the last test (a program of ours in a process of its own: cross-process)."""

from __future__ import annotations

import os
import sys

from tutorial.ros.env import sourced_ros_installation

VENV = "/home/me/ros-tank-tutorial/.venv"
OURS = f"{VENV}/lib/python3.11/site-packages/rclpy/__init__.py"
SOURCED = {
    "AMENT_PREFIX_PATH": "/opt/ros/jazzy",
    "PYTHONPATH": "/opt/ros/jazzy/lib/python3.12/site-packages",
    "LD_LIBRARY_PATH": "/opt/ros/jazzy/opt/rviz_ogre_vendor/lib:/opt/ros/jazzy/lib",
}


def test_nothing_sourced_is_fine():
    assert sourced_ros_installation({}, OURS, VENV) is None
    assert sourced_ros_installation({"PYTHONPATH": "/home/me/src", "LD_LIBRARY_PATH": "/usr/lib"}, OURS, VENV) is None


def test_a_pythonpath_entry_that_holds_this_environment_is_fine():
    # the project's folder on PYTHONPATH, its .venv inside it: the rclpy found is ours
    project = os.path.dirname(VENV)
    assert sourced_ros_installation({"PYTHONPATH": project}, OURS, VENV) is None


def test_the_installations_rclpy_first_is_an_error():
    level, message = sourced_ros_installation(
        SOURCED, "/opt/ros/jazzy/lib/python3.12/site-packages/rclpy/__init__.py", VENV
    )
    assert level == "error"
    assert "AMENT_PREFIX_PATH has /opt/ros/jazzy" in message
    assert "rclpy would be imported from /opt/ros/jazzy/lib/python3.12/site-packages/rclpy" in message
    assert "not sourced /opt/ros/<distro>/setup.bash" in message and "RTT_ALLOW_SOURCED_ROS=1" in message


def test_the_installation_on_the_paths_with_our_rclpy_first_is_a_warning():
    level, message = sourced_ros_installation(SOURCED, OURS, VENV)
    assert level == "warning" and "LD_LIBRARY_PATH has /opt/ros/jazzy/lib" in message


def test_a_workspace_in_ament_prefix_path_counts_too():
    env = {"AMENT_PREFIX_PATH": "/home/me/ws/install/pkg", "PYTHONPATH": "/home/me/ws/install/pkg/lib/python3.12"}
    level, _ = sourced_ros_installation(env, "/home/me/ws/install/pkg/lib/python3.12/rclpy/__init__.py", VENV)
    assert level == "error"


def test_a_program_stops_with_the_message_and_no_traceback(procs, tmp_path):
    """A fake installation whose rclpy shadows ours: rtt-urdf stops at import, exit status 2."""
    fake = tmp_path / "opt_ros" / "lib"
    (fake / "rclpy").mkdir(parents=True)
    (fake / "rclpy" / "__init__.py").write_text("raise ImportError('the wrong rclpy')\n")
    env = {"PATH": "/usr/bin:/bin", "AMENT_PREFIX_PATH": str(tmp_path / "opt_ros"), "PYTHONPATH": str(fake)}
    cmd = [sys.executable, "-m", "tutorial.tools.rtt_urdf", "model/tank.xml", "-o", str(tmp_path / "t.urdf")]
    done = procs(cmd, env=env)
    assert done.wait(60) == 2
    assert done.err.startswith("rtt: ERROR: a ROS 2 installation is sourced in this shell")
    assert "Traceback" not in done.err
