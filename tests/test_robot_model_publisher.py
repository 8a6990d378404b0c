"""Notebook 09's publisher, in this process: the URDF once, then the odometry at its rate, the final pose at stop.

The controller is driven as the simulation thread drives it, with a
stand-in node that keeps what was published; each figure is checked against
MuJoCo's own state, read here independently.
"""

from __future__ import annotations

import logging
import math

import mujoco
import numpy as np
import pytest

from tutorial.controllers.robot_model_publisher import DEFAULT_RATE, RttRobotModelPublisher
from tutorial.core.body import Body
from tutorial.core.controller import ControllerConfig, ControllerIO
from tutorial.core.world import ModelEntry, build_world

from conftest import MODEL

pytestmark = pytest.mark.unit


class Publisher:
    """Stands in for an rclpy publisher: keeps a copy of each message's fields that matter here."""

    def __init__(self, msg_type, topic, qos):
        self.msg_type, self.topic, self.qos, self.sent = msg_type, topic, qos, []
        self.destroyed = False
        self.acked_within = []  # each wait_for_all_acked's timeout

    def publish(self, msg):
        if hasattr(msg, "data"):
            self.sent.append(msg.data)
            return
        p, o = msg.pose.pose.position, msg.pose.pose.orientation
        v, a = msg.twist.twist.linear, msg.twist.twist.angular
        self.sent.append(
            {
                "t": msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9,
                "frame": msg.header.frame_id,
                "child": msg.child_frame_id,
                "p": (p.x, p.y, p.z),
                "q": (o.w, o.x, o.y, o.z),
                "v": (v.x, v.y, v.z),
                "w": (a.x, a.y, a.z),
            }
        )

    def wait_for_all_acked(self, timeout):
        self.acked_within.append(timeout)
        return True


class Node:
    def __init__(self):
        self.publishers = {}

    def create_publisher(self, msg_type, topic, qos):
        self.publishers[topic] = Publisher(msg_type, topic, qos)
        return self.publishers[topic]

    def destroy_publisher(self, publisher):
        publisher.destroyed = True


def tank(rate=None):
    model = build_world([ModelEntry("Tank", MODEL / "tank.xml")])
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    body, node, controller = Body(model, data, "Tank"), Node(), RttRobotModelPublisher()
    parameters = {"rate": DEFAULT_RATE if rate is None else rate}
    config = ControllerConfig(name="M", body=body, node=node, parameters=parameters)
    return model, data, body, node, controller, config


def free_joint(model):
    return next(j for j in range(model.njnt) if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE)


def test_the_description_goes_once_and_the_odometry_at_its_rate_then_the_final_pose():
    model, data, body, node, controller, config = tank(rate=50.0)
    assert controller.configure(config)
    description, odom = node.publishers["/Tank/robot_description"], node.publishers["/Tank/odom"]
    assert len(description.sent) == 1 and description.sent[0].lstrip().startswith("<?xml")
    assert "<robot" in description.sent[0] and 'name="CHASSIS"' in description.sent[0]
    for publisher in (description, odom):  # kept for late joiners, the newest only, reliable
        assert publisher.qos.depth == 1 and publisher.qos.durability.name == "TRANSIENT_LOCAL"
        assert publisher.qos.reliability.name == "RELIABLE"
    assert controller.initialize(ControllerIO(body=body, time_step=model.opt.timestep, node=node, data=data))
    j = free_joint(model)
    qa, da = int(model.jnt_qposadr[j]), int(model.jnt_dofadr[j])
    data.qvel[da : da + 3] = (0.3, -0.2, 0.0)  # the tank slides: the odometry must follow it
    for _ in range(500):  # 0.5 s
        assert controller.control()
        mujoco.mj_step(model, data)
    controller.stop()
    sent = odom.sent
    assert [round(m["t"], 3) for m in sent[:-1]] == [round(0.02 * k, 3) for k in range(25)]  # 50 Hz from t = 0
    assert round(sent[-1]["t"], 3) == 0.5  # and where the tank ended
    last = sent[-1]
    assert last["frame"] == "world" and last["child"] == "CHASSIS"
    assert last["p"] == pytest.approx(tuple(data.qpos[qa : qa + 3]), abs=1e-9)
    q = np.array(data.qpos[qa + 3 : qa + 7]) / np.linalg.norm(data.qpos[qa + 3 : qa + 7])
    assert last["q"] == pytest.approx(tuple(q), abs=1e-9)
    rotation = np.zeros(9)
    mujoco.mju_quat2Mat(rotation, q)
    linear = rotation.reshape(3, 3).T @ np.array(data.qvel[da : da + 3])  # in the body's own frame
    assert last["v"] == pytest.approx(tuple(linear), abs=1e-9)
    assert last["w"] == pytest.approx(tuple(data.qvel[da + 3 : da + 6]), abs=1e-9)
    assert math.dist(sent[0]["p"], last["p"]) > 0.05  # the poses moved with the tank
    s = controller.summary()
    assert s == {
        "description_topic": "/Tank/robot_description",
        "links": len(controller.urdf.links),
        "topic": "/Tank/odom",
        "rate": 50.0,
        "published": len(sent),
    }
    assert s["links"] == description.sent[0].count("<link ")
    controller.unconfigure()
    assert description.destroyed and odom.destroyed


def test_rate_0_publishes_every_step_and_the_default_is_the_joint_states_rate():
    assert RttRobotModelPublisher.PARAMETERS["rate"][1] == DEFAULT_RATE == 50.0
    model, data, body, node, controller, config = tank(rate=0.0)
    assert controller.configure(config)
    assert controller.initialize(ControllerIO(body=body, time_step=model.opt.timestep, node=node, data=data))
    for _ in range(10):
        controller.control()
        mujoco.mj_step(model, data)
    assert len(node.publishers["/Tank/odom"].sent) == 10


def test_a_negative_rate_is_refused_saying_why(caplog):
    *_, node, controller, config = tank(rate=-1.0)
    config.log = logging.getLogger("test.robot_model")
    with caplog.at_level(logging.ERROR, logger="test.robot_model"):
        assert controller.configure(config) is False
    assert caplog.messages == ["rate must be >= 0 Hz, got -1.0"]
    assert node.publishers == {}  # nothing published, nothing to clean up


def test_the_description_names_its_source_and_unconfigure_waits_for_the_final_pose_to_be_acked():
    from nav_msgs.msg import Odometry
    from rclpy.duration import Duration
    from std_msgs.msg import String

    *_, node, controller, config = tank()
    assert controller.configure(config)
    description, odometry = node.publishers["/Tank/robot_description"], node.publishers["/Tank/odom"]
    assert (description.msg_type, odometry.msg_type) == (String, Odometry)
    (urdf,) = description.sent
    assert "from body Tank of the simulation: robot Tank" in urdf
    controller.unconfigure()
    assert odometry.acked_within == [Duration(seconds=1)]  # reliable subscribers get the final pose, 1 s at most
    assert odometry.destroyed and description.destroyed
