"""``/<body>/robot_description``: checked when received, named by a viewer project instead of a
model file, and the Step 3 monitor drawing the tank from it (and saying so)."""

from __future__ import annotations

import json
import re
import signal

import pytest

from tutorial.core.project import ProjectError, load_project
from tutorial.interfaces.robot_description import DescriptionError, check_robot_description

from conftest import PROJECT, module_command

VIEW = """name: v
models:
  - name: Tank
{model}
    controllers:
      - name: RttJointStateMonitor
        class: tutorial.controllers.joint_state_subscriber:RttJointStateMonitor
{simulator}"""


@pytest.mark.unit
@pytest.mark.parametrize(
    "model, simulator, says",
    [
        ("    description: Tank/robot_description", "", "models[0].description: expected a topic name like /Tank/"),
        ("    description: 12", "", "models[0].description: expected a topic name"),
        ("    description: /Tank/robot description", "", "models[0].description: expected a topic name"),
        (
            "    file: ../model/tank.xml\n    description: /Tank/robot_description",
            "",
            "models[0]: give either file (a model file) or description",
        ),
        ("    yaw: 0", "", "models[0].file: missing: give file (a model file) or description"),
        (
            "    description: /Tank/robot_description",
            "simulator:\n  time_step: 0.001",
            "models[0].description: a simulated model needs a model file",
        ),
        (
            "    description: /Tank/robot_description\n    odometry: Tank/odom",
            "",
            "models[0].odometry: expected a topic",
        ),
        ("    description: /Tank/robot_description\n    odometry: [1]", "", "models[0].odometry: expected a topic"),
        (
            f"    file: {PROJECT.parent / 'model' / 'tank.xml'}\n    odometry: /Tank/odom",
            "simulator:\n  time_step: 0.001",
            "models[0].odometry: a simulated model's root moves by its physics",
        ),
    ],
)
def test_a_project_names_a_description_topic_or_says_what_is_wrong(tmp_path, model, simulator, says):
    path = tmp_path / "p.yaml"
    path.write_text(VIEW.format(model=model, simulator=simulator))
    with pytest.raises(ProjectError) as caught:
        load_project(path)
    assert str(caught.value).startswith(f"{path}: {says}"), str(caught.value)


@pytest.mark.unit
def test_the_description_project_loads():
    project = load_project(PROJECT / "step3_description.yaml")
    [tank] = project.models
    assert tank.file is None and tank.description == "/Tank/robot_description" and project.simulator is None


@pytest.mark.unit
@pytest.mark.parametrize(
    "model, topic",
    [
        ("    description: /Tank/robot_description", "/Tank/robot_description"),
        (f"    file: {PROJECT.parent / 'model' / 'tank.xml'}\n    odometry: /Tank/odom", "/Tank/odom"),
    ],
)
def test_the_lessons_app_refuses_a_model_only_rtt_run_draws(tmp_path, model, topic):
    """The notebooks' App leaves robot descriptions and odometry to the tooling (StandaloneApp, rtt-run): it says
    so, naming the model and the topic, before it builds anything; StandaloneApp takes the same project."""
    from tutorial.app.app import App
    from tutorial.tools.standalone.app import StandaloneApp

    (tmp_path / "v.yaml").write_text(VIEW.format(model=model, simulator=""))
    project = load_project(tmp_path / "v.yaml")
    with pytest.raises(ValueError, match=f"^model Tank takes {topic} from ROS: rtt-run draws it"):
        App(project).prepare_project(project)
    assert App(project).prepare_project(load_project(PROJECT / "step3.yaml")).models[0].file is not None
    assert StandaloneApp(project).description_timeout == 10.0


@pytest.mark.unit
def test_rtt_run_describe_adds_the_robot_model_publisher_to_each_robot_once():
    """``rtt-run --describe``: notebook 09's frozen publisher on the tank (a model with controllers), not on the
    room (scenery); a project that has one already (notebook 10's, or the notebook's own exported class) keeps
    just that one; a viewer's project, which would publish what it listens to, is refused."""
    from tutorial.app.reference.robot_model_publisher import RttRobotModelPublisher
    from tutorial.controllers.robot_model_publisher import RttRobotModelPublisher as Exported
    from tutorial.tools.rtt_run import build_parser, describe_robots

    assert build_parser().parse_args(["p.yaml", "--describe"]).describe
    for name, before in (("step2.yaml", 0), ("step10.yaml", 1)):
        project = describe_robots(load_project(PROJECT / name))
        room, tank = project.models
        publishers = [c for c in tank.controllers if c.cls is RttRobotModelPublisher]
        assert room.controllers == [] and len(publishers) == 1, name
        assert [c.name for c in load_project(PROJECT / name).models[1].controllers].count(publishers[0].name) == before
    own = load_project(PROJECT / "step2.yaml").with_controller("Tank", "RttRobotModelPublisher", Exported)
    assert describe_robots(own).models[1].controllers == own.models[1].controllers
    with pytest.raises(ProjectError, match="step3_description.yaml: --describe publishes a simulation's robots"):
        describe_robots(load_project(PROJECT / "step3_description.yaml"))


