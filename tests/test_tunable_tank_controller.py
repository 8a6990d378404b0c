"""Notebook 10's controller in this process, on a real rclpy node: the speed limit judged and used, the reset.

The test thread plays the simulation thread (``control()`` then
``mj_step``); the parameter sets go through the node's own
``set_parameters`` (what its parameter service calls), and the reset
service's callback runs on a thread of its own, as the spin thread would.
The last test runs it as a learner does: ``rtt-run project/step10.yaml``,
changed with ``rtt-ros2`` (in a module of its own: no other simulation
publishes ``/Tank/odom`` meanwhile).
"""

from __future__ import annotations

import threading
import time

import mujoco
import numpy as np
import pytest
from rclpy.parameter import Parameter
from sensor_msgs.msg import Joy

from tutorial.controllers.tunable_tank_controller import MAX_TRACK_SPEED, RttTunableTankController
from tutorial.core.body import Body
from tutorial.core.controller import ControllerConfig, ControllerIO
from tutorial.core.world import ModelEntry, build_world

from conftest import MODEL, module_command, ros2

LIMIT = "RttTunableTankController.max_track_speed"
FORWARD = Joy(axes=[0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], buttons=[0] * 8)


@pytest.fixture
def tank(ros, request):
    """A configured, initialized controller on the tank: ``(controller, model, data, node)``; unconfigured after."""
    node = ros.create_node("test_tunable_" + request.node.name[5:40].replace("[", "_").replace("]", ""))
    model = build_world([ModelEntry("Room", MODEL / "room.xml"), ModelEntry("Tank", MODEL / "tank.xml")])
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    controller = RttTunableTankController()
    config = ControllerConfig(name="RttTunableTankController", body=Body(model, data, "Tank"), node=node)
    assert controller.configure(config)
    body = Body(model, data, "Tank")
    assert controller.initialize(ControllerIO(body=body, time_step=model.opt.timestep, node=node, data=data))
    yield controller, model, data, node
    controller.unconfigure()
    node.destroy_node()


def step(controller, model, data, n: int = 1) -> None:
    for _ in range(n):
        assert controller.control()
        mujoco.mj_step(model, data)


def test_a_speed_limit_is_judged_then_used_from_the_next_step(tank):
    controller, model, data, node = tank
    controller.on_joy(FORWARD)
    step(controller, model, data)
    assert [t.dq_target for t in controller.tracks] == [2.0, 2.0]  # Step 1's full stick, under the 3.0 default
    for bad in (-1.0, 3.5, float("nan"), float("inf")):
        result = node.set_parameters([Parameter(LIMIT, value=bad)])[0]
        assert not result.successful and result.reason == f"{LIMIT} must be from 0.0 to 3.0 m/s, got {bad!r}"
    assert node.get_parameter(LIMIT).value == MAX_TRACK_SPEED and controller.refused == 4
    step(controller, model, data)
    assert [t.dq_target for t in controller.tracks] == [2.0, 2.0]  # nothing refused was used
    assert node.set_parameters([Parameter(LIMIT, value=0.5)])[0].successful
    step(controller, model, data)
    assert [t.dq_target for t in controller.tracks] == [0.5, 0.5]
    assert node.set_parameters([Parameter(LIMIT, value=0.0)])[0].successful  # the tracks held still
    step(controller, model, data)
    assert [t.dq_target for t in controller.tracks] == [0.0, 0.0]
    assert node.set_parameters([Parameter(LIMIT, value=3.0)])[0].successful  # raised again: at once, no new Joy
    step(controller, model, data)
    assert [t.dq_target for t in controller.tracks] == [2.0, 2.0]
    # full stick forward and to the left: (1.0, 3.0) asked; under 1.5 m/s both halved, so it still turns
    controller.on_joy(Joy(axes=[1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], buttons=[0] * 8))
    assert node.set_parameters([Parameter(LIMIT, value=1.5)])[0].successful
    step(controller, model, data)
    assert [t.dq_target for t in controller.tracks] == [0.5, 1.5]
    # an integer is refused by rclpy itself: the parameter was declared as a float
    assert not node.set_parameters([Parameter(LIMIT, value=1)])[0].successful


