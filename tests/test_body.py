"""Which joints a body numbers and which elements it owns, for our models and for unnamed ones."""

from pathlib import Path

import mujoco
import pytest

from tutorial.core.body import Body
from tutorial.core.world import ModelEntry, build_world, name_unnamed_elements

from conftest import MODEL

FIXTURES = Path(__file__).resolve().parent / "fixtures"


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


def test_a_roots_free_joint_is_found_in_qpos_and_a_fixed_root_has_none():
    model = build_world([ModelEntry("Tank", MODEL / "tank.xml"), ModelEntry("Tank2", MODEL / "tank.xml", (2, 0, 0))])
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    a, b = Body(model, data, "Tank"), Body(model, data, "Tank2")
    assert b.root_qpos_address not in (None, a.root_qpos_address)
    assert list(data.qpos[b.root_qpos_address : b.root_qpos_address + 3]) == list(data.xpos[b.root_id])
    crane = build_world([ModelEntry("Crane", MODEL / "crane.xml")])
    assert Body(crane, mujoco.MjData(crane), "Crane").root_qpos_address is None  # bolted to the ground


# ---- models whose links and joints have no names -------------------------------------

UNNAMED = FIXTURES / "unnamed_links.xml"


def test_unnamed_joints_are_named_after_their_id_in_the_file():
    model = build_world([ModelEntry("U", UNNAMED)])
    body = Body(model, mujoco.MjData(model), "U")
    assert body.joint_names == ["joint1", "joint3", "shoulder", "joint5"]  # hinge, slide, hinge, hinge
    assert [j.kind for j in body.joint_infos] == ["hinge", "slide", "hinge", "hinge"]
    # joint 3 (the ball) cannot be "joint3": the file gave that name to joint 2 (the slide)
    assert body.skipped_joints == {
        "joint0": "free joint: the body's root pose, not a robot joint",
        "joint3_1": "ball joint: a quaternion, JointState carries one number per joint",
    }
    alone = mujoco.MjModel.from_xml_path(str(UNNAMED))  # the ids the rule refers to
    kinds = mujoco.mjtJoint
    assert [int(alone.jnt_type[i]) for i in (0, 1, 3, 5)] == [
        int(kinds.mjJNT_FREE),
        int(kinds.mjJNT_HINGE),
        int(kinds.mjJNT_BALL),
        int(kinds.mjJNT_HINGE),
    ]
    assert body.joint("shoulder").info.motor >= 0 and body.joint("joint3").info.gear == 5.0
    assert body.joint("joint1").info.motor == -1


def test_a_body_owns_its_whole_kinematic_tree_and_what_it_fixed_to_the_world():
    model = build_world([ModelEntry("U", UNNAMED)])
    body = Body(model, mujoco.MjData(model), "U")
    body_names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b) for b in sorted(body.body_ids)]
    assert body_names == ["U/body1", "U/body2", "U/body3", "U/arm", "U/body5"]
    assert [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b) for b in body.root_ids] == ["U/body1", "U/arm"]
    assert body.root_id == body.root_ids[0]
    assert len(body.joint_ids) == model.njnt and len(body.geom_ids) == model.ngeom == 6  # the plane too
    assert len(body.site_ids) == model.nsite == 2
    assert len(body.actuator_ids) == model.nu == 3  # two joint motors and the tendon's


def test_two_copies_of_an_unnamed_model_and_the_tank_share_nothing():
    entries = [
        ModelEntry("A", UNNAMED),
        ModelEntry("B", UNNAMED, (3, 0, 0)),
        ModelEntry("Tank", MODEL / "tank.xml", (0, 3, 0)),
    ]
    model = build_world(entries)
    data = mujoco.MjData(model)
    a, b, tank = (Body(model, data, e.name) for e in entries)
    for attribute in ("body_ids", "joint_ids", "geom_ids", "site_ids", "actuator_ids"):
        sets = [getattr(x, attribute) for x in (a, b, tank)]
        assert not (sets[0] & sets[1] or sets[0] & sets[2] or sets[1] & sets[2]), attribute
    assert len(a.body_ids | b.body_ids | tank.body_ids) == model.nbody - 1
    assert a.joint_names == b.joint_names == ["joint1", "joint3", "shoulder", "joint5"]
    a.joint("joint5").q = 0.5
    assert b.joint("joint5").q == 0.0
    assert tank.joint_names == ["TURRET_Y", "TURRET_P"]


def test_a_model_of_one_unnamed_static_geom_is_a_body(tmp_path):
    floor = tmp_path / "floor.xml"
    floor.write_text('<mujoco><worldbody><geom type="plane" size="1 1 .1"/></worldbody></mujoco>')
    model = build_world([ModelEntry("Floor", floor), ModelEntry("U", UNNAMED)])
    body = Body(model, mujoco.MjData(model), "Floor")
    assert body.root_id == 0 and not body.body_ids and body.num_joints == 0
    assert [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) for g in body.geom_ids] == ["Floor/geom0"]
    with pytest.raises(KeyError, match="no model named 'Nothing'"):
        Body(model, mujoco.MjData(model), "Nothing")


def test_a_world_not_built_by_build_world_never_publishes_an_empty_name():
    """Attached without naming: the named root's unnamed link is still owned, its
    unnamed joint is skipped with a reason instead of going out as ""."""
    spec = mujoco.MjSpec()
    spec.attach(mujoco.MjSpec.from_file(str(UNNAMED)), prefix="U/", frame=spec.worldbody.add_frame())
    model = spec.compile()
    body = Body(model, mujoco.MjData(model), "U")
    assert [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b) for b in body.root_ids] == ["U/arm"]
    assert len(body.body_ids) == 2  # the arm and its unnamed forearm
    assert body.joint_names == ["shoulder"]
    unnamed = {k: v for k, v in body.skipped_joints.items() if v.startswith("unnamed")}
    assert len(unnamed) == 1 and all(body.joint_names)


def test_naming_keeps_given_names_and_appends_a_suffix_on_a_clash():
    spec = mujoco.MjSpec.from_file(str(UNNAMED))
    assert name_unnamed_elements(spec) == 4 + 4 + 6 + 2  # bodies 1-3 and 5, joints 0, 1, 3 and 5, all geoms, sites
    assert [j.name for j in spec.joints] == ["joint0", "joint1", "joint3", "joint3_1", "shoulder", "joint5"]
    assert [b.name for b in spec.bodies] == ["world", "body1", "body2", "body3", "arm", "body5"]
    assert name_unnamed_elements(spec) == 0  # a second pass changes nothing


def test_odd_joint_names_go_out_as_they_are(tmp_path):
    """MJCF allows spaces, slashes and any letters in a name; JointState names are free strings."""
    odd = ["left hip", "arm/elbow", "gelenk-ü", "0"]
    joints = "".join(f'<body pos="0 0 {k}"><joint name="{n}"/><geom size=".1"/></body>' for k, n in enumerate(odd))
    path = tmp_path / "odd.xml"
    path.write_text(f"<mujoco><worldbody>{joints}</worldbody></mujoco>", encoding="utf-8")
    model = build_world([ModelEntry("Odd", path)])
    assert Body(model, mujoco.MjData(model), "Odd").joint_names == odd