@pytest.mark.unit
@pytest.mark.parametrize(
    "text, says",
    [
        ("", "empty"),
        (None, "empty"),
        ("<robot", "not XML"),
        ("<mujoco model='x'/>", "not <robot>"),
        ("<robot><link name='a'/></robot>", "has no name"),
        ("<robot name='r'/>", "has no <link>"),
        ("<robot name='r'><link name='a'/>" + " " * (17 * 1024 * 1024) + "</robot>", "larger than 16 MiB"),
    ],
)
def test_a_received_description_is_checked(text, says):
    with pytest.raises(DescriptionError, match=says):
        check_robot_description(text, "/Tank/robot_description")


def description_error(node_name: str, timeout: float) -> DescriptionError:
    """The error a viewer of ``step3_description.yaml`` fails with when no description reaches it in ``timeout`` s."""
    from tutorial.tools.standalone.app import StandaloneApp

    app = StandaloneApp(
        load_project(PROJECT / "step3_description.yaml"),
        node_name=node_name,
        headless=True,
        output=lambda record: None,
        description_timeout=timeout,
    )
    try:
        with pytest.raises(DescriptionError) as caught:
            app.open()
    finally:
        app.close()
    return caught.value


def test_a_viewer_with_no_description_to_read_says_so(ros, tmp_path):
    """No simulation: the viewer waits its timeout, then fails with one clear line."""
    error = description_error("no_description_viewer", 0.5)
    assert re.search(r"no robot description on /Tank/robot_description within 0.5 s", str(error)), str(error)


def test_a_description_published_volatile_is_named_as_the_cause(ros, capfd):
    """A learner's description publisher with rclpy's default QoS (volatile) cannot reach the transient-local
    subscription: the viewer's error says that, and how to publish it; rclpy's own warning is not printed."""
    from rclpy.qos import QoSProfile
    from std_msgs.msg import String

    node = ros.create_node("volatile_description")
    publisher = node.create_publisher(String, "/Tank/robot_description", QoSProfile(depth=1))
    try:
        error = description_error("viewer_of_a_volatile_description", 2.0)
    finally:
        node.destroy_publisher(publisher)
        node.destroy_node()
    assert "a publisher offers it with an incompatible QoS (durability)" in str(error), str(error)
    assert "transient local" in str(error)
    assert "incompatible QoS" not in capfd.readouterr().err  # rclpy's warning, had no handler been given


def test_the_step3_monitor_draws_the_published_description(procs):
    """rtt-run step3_description.yaml beside a Step 2 simulation: the monitor takes its model from
    /Tank/robot_description, says so, mirrors the simulation's final joint state by name, and stands where
    /Tank/odom puts it."""
    sim = procs(module_command("tutorial.tools.rtt_run", "project/step2.yaml", "--headless", "--json", "--describe"))
    view = procs(
        module_command(
            "tutorial.tools.rtt_run",
            "project/step3_description.yaml",
            "--headless",
            "--json",
            "--ros-args",
            "-r",
            "__node:=rtt_viewer",
        )
    )
    said = json.loads(view.wait_for_line(lambda line: '"event": "description"' in line, timeout=30))
    assert said["topic"] == "/Tank/robot_description" and said["moving_joints"] == ["TURRET_Y", "TURRET_P"]
    assert "no model file of its own: drawing the robot description on /Tank/robot_description" in said["line"]
    view.wait_for_line(lambda line: '"event": "first_state"' in line, timeout=30)
    sim.p.send_signal(signal.SIGINT)
    assert sim.wait(30) == 0, sim.err
    final = sim.summary()["bodies"]["Tank"]
    view.wait_for_line(lambda line: '"event": "stale"' in line, timeout=30)  # silent since the sim ended
    view.p.send_signal(signal.SIGINT)
    assert view.wait(30) == 0, view.err
    shown = view.summary()["controllers"]["RttJointStateMonitor"]
    assert shown["rejected"] == {}
    assert shown["last_positions"] == pytest.approx(final["joint_positions"], abs=1e-9)
    # the root link follows /Tank/odom: the tank stands where the simulation left it
    assert view.summary()["controllers"]["Tank/floating_base"]["rejected"] == {}
    where = view.summary()["bodies"]["Tank"]
    assert where["root_position"] == pytest.approx(final["root_position"], abs=1e-6)
    assert where["root_yaw"] == pytest.approx(final["root_yaw"], abs=1e-6)


ARM = """<robot name="arm">
  <link name="base"><visual><geometry><box size="0.2 0.2 0.1"/></geometry></visual></link>
  <link name="tip"><visual><geometry><cylinder radius="0.02" length="0.3"/></geometry></visual></link>
  <joint name="shoulder" type="revolute"><parent link="{parent}"/><child link="tip"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>"""