def test_the_reset_waits_for_the_simulation_thread_and_puts_the_tank_back(tank):
    controller, model, data, node = tank
    from std_srvs.srv import Trigger

    for _ in range(20):  # 1 s of full stick, repeated at 20 Hz as rtt-joy does
        controller.on_joy(FORWARD)
        step(controller, model, data, 50)
    assert data.qpos[0] > 0.5, data.qpos[:3]  # driven forward
    answers, errors = [], []

    def spin_thread() -> None:
        try:
            answers.append(controller.on_reset(Trigger.Request(), Trigger.Response()))
        except BaseException as exc:  # noqa: BLE001 - asserted none below
            errors.append(exc)

    caller = threading.Thread(target=spin_thread)
    caller.start()
    deadline = time.monotonic() + 10
    while not controller.resets:  # the callback's request is taken at the first step after it was left
        assert time.monotonic() < deadline and caller.is_alive(), errors
        step(controller, model, data)
    caller.join(timeout=5)
    assert not errors and not caller.is_alive() and controller.resets == 1
    assert answers[0].success and answers[0].message.startswith("back at the start at t = ")
    # one step after the reset, from qpos0 at rest: the tank is where the model put it, within a step's drive
    tank_free = model.jnt_qposadr[model.body_jntadr[Body(model, data, "Tank").root_id]]
    assert np.allclose(data.qpos[tank_free : tank_free + 3], model.qpos0[tank_free : tank_free + 3], atol=0.005)


def test_a_reset_with_no_simulation_step_is_refused_and_taken_back(tank):
    controller, model, data, node = tank
    from std_srvs.srv import Trigger

    answer = controller.on_reset(Trigger.Request(), Trigger.Response())  # nobody steps: waits RESET_TIMEOUT
    assert not answer.success and "did not step within 1.0 s" in answer.message
    assert controller._reset_wanted is None  # taken back
    step(controller, model, data)
    assert controller.resets == 0  # so a later step does not reset


def test_unconfigure_gives_the_node_back_as_it_was(ros):
    """In a notebook the node outlives the controller: a second configure on it works, and a bad
    ``--ros-args -p`` value is refused at configure, saying why."""
    node = ros.create_node("test_tunable_unconfigure")
    model = build_world([ModelEntry("Room", MODEL / "room.xml"), ModelEntry("Tank", MODEL / "tank.xml")])
    data = mujoco.MjData(model)
    try:
        for _ in range(2):
            controller = RttTunableTankController()
            config = ControllerConfig(name="RttTunableTankController", body=Body(model, data, "Tank"), node=node)
            assert controller.configure(config)
            assert node.has_parameter(LIMIT) and any(s.srv_name == "/Tank/reset" for s in node.services)
            controller.unconfigure()
            assert not node.has_parameter(LIMIT) and not any(s.srv_name == "/Tank/reset" for s in node.services)
            assert node.set_parameters([Parameter("use_sim_time", value=False)])[0].successful  # no callback left
    finally:
        node.destroy_node()
    overridden = ros.create_node("test_tunable_override", parameter_overrides=[Parameter(LIMIT, value=-2.0)])
    try:
        logged = []

        class Log:
            def error(self, text, *args):
                logged.append(text % args if args else text)

        body = Body(model, data, "Tank")
        config = ControllerConfig(name="RttTunableTankController", body=body, node=overridden, log=Log())
        assert not RttTunableTankController().configure(config)
        assert logged == [f"{LIMIT} must be from 0.0 to 3.0 m/s, got -2.0"]
        assert not overridden.has_parameter(LIMIT)
    finally:
        overridden.destroy_node()


