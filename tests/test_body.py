"""Which joints a body numbers, for the tank and for another model."""

import mujoco

from tutorial.body import Body
from tutorial.world import ModelEntry, build_world
from conftest import MODEL


def test_tank_numbers_its_turret_joints_only():
    model = build_world([ModelEntry("Tank", MODEL / "tank.xml")])
    body = Body(model, mujoco.MjData(model), "Tank")
    assert body.joint_names == ["TURRET_Y", "TURRET_P"]
    assert body.skipped_joints["CHASSIS"].startswith("free joint")
    assert all(body.skipped_joints[f"TRACK_L_W{i}"].startswith("joint group 3") for i in range(4))
    assert body.track("TRACK_L").actuator_id >= 0


def test_crane_numbers_hinges_and_slides_and_skips_the_ball():
    model = build_world([ModelEntry("Crane", MODEL / "crane.xml")])
    body = Body(model, mujoco.MjData(model), "Crane")
    assert body.joint_names == ["SLEW", "LUFF", "TROLLEY"]
    assert [j.kind for j in body.joint_infos] == ["hinge", "hinge", "slide"]
    assert body.skipped_joints == {"HOOK_SWING": "ball joint: a quaternion, JointState carries one number per joint"}
    assert not body.joint("SLEW").info.limited


def test_two_bodies_in_one_world_keep_their_own_names():
    model = build_world([ModelEntry("Tank", MODEL / "tank.xml"), ModelEntry("Tank2", MODEL / "tank.xml", (2, 0, 0))])
    data = mujoco.MjData(model)
    a, b = Body(model, data, "Tank"), Body(model, data, "Tank2")
    a.joint("TURRET_Y").q = 0.5
    assert b.joint("TURRET_Y").q == 0.0 and a.joint_names == b.joint_names