def test_a_broken_description_waits_for_a_fixed_one(procs, node, tmp_path):
    """A description whose joint names a parent link that is not there: the monitor says what is wrong, keeps
    running and listening, and draws the corrected description published 2 s later, without a restart."""
    import time

    from sensor_msgs.msg import JointState
    from std_msgs.msg import String

    from tutorial.interfaces.joint_state import joint_state_qos
    from tutorial.interfaces.robot_description import robot_description_qos

    (tmp_path / "arm.yaml").write_text(
        "name: arm\nmodels:\n  - name: Arm\n    description: /Arm/robot_description\n    controllers:\n"
        "      - name: RttJointStateMonitor\n"
        "        class: tutorial.controllers.joint_state_subscriber:RttJointStateMonitor\n"
    )
    description = node.create_publisher(String, "/Arm/robot_description", robot_description_qos())
    description.publish(String(data=ARM.format(parent="shoulder_link")))  # no such link
    view = procs(
        module_command("tutorial.tools.rtt_run", str(tmp_path / "arm.yaml"), "--headless", "--json")
        + ["--ros-args", "-r", "__node:=arm_monitor"]
    )
    warned = json.loads(view.wait_for_line(lambda line: '"event": "warning"' in line, timeout=30))
    assert "/Arm/robot_description" in warned["message"] and "shoulder_link" in warned["message"], warned
    assert warned["message"].endswith("waiting for a corrected description on /Arm/robot_description"), warned
    description.publish(String(data=ARM.format(parent="elbow_link")))  # a second broken one: said too
    view.wait_for_count(lambda line: '"event": "warning"' in line, 2, timeout=30)
    later = time.monotonic() + 2.0
    while time.monotonic() < later:  # the 2 s a person takes to fix the file: the monitor stays up
        assert view.p.poll() is None, view.err
        time.sleep(0.05)
    description.publish(String(data=ARM.format(parent="base")))
    said = json.loads(view.wait_for_line(lambda line: '"event": "description"' in line, timeout=30))
    assert said["moving_joints"] == ["shoulder"] and said["links"] == 2, said
    states = node.create_publisher(JointState, "/Arm/joint_state", joint_state_qos())
    deadline = time.monotonic() + 30
    while not view.count(lambda line: '"event": "first_state"' in line):
        assert time.monotonic() < deadline, view.out
        states.publish(JointState(name=["shoulder"], position=[0.5]))  # sent again until discovery has matched
        time.sleep(0.1)
    view.p.send_signal(signal.SIGINT)
    assert view.wait(30) == 0, view.err
    assert view.count(lambda line: '"event": "warning"' in line) == 2  # once per description, not per retry
    assert view.summary()["controllers"]["RttJointStateMonitor"]["last_positions"] == {"shoulder": 0.5}


@pytest.mark.more  # make test keeps the wait itself (test_a_broken_description_waits_for_a_fixed_one)
def test_ctrl_c_ends_the_wait_for_a_corrected_description(procs, node, tmp_path):
    """Waiting, with no deadline, for a description that can be drawn: one Ctrl-C ends it, cleanly."""
    from std_msgs.msg import String

    from tutorial.interfaces.robot_description import robot_description_qos

    (tmp_path / "arm.yaml").write_text("name: arm\nmodels:\n  - name: Arm\n    description: /Arm/robot_description\n")
    description = node.create_publisher(String, "/Arm/robot_description", robot_description_qos())
    description.publish(String(data=ARM.format(parent="shoulder_link")))
    view = procs(module_command("tutorial.tools.rtt_run", str(tmp_path / "arm.yaml"), "--headless", "--json"))
    view.wait_for_line(lambda line: '"event": "warning"' in line, timeout=30)
    view.p.send_signal(signal.SIGINT)
    assert view.wait(10) == 0, view.err


@pytest.mark.unit
def test_the_rviz_config_draws_the_tank_from_our_topics():
    """rviz/tank.rviz (not run here: no RViz2): YAML with the displays the README's commands rely on."""
    import yaml

    from conftest import ROOT

    config = yaml.safe_load((ROOT / "rviz" / "tank.rviz").read_text())
    manager = config["Visualization Manager"]
    displays = {d["Class"]: d for d in manager["Displays"]}
    model = displays["rviz_default_plugins/RobotModel"]
    assert model["Description Source"] == "Topic"
    assert model["Description Topic"]["Value"] == "/robot_description"
    assert model["Description Topic"]["Durability Policy"] == "Transient Local"  # what robot_state_publisher offers
    assert displays["rviz_default_plugins/Odometry"]["Topic"]["Value"] == "/Tank/odom"
    assert "rviz_default_plugins/TF" in displays
    assert manager["Global Options"]["Fixed Frame"] == "world"