@pytest.mark.more  # make test runs notebook 10 under nbval: the limit set live, rtt-ros2 param set, the reset
def test_param_set_and_service_call_change_the_running_tank(ros):
    """Notebook 10's controller under ``rtt-run project/step10.yaml``: ``param set`` slows the driving tank
    down (its odometry's speed), a bad value is refused with the controller's reason and changes nothing, and
    ``service call /Tank/reset`` puts it back where it started."""
    import time

    from nav_msgs.msg import Odometry
    from rclpy.executors import SingleThreadedExecutor
    from sensor_msgs.msg import Joy

    from tutorial.interfaces import joy

    from conftest import Proc

    limit = "RttTunableTankController.max_track_speed"
    sim = Proc(module_command("tutorial.tools.rtt_run", "project/step10.yaml", "--headless", "--json"))
    node = ros.create_node("test_tunable_tank")
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    newest: list[Odometry] = []
    node.create_subscription(Odometry, "/Tank/odom", newest.append, 10)
    stick = node.create_publisher(Joy, joy.TOPIC, joy.joy_publisher_qos())
    forward = Joy(axes=[0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], buttons=[0] * joy.NUM_BUTTONS)
    pushing = threading.Event()
    errors: list[BaseException] = []

    def spin_and_push() -> None:  # the stick repeated at 20 Hz while pushing, as rtt-joy does
        try:
            while not stopped.is_set():
                executor.spin_once(timeout_sec=0.05)
                if pushing.is_set():
                    stick.publish(forward)
        except BaseException as exc:  # noqa: BLE001 - asserted none below
            errors.append(exc)

    stopped = threading.Event()
    spinner = threading.Thread(target=spin_and_push, daemon=True)
    spinner.start()

    def odometry_after(seconds: float) -> Odometry:
        """The newest odometry once ``seconds`` of simulated time have passed since the newest now."""
        deadline = time.monotonic() + 30
        while not newest:
            assert time.monotonic() < deadline and sim.p.poll() is None, sim.err
            time.sleep(0.05)
        start = newest[-1].header.stamp.sec + newest[-1].header.stamp.nanosec * 1e-9
        while newest[-1].header.stamp.sec + newest[-1].header.stamp.nanosec * 1e-9 < start + seconds:
            assert time.monotonic() < deadline and sim.p.poll() is None, sim.err
            time.sleep(0.05)
        return newest[-1]

    try:
        odometry_after(0.0)  # the simulation is up
        pushing.set()
        assert abs(odometry_after(0.6).twist.twist.linear.x - 2.0) < 0.1  # full stick: 2 m/s, the default limit
        pushing.clear()  # (the room's walls are 3 m away)
        slowed = ros2("param", "set", "/rtt", limit, "0.5")
        assert slowed.returncode == 0 and slowed.stdout == "Set parameter successful\n", slowed
        called = ros2("service", "call", "/Tank/reset", "std_srvs/srv/Trigger")
        assert (
            called.returncode == 0 and "std_srvs.srv.Trigger_Response(success=True, message='back at" in called.stdout
        )
        at = odometry_after(0.1).pose.pose.position
        assert abs(at.x) < 0.01 and abs(at.y) < 0.01, at  # where the model put it
        pushing.set()
        assert abs(odometry_after(0.5).twist.twist.linear.x - 0.5) < 0.02  # the same stick, limited
        pushing.clear()
        refused = ros2("param", "set", "/rtt", limit, "-1.0")
        assert refused.returncode == 1, refused  # what could not be done
        assert refused.stderr == f"Set parameter failed: {limit} must be from 0.0 to 3.0 m/s, got -1.0\n", refused
        assert ros2("param", "get", "/rtt", limit).stdout == "Double value is: 0.5\n"
        whole = ros2("param", "set", "/rtt", limit, "3")  # an integer, refused by rclpy before any callback
        assert whole.stderr == "Set parameter failed: Wrong parameter type, expected 'Type.DOUBLE' got 'Type.INTEGER'\n"
    finally:
        stopped.set()
        spinner.join(timeout=5)
        executor.shutdown()
        node.destroy_node()
        sim.kill()
    assert not errors and not spinner.is_alive()
