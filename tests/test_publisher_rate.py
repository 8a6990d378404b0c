"""Step 2's accumulator keeps the publish rate exact over the 1 ms step."""

import pytest

from tutorial.core.period import PeriodAccumulator


def due_steps(time_step, rate, steps):
    acc = PeriodAccumulator(time_step, rate)
    return [k for k in range(steps) if acc.tick()]


def test_50_hz_over_1_ms_is_every_20th_step_exactly():
    due = due_steps(0.001, 50.0, 100_000)  # 100 s of simulated time
    assert len(due) == 5000
    assert set(b - a for a, b in zip(due, due[1:])) == {20}


@pytest.mark.parametrize("rate", [0.0, 1000.0, 5000.0])
def test_every_step_when_rate_is_0_or_at_least_the_step_rate(rate):
    assert len(due_steps(0.001, rate, 1000)) == 1000


def test_uneven_rate_holds_on_average():
    due = due_steps(0.001, 300.0, 30_000)  # period 3.333 ms: steps of 3 and 4
    assert len(due) == pytest.approx(9000, abs=1)
    assert set(b - a for a, b in zip(due, due[1:])) <= {3, 4}


def test_first_due_false_starts_one_period_later():
    acc = PeriodAccumulator(0.001, 50.0, first_due=False)
    due = [k for k in range(100) if acc.tick()]
    assert due == [20, 40, 60, 80]
    every_step = PeriodAccumulator(0.001, 0.0, first_due=False)
    assert [k for k in range(3) if every_step.tick()] == [1, 2]


def test_the_step2_publisher_sends_the_start_state_then_one_per_period_then_the_final_state():
    """start() publishes the state before the first step; at 0.1 Hz the next comes 10 s later (issue 26)."""
    import mujoco

    from tutorial.controllers.joint_state_publisher import RttJointStatePublisher
    from tutorial.core.body import Body
    from tutorial.core.controller import ControllerConfig, ControllerIO
    from tutorial.core.world import ModelEntry, build_world

    from conftest import MODEL

    class Publisher:  # stands in for an rclpy publisher: keeps each message's stamp and TURRET_P
        def __init__(self):
            self.sent = []

        def publish(self, msg):
            self.sent.append((msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9, msg.position[1]))

    class Node:
        def create_publisher(self, *args):
            self.publisher = Publisher()
            return self.publisher

    model = build_world([ModelEntry("Tank", MODEL / "tank.xml")])
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    start_pitch = float(data.qpos[Body(model, data, "Tank").joint("TURRET_P").info.qpos_adr])
    node, controller = Node(), RttJointStatePublisher()
    body = Body(model, data, "Tank")
    assert controller.configure(ControllerConfig(name="P", body=body, node=node, parameters={"rate": 0.1}))
    assert controller.initialize(ControllerIO(body=body, time_step=model.opt.timestep, node=node, data=data))
    assert controller.start()
    assert node.publisher.sent == [(0.0, start_pitch)]  # the state the simulation starts in, at once
    for _ in range(10_500):  # 10.5 s
        controller.control()
        mujoco.mj_step(model, data)
    controller.stop()
    stamps = [round(t, 3) for t, _ in node.publisher.sent]
    assert stamps == [0.0, 10.0, 10.5]  # start, one period later, the final state
    assert node.publisher.sent[1][1] != start_pitch  # the barrel sagged: a later state, not the start again


def test_the_step2_publisher_counts_what_it_sent_refuses_a_negative_rate_and_lets_the_final_state_be_acked(caplog):
    import logging

    import mujoco
    from rclpy.duration import Duration

    from tutorial.controllers.joint_state_publisher import RttJointStatePublisher
    from tutorial.core.body import Body
    from tutorial.core.controller import ControllerConfig, ControllerIO
    from tutorial.core.world import ModelEntry, build_world

    from conftest import MODEL

    class Publisher:
        def __init__(self):
            self.sent, self.acked_within = 0, []

        def publish(self, msg):
            self.sent += 1

        def wait_for_all_acked(self, timeout):
            self.acked_within.append(timeout)
            return True

    class Node:
        def __init__(self):
            self.publishers, self.destroyed = [], []

        def create_publisher(self, msg_type, topic, qos):
            self.publishers.append((topic, Publisher()))
            return self.publishers[-1][1]

        def destroy_publisher(self, publisher):
            self.destroyed.append(publisher)

    model = build_world([ModelEntry("Tank", MODEL / "tank.xml")])
    data = mujoco.MjData(model)
    body = Body(model, data, "Tank")
    log = logging.getLogger("test.step2")
    node = Node()
    with caplog.at_level(logging.ERROR, logger="test.step2"):
        refused = RttJointStatePublisher().configure(
            ControllerConfig(name="P", body=body, node=node, parameters={"rate": -1.0}, log=log)
        )
    assert refused is False and node.publishers == []
    assert caplog.messages == ["rate must be >= 0 Hz, got -1.0"]
    controller = RttJointStatePublisher()
    assert controller.configure(ControllerConfig(name="P", body=body, node=node, parameters={"rate": 0.0}, log=log))
    assert controller.summary() == {"topic": "/Tank/joint_state", "rate": 0.0, "published": 0}
    assert controller.initialize(ControllerIO(body=body, time_step=0.001, node=node, data=data))
    assert controller.start()
    for _ in range(5):
        assert controller.control()  # rate 0: every step after the first (start() sent that state)
    controller.stop()
    ((topic, publisher),) = node.publishers
    assert publisher.sent == 6 and controller.summary() == {"topic": topic, "rate": 0.0, "published": 6}
    controller.unconfigure()
    assert publisher.acked_within == [Duration(seconds=1)] and node.destroyed == [publisher]
