"""Launch files: one command starts every node; Ctrl-C or SIGTERM ends them all, cleanly, in time."""

import os
import signal
import sys
import time
import uuid
from pathlib import Path

import pytest

from tutorial.ros.launch import Launch, LaunchDescription, NodeProcess

from conftest import ROOT, wait_until

pytestmark = pytest.mark.launch


def processes_with_marker(marker: str) -> list[int]:
    """Pids of live processes whose environment holds ``RTT_TEST_MARKER=marker`` (children and grandchildren)."""
    found = []
    needle = f"RTT_TEST_MARKER={marker}".encode()
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            if needle in (entry / "environ").read_bytes():
                status = (entry / "status").read_text()
                if "State:\tZ" not in status:
                    found.append(int(entry.name))
        except OSError:
            continue
    return found


@pytest.mark.parametrize(
    "sig, group",
    [  # make test: Ctrl-C in a terminal, as a learner stops a launch; make test-more: the other two
        pytest.param(signal.SIGINT, False, marks=pytest.mark.more),
        (signal.SIGINT, True),
        pytest.param(signal.SIGTERM, False, marks=pytest.mark.more),
    ],
    ids=["ctrl-c", "ctrl-c-in-a-terminal", "sigterm"],
)
def test_step3_launch_stops_every_node_within_5_s(procs, sig, group):
    """``group``: the signal goes to the launcher's whole process group, as a terminal's Ctrl-C
    does, so every node gets SIGINT twice: from the terminal and from the launcher."""
    marker = uuid.uuid4().hex
    env = dict(os.environ, RTT_TEST_MARKER=marker)
    launch = procs(
        [sys.executable, "-u", str(ROOT / "launch_py" / "step3_launch.py"), "--demo"], env=env, start_new_session=group
    )
    launch.wait_for_line(lambda line: line.startswith("[rtt_viewer]") and "meshcat: open" in line, timeout=60)
    launch.wait_for_line(
        lambda line: (
            line.startswith("[rtt_viewer]")
            and "2/2 joints matched" in line
            and not line.split("] ", 2)[-1].startswith("0.0 msg/s")
        ),
        timeout=60,
    )
    assert len(processes_with_marker(marker)) >= 6  # launcher, 3 nodes, 2 meshcat servers
    started = time.monotonic()
    if group:
        os.killpg(launch.p.pid, sig)
    else:
        launch.p.send_signal(sig)
    code = launch.wait(15)
    elapsed = time.monotonic() - started
    assert code == 0, launch.out
    assert "[launch] all nodes stopped cleanly" in launch.out
    assert "Traceback" not in launch.out + launch.err, launch.out + launch.err
    assert elapsed < 5.0 + 1.0  # the launcher's own start-up of Python is not in its 5 s budget
    assert wait_until(lambda: processes_with_marker(marker) == [], timeout=2.0), processes_with_marker(marker)
    for name in ("rtt_joy", "rtt", "rtt_viewer"):
        assert f"[{name}]" in launch.out
    assert "[rtt_viewer] --- summary: project step3, node /rtt_viewer ---" in launch.out


def test_a_failing_node_fails_the_launch_and_stops_the_others():
    import io

    out = io.StringIO()
    launch = Launch(
        LaunchDescription(
            [
                NodeProcess("rtt_joy", "tutorial.tools.rtt_joy", ["--demo"]),
                NodeProcess(
                    "broken", "tutorial.tools.rtt_run", ["/nonexistent/project.yaml", "--headless"], required=True
                ),
            ]
        ),
        out=out,
    )
    launch.start()
    code = launch.wait()
    text = out.getvalue()
    assert code == 1
    assert "[launch] broken exited with code 2" in text
    assert "[launch] failed: broken (exit 2)" in text
    assert all(p.poll() is not None for p in launch.procs.values())
    assert "cannot read the project file" in text


