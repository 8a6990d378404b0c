"""``rtt-ros2``: the ``ros2`` commands of ROS 2's beginner tutorials, against a running Step 2 simulation.

Each command runs as a learner types it, a process of its own; the
simulation is ``rtt-run project/step2.yaml --describe`` (50 Hz joint states, its odometry, its
controllers' parameters on the node ``/rtt``).
"""

from __future__ import annotations

import re
import threading

import pytest
import yaml

from conftest import module_command, ros2


@pytest.fixture(scope="module")
def step2():
    """A Step 2 simulation for the module's commands, stopped with Ctrl-C at the end."""
    import time

    from conftest import Proc

    sim = Proc(module_command("tutorial.tools.rtt_run", "project/step2.yaml", "--headless", "--json", "--describe"))
    try:  # stopped also when it never came up: a simulation left running costs every later test
        deadline = time.monotonic() + 60
        while "Publisher count: 1" not in ros2("topic", "info", "/Tank/joint_state").stdout:
            assert time.monotonic() < deadline and sim.p.poll() is None, sim.err  # each try discovers for 2 s
        yield sim
    finally:
        sim.kill()


def test_topic_echo_against_a_running_simulation(step2):
    """make test's case of a command against a running node: ``topic echo --once`` prints ros2cli's YAML."""
    echoed = ros2("topic", "echo", "/Tank/joint_state", "--once", timeout=30)
    assert echoed.returncode == 0 and echoed.stdout.endswith("\n---\n"), echoed
    state = yaml.safe_load(echoed.stdout.removesuffix("---\n"))
    assert list(state) == ["header", "name", "position", "velocity", "effort"]
    assert state["name"] == ["TURRET_Y", "TURRET_P"] and "  frame_id: ''\n" in echoed.stdout


@pytest.mark.more  # make test keeps test_topic_echo_against_a_running_simulation
def test_the_beginner_commands_against_a_running_simulation(step2):
    """node, topic, service and param, as the Beginner CLI tutorials use them, each checked on what it printed."""
    listed = ros2("node", "list")
    assert listed.returncode == 0 and "/rtt" in listed.stdout.split(), listed
    assert "rtt_ros2" not in listed.stdout  # the command's own node is not a node of the system
    info = ros2("node", "info", "/rtt").stdout
    assert "  Publishers:\n" in info and "    /Tank/joint_state: sensor_msgs/msg/JointState\n" in info, info
    assert "  Subscribers:\n    /joy: sensor_msgs/msg/Joy\n" in info, info
    assert "  Service Clients:\n\n  Action Servers:\n\n" in info, info  # an empty section: an empty line
    topics = ros2("topic", "list", "-t").stdout.splitlines()
    assert "/Tank/joint_state [sensor_msgs/msg/JointState]" in topics and "/joy [sensor_msgs/msg/Joy]" in topics
    described = ros2("topic", "info", "/Tank/joint_state").stdout
    assert described.startswith("Type: sensor_msgs/msg/JointState\nPublisher count: 1\n"), described

    # echo: ros2cli's YAML, fields in the message's order, each message ended by ---
    echoed = ros2("topic", "echo", "/Tank/joint_state", "--once", timeout=30)
    assert echoed.returncode == 0 and echoed.stdout.endswith("\n---\n"), echoed
    state = yaml.safe_load(echoed.stdout.removesuffix("---\n"))
    assert list(state) == ["header", "name", "position", "velocity", "effort"]
    assert list(state["header"]) == ["stamp", "frame_id"] and list(state["header"]["stamp"]) == ["sec", "nanosec"]
    assert state["name"] == ["TURRET_Y", "TURRET_P"] and all(isinstance(q, float) for q in state["position"])
    assert "  frame_id: ''\n" in echoed.stdout and "name:\n- TURRET_Y\n- TURRET_P\n" in echoed.stdout

    # hz: within 2 % of the publisher's 50 Hz (the simulation keeps real time)
    rates = ros2("topic", "hz", "/Tank/joint_state", "--timeout", "3.2", timeout=60).stdout
    measured = [float(r) for r in re.findall(r"average rate: ([0-9.]+)", rates)]
    assert len(measured) >= 3 and re.search(r"\tmin: [0-9.]+s max: [0-9.]+s std dev: [0-9.]+s window: \d+", rates)
    assert abs(measured[-1] - 50.0) <= 1.0, rates

    # param: listed, read, and a controller's parameter refused while it runs, saying how to set it
    names = ros2("param", "list", "/rtt").stdout.split()
    assert {"RttJointStatePublisher.rate", "RttTankController.joy_timeout", "use_sim_time"} <= set(names), names
    assert ros2("param", "get", "/rtt", "RttJointStatePublisher.rate").stdout == "Double value is: 50.0\n"
    refused = ros2("param", "set", "/rtt", "RttJointStatePublisher.rate", "10.0")
    assert refused.returncode == 1 and refused.stderr.startswith("Set parameter failed: RttJointStatePublisher.rate")
    assert "--ros-args -p RttJointStatePublisher.rate:=10.0" in refused.stderr
    assert ros2("param", "get", "/rtt", "RttJointStatePublisher.rate").stdout == "Double value is: 50.0\n"
    assert ros2("param", "set", "/rtt", "use_sim_time", "true").stdout == "Set parameter successful\n"
    assert ros2("param", "get", "/rtt", "use_sim_time").stdout == "Boolean value is: True\n"
    assert ros2("param", "get", "/rtt", "no_such").stdout == "Parameter not set.\n"

    # service: the node's own parameter service, called by type
    called = ros2("service", "call", "/rtt/list_parameters", "rcl_interfaces/srv/ListParameters", "{depth: 0}")
    assert called.returncode == 0 and called.stdout.startswith("requester: making request: "), called
    assert "response:\nrcl_interfaces.srv.ListParameters_Response(" in called.stdout
    assert "'RttJointStatePublisher.rate'" in called.stdout


