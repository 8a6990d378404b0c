"""The URDF of a body (tutorial/tools/urdf): checked by a parser we did not write.

Unit tier, but for ``rtt-urdf``'s command line (a process of its own: cross-process).

``yourdfpy`` reads each written URDF back and computes every link's pose for
random joint values with its own forward kinematics; MuJoCo computes the
body poses for the same values.  They must agree within 1e-9 m and rad for
the tank and for every third-party model tests/test_third_party_models.py
uses (gymnasium, dm_control, MuJoCo's own), whose joints sit off their
bodies' origins, several to a body, with reference angles, slides, ball
and free joints and meshes.  Also: what each geom becomes, the mesh files,
``rtt-urdf``'s command line, our own kinematics (the TF of recordings)
against ``yourdfpy``, and a description MuJoCo reads back.
"""

from __future__ import annotations

import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest
from test_third_party_models import CASES

from tutorial.tools.urdf.export import export_model_file
from tutorial.tools.urdf.frames import pose_matrix
from tutorial.tools.urdf.kinematics import UrdfKinematics
from tutorial.tools.urdf.records import ROOT_FREE, ROOT_WORLD

from conftest import MODEL, ROOT

MODELS = [("Tank", None), *((c.name, c) for c in CASES)]
POSTURES = 40  # random joint configurations per model
TOLERANCE = 1e-9  # m, and rad (a rotation matrix's entries)


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    """Model name -> (its Body, its UrdfExport, the written URDF's path), built once."""
    cache = {}

    def get(name, case):
        if name not in cache:
            path = MODEL / "tank.xml" if case is None else case.file()
            body, urdf = export_model_file(path, name)
            folder = tmp_path_factory.mktemp(name)
            urdf.write(folder / f"{name}.urdf", source=path.name)
            cache[name] = body, urdf, folder / f"{name}.urdf"
        return cache[name]

    return get


def random_posture(body, urdf, rng) -> dict[str, float]:
    """Set random values of the numbered joints (and a random root pose) in ``body.data``; the joint values."""
    m, data = body.model, body.data
    data.qpos[:] = m.qpos0
    values = {}
    for j in body.joint_infos:
        if j.limited:
            q = rng.uniform(j.lower, j.upper)
        else:
            q = rng.uniform(-np.pi, np.pi) if j.kind == "hinge" else rng.uniform(-2.0, 2.0)
        data.qpos[j.qpos_adr] = values[j.name] = q
    if urdf.root_kind == ROOT_FREE:
        a = m.jnt_qposadr[m.body_jntadr[urdf.root_body]]
        quat = rng.normal(size=4)
        data.qpos[a : a + 7] = [*rng.uniform(-5, 5, 3), *(quat / np.linalg.norm(quat))]
    mujoco.mj_kinematics(m, data)
    return values


def mujoco_link_poses(body, urdf) -> dict[str, np.ndarray]:
    """Each link's body pose in the root link's frame, from MuJoCo's forward kinematics."""
    data = body.data
    root = (
        np.eye(4)
        if urdf.root_kind == ROOT_WORLD
        else pose_matrix(data.xpos[urdf.root_body], data.xquat[urdf.root_body])
    )
    inverse = np.linalg.inv(root)
    return {link: inverse @ pose_matrix(data.xpos[b], data.xquat[b]) for b, link in urdf.body_links.items()}


@pytest.mark.parametrize("name, case", MODELS, ids=[n for n, _ in MODELS])
def test_yourdfpy_and_mujoco_agree_on_every_link(name, case, exported):
    import yourdfpy

    body, urdf, path = exported(name, case)
    parsed = yourdfpy.URDF.load(str(path), load_meshes=False)
    assert parsed.base_link == urdf.root_link
    moving = [j.name for j in parsed.robot.joints if j.type in ("revolute", "continuous", "prismatic")]
    assert sorted(moving) == sorted(body.joint_names)  # JointState moves the URDF by name
    assert len(urdf.body_links) == len(body.body_ids)  # a link for every MuJoCo body
    rng = np.random.default_rng(27)
    worst = 0.0
    for _ in range(POSTURES):
        values = random_posture(body, urdf, rng)
        parsed.update_cfg(values)
        for link, expected in mujoco_link_poses(body, urdf).items():
            worst = max(worst, np.abs(parsed.get_transform(link, urdf.root_link) - expected).max())
    assert worst <= TOLERANCE, worst