def test_a_node_hung_in_its_clean_up_says_where_before_it_is_killed(tmp_path, monkeypatch):
    """A node that ignores SIGINT and SIGTERM (as ours do while they clean up) and never ends: the
    launcher names it, its threads' stacks are printed (faulthandler, on SIGABRT), the abort writes
    no core file, and the launch still ends within SHUTDOWN_TIMEOUT s."""
    import io
    import re
    import resource

    from tutorial.ros.launch import SHUTDOWN_TIMEOUT

    # Cores allowed, written as ./core in the node's working folder here (when /proc says "core"):
    # only the launcher's own limit on the node can keep the abort from writing one.
    monkeypatch.chdir(tmp_path)
    soft, hard = resource.getrlimit(resource.RLIMIT_CORE)
    resource.setrlimit(resource.RLIMIT_CORE, (hard, hard))
    out = io.StringIO()
    launch = Launch(LaunchDescription([NodeProcess("hung", "tests.fixtures.hanging_node")]), out=out)
    try:
        launch.start()
        assert wait_until(lambda: "[hung] cleaning up" in out.getvalue(), timeout=20), out.getvalue()
        started = time.monotonic()
        code = launch.shutdown()
        elapsed = time.monotonic() - started
    finally:
        resource.setrlimit(resource.RLIMIT_CORE, (soft, hard))
        for p in launch.procs.values():
            if p.poll() is None:
                p.kill()
    text = out.getvalue()
    assert code == 1, text
    assert re.search(r"\[launch\] hung did not stop within 4\.\d s: sending SIGABRT", text), text
    # faulthandler's dump, line by line through the launcher: the function the node hangs in
    assert "[hung] Current thread" in text, text
    assert "in clean_up_forever" in text, text
    assert "[launch] failed: hung (did not stop: the launcher sent SIGABRT)" in text, text
    assert elapsed < SHUTDOWN_TIMEOUT + 0.5
    assert launch.procs["hung"].returncode == -signal.SIGABRT
    assert list(tmp_path.glob("core*")) == []


@pytest.mark.more  # make test: a recording of a running step, test_bag_replay and test_tf_recording
def test_record_option_records_the_steps_topics_alongside(procs, tmp_path):
    """``--record FILE.mcap`` adds ``rtt-bag record`` (node ``rtt_bag``); the launch's stop closes the file whole.

    With ``--tf`` it also holds what Foxglove draws the tank from: the URDF on
    ``/robot_description``, ``/tf_static`` and ``/tf`` (read back with the ``mcap`` reader
    and ``mcap-ros2-support``'s decoder, as Foxglove reads them).
    """
    from tutorial.tools.bag.info import bag_info
    from tutorial.tools.bag.reader import read_messages

    bag = tmp_path / "launch.mcap"
    launch = procs(
        [
            sys.executable,
            "-u",
            str(ROOT / "launch_py" / "step3_launch.py"),
            "--demo",
            "--headless",
            "--duration",
            "5",
            "--record",
            str(bag),
            "--tf",
        ]
    )
    assert launch.wait(60) == 0, launch.out
    assert "[launch] all nodes stopped cleanly" in launch.out
    assert "Traceback" not in launch.out + launch.err
    assert "[rtt_bag] [/rtt_bag] recording /joy /Tank/joint_state, and TF from every robot description to" in launch.out
    info = bag_info(bag)  # raises unless the file is a whole MCAP file
    assert sorted((t.topic, t.type) for t in info.topics) == [
        ("/Tank/joint_state", "sensor_msgs/msg/JointState"),
        ("/Tank/odom", "nav_msgs/msg/Odometry"),
        ("/Tank/robot_description", "std_msgs/msg/String"),
        ("/joy", "sensor_msgs/msg/Joy"),
        ("/robot_description", "std_msgs/msg/String"),
        ("/tf", "tf2_msgs/msg/TFMessage"),
        ("/tf_static", "tf2_msgs/msg/TFMessage"),
    ]
    assert all(t.count > 0 for t in info.topics), launch.out
    frames = set()
    for topic, _, msg in read_messages(bag, topics=["/tf", "/tf_static", "/robot_description"]):
        if topic == "/robot_description":
            assert '<robot name="Tank">' in msg.data
        else:
            frames |= {(t.header.frame_id, t.child_frame_id) for t in msg.transforms}
    assert {("world", "CHASSIS"), ("CHASSIS", "TURRET_Y"), ("TURRET_Y", "TURRET_P"), ("CHASSIS", "TRACK_L")} <= frames


@pytest.mark.parametrize("name", [f"step{n}_launch.py" for n in range(1, 7)])
def test_help_shows_each_example_on_a_line_of_its_own(name):
    """``--help`` keeps the launch file's example commands as written (argparse's default refills them into one
    paragraph, a learner found)."""
    import ast
    import subprocess

    path = ROOT / "launch_py" / name
    examples = [
        line.rstrip()
        for line in ast.get_docstring(ast.parse(path.read_text()), clean=False).splitlines()
        if line.strip().startswith("python ")
    ]
    assert examples, f"{name} gives no example command"
    shown = subprocess.run(
        [sys.executable, str(path), "--help"], capture_output=True, text=True, timeout=60, check=True
    ).stdout.splitlines()
    assert [line for line in examples if line not in shown] == []