@pytest.mark.more  # make test keeps the other commands against the running simulation
def test_topic_pub_drives_the_tank(step2):
    """``topic pub /joy`` with the left stick pushed: the simulated tank drives forward (Step 1's controller)."""
    before = ros2("topic", "echo", "/Tank/odom", "--once", timeout=30)
    x0 = yaml.safe_load(before.stdout.removesuffix("---\n"))["pose"]["pose"]["position"]["x"]
    sent = ros2(
        "topic", "pub", "/joy", "sensor_msgs/msg/Joy", "{axes: [0.0, 1.0, 0.0, 0.0, 0.0, 0.0]}", "-t", "20", "-r", "20"
    )
    began = "Waiting for at least 1 matching subscription(s)...\npublisher: beginning loop\n"
    assert sent.returncode == 0 and sent.stdout.startswith(began + "publishing #1: sensor_msgs.msg.Joy("), sent
    assert sent.stdout.count("publishing #") == 20
    after = ros2("topic", "echo", "/Tank/odom", "--once", timeout=30)
    x1 = yaml.safe_load(after.stdout.removesuffix("---\n"))["pose"]["pose"]["position"]["x"]
    assert x1 - x0 > 0.05, (x0, x1)  # forward, about 1 s of driving


MORE = pytest.mark.more  # make test keeps the first two cases


@pytest.mark.parametrize(
    "args, says",
    [
        (("topic", "pub", "/joy", "sensor_msgs/msg/Joy", "{axis: [1.0]}"), "axis: Joy has no such field"),
        (("topic", "pub", "/joy", "sensor_msgs/msg/Joy", "{axes: text}"), "axes: 'text' does not fit sequence<float>"),
        pytest.param(("topic", "pub", "/joy", "sensor_msgs/msg/Joi", "{}"), "msg has no type Joi", marks=MORE),
        pytest.param(("topic", "pub", "/joy", "tf2_msgs/msg/TFMessage", "{}"), "no package tf2_msgs", marks=MORE),
        pytest.param(("topic", "pub", "/joy", "sensor_msgs/msg/Joy", "{axes: [1.0"), "message: not YAML", marks=MORE),
        pytest.param(("action", "info", "/Tank/turn_turret"), "not here: rtt-ros2 node info", marks=MORE),
        pytest.param(
            ("action", "send_goal", "/t", "test_msgs/action/Fibonaci", "{}"), "action has no type Fibonaci", marks=MORE
        ),
        pytest.param(
            ("action", "send_goal", "/t", "test_msgs/action/Fibonacci", "{orders: 3}"), "orders: ", marks=MORE
        ),
        pytest.param(("topic", "pub", "/j", "std_srvs/srv/Trigger", "{}"), "a srv type, where a msg", marks=MORE),
        pytest.param(("topic", "pub", "/a b", "sensor_msgs/msg/Joy", "{}"), "Invalid topic name", marks=MORE),
        pytest.param(("param", "set", "/rtt", "x", "'unbalanced"), "the value: not YAML", marks=MORE),
    ],
)
def test_a_bad_command_says_what_is_wrong_in_one_line(ros, args, says):
    done = ros2(*args)
    assert done.returncode == 2 and says in done.stderr and done.stderr.count("\n") == 1, done


def test_what_could_not_be_done_exits_1_saying_why(ros):
    """A command whose request was right but could not be carried out (here: nobody publishes the topic)."""
    done = ros2("topic", "echo", "/nobody_publishes_this", "--once", "--spin-time", "0.3")
    assert done.returncode == 1 and "no publisher of /nobody_publishes_this seen within 0.3 s" in done.stderr, done