@pytest.mark.parametrize("name, case", MODELS[:4], ids=[n for n, _ in MODELS[:4]])
def test_our_kinematics_is_yourdfpys(name, case, exported):
    """UrdfKinematics (what /tf in a recording is computed with) against yourdfpy, on the same file."""
    import yourdfpy

    body, urdf, path = exported(name, case)
    parsed = yourdfpy.URDF.load(str(path), load_meshes=False)
    ours = UrdfKinematics(path.read_text())
    assert ours.root == urdf.root_link and sorted(j.name for j in ours.moving) == sorted(urdf.moving_joints)
    rng = np.random.default_rng(5)
    for _ in range(10):
        values = random_posture(body, urdf, rng)
        parsed.update_cfg(values)
        poses = ours.link_poses(ours.joint_values(list(values), list(values.values())))
        for link in urdf.body_links.values():
            assert np.abs(poses[link] - parsed.get_transform(link, urdf.root_link)).max() <= TOLERANCE


def test_the_tank_urdf(exported):
    """Names, joint types, limits, inertials, shapes and colours as the MJCF gives them, read back by yourdfpy."""
    import yourdfpy

    body, urdf, path = exported("Tank", None)
    assert urdf.root_link == "CHASSIS" and urdf.root_kind == ROOT_FREE
    robot = yourdfpy.URDF.load(str(path), load_meshes=False).robot
    assert robot.name == "Tank"
    joints = {j.name: j for j in robot.joints}
    links = {link.name: link for link in robot.links}
    assert joints["TURRET_Y"].type == "revolute" and list(joints["TURRET_Y"].axis) == [0.0, 0.0, -1.0]
    assert (joints["TURRET_P"].limit.lower, joints["TURRET_P"].limit.upper) == pytest.approx(
        (np.radians(-10), np.radians(45))
    )
    # The road wheels (joint group 3, not in JointState) are fixed, named after their joints.
    assert {n: j.type for n, j in joints.items() if n.startswith("TRACK_L_W")} == {
        f"TRACK_L_W{i}": "fixed" for i in range(4)
    }
    assert joints["CHASSIS_to_TRACK_L"].type == "fixed"  # welded: no joint in MuJoCo
    assert links["CHASSIS"].inertial.mass == 8.0
    assert np.diag(links["TURRET_P"].inertial.inertia) == pytest.approx([0.015, 0.02, 0.02])
    box = next(v for v in links["CHASSIS"].visuals if v.name == "CHASSIS_body")
    assert list(box.geometry.box.size) == pytest.approx([0.375, 0.3, 0.1])  # MuJoCo's half sizes, doubled
    assert list(box.material.color.rgba) == [0.36, 0.42, 0.24, 1.0]  # the MJCF's rgba, as written there
    barrel = next(v for v in links["TURRET_P"].visuals if v.name == "TURRET_P_barrel")
    assert (barrel.geometry.cylinder.radius, barrel.geometry.cylinder.length) == pytest.approx((0.02, 0.1))
    # The wheels are hidden (geom group 3) but collide: collision only.
    wheel = links["TRACK_L_W0"]
    assert not wheel.visuals and wheel.collisions[0].geometry.cylinder.radius == pytest.approx(0.08)
    text = path.read_text()
    assert "Joints moved by /Tank/joint_state: TURRET_Y, TURRET_P." in text
    assert "joint TRACK_L_W0: fixed at its reference position (joint group 3: drive mechanism)" in text
    # The turret's armature is not mapped, and it has no damping: no <dynamics>.
    assert "<dynamics" not in text


def test_damping_and_friction_are_written(tmp_path):
    """A hinge with damping and friction loss: <dynamics damping friction>, read back by yourdfpy."""
    import yourdfpy

    (tmp_path / "arm.xml").write_text(
        "<mujoco><worldbody><body name='base'><body name='arm'>"
        "<joint name='shoulder' axis='0 1 0' pos='0 0 0.1' ref='0.3' damping='2.5' frictionloss='0.25'/>"
        "<geom type='capsule' size='0.02 0.1'/></body></body></worldbody></mujoco>"
    )
    body, urdf = export_model_file(tmp_path / "arm.xml", "Arm")
    urdf.write(tmp_path / "arm.urdf")
    parsed = yourdfpy.URDF.load(str(tmp_path / "arm.urdf"), load_meshes=False)
    [joint] = [j for j in parsed.robot.joints if j.name == "shoulder"]
    assert joint.type == "continuous"
    assert (float(joint.dynamics.damping), float(joint.dynamics.friction)) == (2.5, 0.25)
    # The anchor (pos) is off the body's origin: a joint frame link, and a fixed joint to the body.
    assert {link.name for link in parsed.robot.links} == {"base", "shoulder_frame", "arm"}
    assert urdf.root_kind == "fixed"