@pytest.mark.more  # one more process against the simulation: make test keeps the single node's list
def test_param_list_of_every_node(step2):
    listed = ros2("param", "list").stdout
    assert "/rtt:\n" in listed and "  RttJointStatePublisher.rate\n" in listed, listed


@pytest.mark.more  # a managed node of rclpy's: make test keeps the other commands against a running node
def test_lifecycle_set_walks_every_transition(ros):
    """A managed node (rclpy's LifecycleNode): ``lifecycle set`` takes it through every transition, ``get`` says
    where it is, and a transition its state does not have is refused naming the ones it has."""
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.lifecycle import LifecycleNode

    managed = LifecycleNode("managed_tank")
    executor = SingleThreadedExecutor()
    executor.add_node(managed)
    errors = []

    def spin():
        try:
            executor.spin()
        except Exception as exc:  # noqa: BLE001 - collected: the test asserts there was none
            errors.append(exc)

    thread = threading.Thread(target=spin, daemon=True)
    thread.start()
    try:
        assert ros2("lifecycle", "get", "/managed_tank").stdout == "unconfigured [1]\n"
        refused = ros2("lifecycle", "set", "/managed_tank", "activate")
        assert refused.returncode == 1 and "available ones are: configure, shutdown" in refused.stderr, refused
        for transition, state in (
            ("configure", "inactive [2]"),
            ("activate", "active [3]"),
            ("deactivate", "inactive [2]"),
            ("cleanup", "unconfigured [1]"),
            ("shutdown", "finalized [4]"),
        ):
            assert ros2("lifecycle", "set", "/managed_tank", transition).stdout == "Transitioning successful\n"
            assert ros2("lifecycle", "get", "/managed_tank").stdout == f"{state}\n", transition
    finally:
        executor.shutdown(timeout_sec=5)
        thread.join(timeout=10)
        managed.destroy_node()
    assert errors == [] and not thread.is_alive()


@pytest.mark.more  # make test keeps two commands refused in one line
def test_interface_show_and_what_is_not_here(ros):
    shown = ros2("interface", "show", "sensor_msgs/msg/Joy")
    assert shown.returncode == 0 and "float32[] axes\n" in shown.stdout and "int32[] buttons\n" in shown.stdout
    refused = ros2("launch", "demo_nodes_py", "talker.launch.py")
    assert refused.returncode == 2 and "python launch_py/stepN_launch.py" in refused.stderr, refused


@pytest.mark.unit
def test_messages_print_as_ros2cli_prints_them():
    from geometry_msgs.msg import Twist
    from nav_msgs.msg import Path
    from rcl_interfaces.msg import ParameterValue
    from sensor_msgs.msg import Imu, JointState

    from tutorial.ros.messages import set_fields, to_yaml

    msg = JointState(name=["a"], position=[1.5], velocity=[], effort=[])
    msg.header.stamp.sec = 3
    assert to_yaml(msg) == (
        "header:\n  stamp:\n    sec: 3\n    nanosec: 0\n  frame_id: ''\nname:\n- a\nposition:\n- 1.5\n"
        "velocity: []\neffort: []\n"
    )
    long = JointState(position=[0.0] * 200)
    assert "position:\n- 0.0\n- 0.0\n- 0.0\n- '...'\nvelocity" in to_yaml(long, truncate_length=3)
    twist = Twist()
    set_fields(twist, {"linear": {"x": 2}, "angular": {"z": 1.8}})  # a whole number into a float, as ros2 takes it
    assert twist.linear.x == 2.0 and isinstance(twist.linear.x, float)
    value = ParameterValue()
    set_fields(value, {"type": 5, "byte_array_value": [1, 2, 255]})
    assert "byte_array_value:\n- 1\n- 2\n- 255\n" in to_yaml(value)  # octets as numbers
    for bad, says in (
        ({"orientation_covariance": [1.0] * 8}, r"does not fit double\[9\] \(expected a list of 9\)"),
        ({"linear_acceleration_covariance": [True] * 9}, r"linear_acceleration_covariance\[0\]: True does not fit"),
        ({"orientation": {"x": "a"}}, "orientation.x: 'a' does not fit double"),
    ):
        with pytest.raises(ValueError, match=says):
            set_fields(Imu(), bad)
    path = Path()
    set_fields(path, {"header": {"frame_id": "map"}, "poses": [{"pose": {"position": {"x": 1.0}}}, {}]})
    assert path.header.frame_id == "map" and len(path.poses) == 2 and path.poses[0].pose.position.x == 1.0
    with pytest.raises(ValueError, match=r"poses\[1\]\.pose\.position\.w: Point has no such field"):
        set_fields(Path(), {"poses": [{}, {"pose": {"position": {"w": 1.0}}}]})