def test_capsules_ellipsoids_planes_and_meshes(exported, tmp_path):
    """MuJoCo's test model: capsules become a cylinder and two spheres, an ellipsoid a scaled
    sphere mesh, a plane a thin box; the dog's meshes are written as STL with MuJoCo's vertices."""
    import trimesh
    import yourdfpy

    case = next(c for c in CASES if c.name == "MujocoTest")
    body, urdf, path = exported("MujocoTest", case)
    m = body.model
    capsule = next(g for g in range(m.ngeom) if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_CAPSULE)
    name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, capsule).split("/", 1)[1]
    elements = [v for link in urdf.links for v in link.visuals if v.name.startswith(name)]
    assert sorted(v.name for v in elements) == [name, f"{name}_cap0", f"{name}_cap1"]
    # The scene yourdfpy builds from the file (meshes loaded) holds every visual.
    scene = yourdfpy.URDF.load(str(path), load_meshes=True).scene
    assert f"{name}_cap1" in scene.geometry
    ellipsoids = [v for link in urdf.links for v in link.visuals if v.geometry.kind == "mesh"]
    assert any(v.geometry.filename == "ellipsoid.stl" for v in ellipsoids)
    assert (path.parent / "MujocoTest_meshes" / "ellipsoid.stl").is_file()

    dog = next(c for c in CASES if c.name == "Dog")
    body, urdf, path = exported("Dog", dog)
    m = body.model
    for mesh_id in range(m.nmesh)[:5]:
        file = (
            path.parent
            / "Dog_meshes"
            / f"{mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_MESH, mesh_id).split('/', 1)[1]}.stl"
        )
        loaded = trimesh.load(file, process=False)
        v0, nv = m.mesh_vertadr[mesh_id], m.mesh_vertnum[mesh_id]
        assert len(loaded.faces) == m.mesh_facenum[mesh_id]
        assert np.abs(np.unique(loaded.vertices, axis=0) - np.unique(m.mesh_vert[v0 : v0 + nv], axis=0)).max() < 1e-6


def test_a_description_mujoco_reads_back(exported):
    """What a viewer with no model file builds: the joints, by name, with their limits."""
    from tutorial.tools.urdf.mujoco_load import mujoco_text

    _, urdf, _ = exported("Tank", None)
    text, left_out, changed = mujoco_text(urdf.description())
    model = mujoco.MjModel.from_xml_string(text)
    names = [model.joint(j).name for j in range(model.njnt)]
    assert names == ["TURRET_Y", "TURRET_P"] and left_out == [] and changed == []
    assert model.jnt_range[1] == pytest.approx([np.radians(-10), np.radians(45)])
    assert model.ngeom == sum(len(link.visuals) for link in urdf.links)  # visuals only


def test_rtt_urdf_command_line(procs, tmp_path):
    def run(*args):
        proc = procs([sys.executable, "-m", "tutorial.tools.rtt_urdf", *args])
        return proc.wait(60), proc

    status, ok = run("project/step2.yaml", "--body", "Tank", "-o", str(tmp_path / "tank.urdf"))
    assert status == 0, ok.err
    assert "robot Tank, 13 links, 12 joints (2 moving: TURRET_Y, TURRET_P), root link CHASSIS" in ok.out
    assert UrdfKinematics((tmp_path / "tank.urdf").read_text()).root == "CHASSIS"
    for args, says in (
        (["project/step2.yaml"], "name the body with --body"),
        (["project/step2.yaml", "--body", "Gun"], "no body 'Gun'"),
        (["model/room.xml"], "has no link"),
        (["model/nothing.xml"], "no such model file"),
    ):
        status, bad = run(*args, "-o", str(tmp_path / "x.urdf"))
        assert status == 2 and says in bad.err and "Traceback" not in bad.err, (args, bad.err)


def test_our_kinematics_leaves_out_what_robot_state_publisher_does():
    urdf = (Path(ROOT) / "model").glob("tank.xml")
    _, export = export_model_file(next(urdf))
    k = UrdfKinematics(export.xml())
    values = k.joint_values(["TURRET_Y", "GUN", "TURRET_P", "TURRET_Y"], [0.1, 1.0, float("nan")])
    assert values == {"TURRET_Y": 0.1}  # unknown names, NaN, and an entry with no position left out
    moved = k.moving_transforms(values, (3, 4))
    assert [(t.parent, t.child, t.stamp) for t in moved] == [("CHASSIS", "TURRET_Y", (3, 4))]
    assert len(k.static_transforms((0, 0))) == 10
    for bad in ("<robot name='x'><link name='a'/><link name='b'/></robot>", "not xml"):
        with pytest.raises(ValueError):
            UrdfKinematics(bad)
