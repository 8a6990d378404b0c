"""The Step 3 monitor draws robots no one here wrote, from their descriptions as ROS publishes them.

Every URDF of ``example-robot-data`` 6.0.0 (BSD-licensed URDFs and meshes)
that ROS's own parser (urdfdom's ``check_urdf``) accepts: 68 files, among
them the Franka Panda (Collada visuals, a mimic finger), the UR5, the SO-100
arm (STL), TIAGo, Allegro hands, ANYmal, Baxter, Go1 and B1.  Each is
published on ``/<name>/robot_description`` with its ``package://`` URIs as
shipped, ``AMENT_PREFIX_PATH`` naming the package's prefix, and a sine
JointState on ``/<name>/joint_state``.  The monitor must draw every visual
whose mesh file exists, end on the publisher's final positions, and put
every link where ``yourdfpy``'s forward kinematics puts it.  Physics a
viewer does not need never stops it: inertias MuJoCo refuses, visual meshes
too thin to have a volume, meshes over MuJoCo's 200,000 triangles.

``make test`` runs one robot of each kind of trouble (and the Panda);
``make test-robots`` all of them.  Unitree's Go2 floats: its root link
follows ``/Go2/odom``.
"""

from __future__ import annotations

import math
import os
import re
import shutil
import subprocess
import sysconfig
from pathlib import Path

import numpy as np
import pytest

PREFIX = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix"
ROBOTS = PREFIX / "share" / "example-robot-data" / "robots"
ALL = sorted(str(p.relative_to(ROBOTS)) for p in ROBOTS.rglob("*.urdf")) if ROBOTS.is_dir() else []
# make test: the Panda, and a robot of each kind of trouble (inertias MuJoCo refuses, thin meshes); a mesh
# over 200,000 triangles is simplified in make test by test_a_mesh_over_mujocos_limit_is_simplified_...
MAKE_TEST = {
    "panda_description/urdf/panda.urdf",
    "tiago_description/robots/tiago.urdf",
    "icub_description/robots/icub_reduced.urdf",  # like Baxter's, its thin meshes have no volume: drawn
}
LINES = {  # file: what its description line must say
    "panda_description/urdf/panda.urdf": "1 of them following another (mimic)",
    "allegro_hand_description/urdf/allegro_left_hand.urdf": "the inertia of 4 links replaced, which MuJoCo refuses",
    "tiago_description/robots/tiago.urdf": "the inertia of 2 links replaced, which MuJoCo refuses",  # eigenvalues < 0
    "baxter_description/urdf/baxter.urdf": "",  # visual meshes too thin for a volume: drawn, nothing to say
    "go1_description/urdf/go1.urdf": "1 mesh over MuJoCo's 200,000 triangles simplified to that many (trunk.dae "
    "had 351,394)",
    "anymal_b_simple_description/robots/anymal.urdf": "",  # Collada feet whose texture is missing: drawn
}
# what urdfdom (Debian's check_urdf) refuses, and why: the monitor is not asked to draw these
URDFDOM_REFUSES = {"ur_description/urdf/ur3.urdf": "No name given for the robot."}  # an empty <robot>

pytestmark = pytest.mark.skipif(not ROBOTS.is_dir(), reason="example-robot-data is not installed (make installs it)")


def project(name: str, folder: Path):
    from tutorial.core.project import load_project

    path = folder / f"monitor_{name}.yaml"
    path.write_text(
        f"""name: monitor_{name}
models:
  - name: {name}
    description: /{name}/robot_description
    controllers:
      - name: RttJointStateMonitor
        class: tutorial.controllers.joint_state_subscriber:RttJointStateMonitor
"""
    )
    return load_project(path)


def urdfdom_refusal(path: Path) -> str | None:
    """What ``check_urdf`` says of a file it refuses (its first line), or None when it accepts it."""
    if shutil.which("check_urdf") is None:
        pytest.skip("no check_urdf (make test-robots installs Debian's liburdfdom-tools)")
    done = subprocess.run(["check_urdf", str(path)], capture_output=True, text=True, timeout=60)
    return None if done.returncode == 0 else " ".join((done.stdout + done.stderr).split("\n")[0].split()[1:])


@pytest.mark.slow
def test_urdfdom_accepts_68_of_the_69_files_and_yourdfpy_reads_them():
    import yourdfpy

    refused = {rel: urdfdom_refusal(ROBOTS / rel) for rel in ALL}
    refused = {rel: why for rel, why in refused.items() if why is not None}
    print(f"{len(ALL)} URDF files, {len(ALL) - len(refused)} that urdfdom accepts; refused: {refused}")
    assert len(ALL) == 69 and refused == URDFDOM_REFUSES
    for rel in set(ALL) - set(refused):  # the reader the monitor's joint tree and these tests use
        yourdfpy.URDF.load(str(ROBOTS / rel), load_meshes=False, build_collision_scene_graph=False)


def ident(rel: str) -> str:
    """A name for a file's robot, usable in a topic and a node's name: ``r_<package>_<file>``."""
    package, stem = rel.split("/", 1)[0].removesuffix("_description"), Path(rel).stem
    return "r_" + re.sub(r"[^A-Za-z0-9_]", "_", stem if stem.startswith(package) else f"{package}_{stem}")


@pytest.fixture(scope="module")
def mesh_cache(tmp_path_factory):
    """One mesh cache for the module's robots: several files share their meshes (as a robot's users would)."""
    return tmp_path_factory.mktemp("meshes")


@pytest.mark.parametrize(
    "rel", [rel if rel in MAKE_TEST else pytest.param(rel, marks=pytest.mark.slow) for rel in ALL], ids=ident
)
def test_the_monitor_mirrors_every_robot_of_example_robot_data(ros, node, monkeypatch, mesh_cache, tmp_path, rel):
    """Published as ``robot_state_publisher`` would, each robot is drawn, mirrors a moving joint state exactly
    (<= 1e-6 rad) and puts every link where ``yourdfpy``'s forward kinematics puts it."""
    import mujoco
    import yourdfpy
    from sensor_msgs.msg import JointState
    from std_msgs.msg import String

    from tutorial.interfaces.joint_state import joint_state_qos
    from tutorial.interfaces.robot_description import robot_description_qos
    from tutorial.tools.standalone.app import StandaloneApp
    from tutorial.tools.urdf.mesh_files import MeshError, resolve_mesh

    if rel in URDFDOM_REFUSES:  # the list test_urdfdom_accepts_68_of_the_69_files_and_yourdfpy_reads_them checks
        pytest.skip(f"urdfdom refuses it: {URDFDOM_REFUSES[rel]}")
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(PREFIX))  # where package://example-robot-data/ is
    monkeypatch.setenv("RTT_MESH_CACHE", str(mesh_cache))
    name = ident(rel)
    node.create_publisher(String, f"/{name}/robot_description", robot_description_qos()).publish(
        String(data=(ROBOTS / rel).read_text())
    )
    states = node.create_publisher(JointState, f"/{name}/joint_state", joint_state_qos())

    robot = yourdfpy.URDF.load(str(ROBOTS / rel), load_meshes=False, build_collision_scene_graph=False)
    moving = list(robot.actuated_joint_names)  # a mimic joint is not among them: the monitor moves it itself
    # ... but joint_state_publisher sends it too, computed from its leader: the monitor must not reject it
    # (a fixed joint's <mimic>, as in TALOS's reduced grippers, moves nothing)
    mimic = {n: j.mimic for n, j in robot.joint_map.items() if j.mimic is not None and j.type != "fixed"}
    # A <mimic> naming a joint the file does not have (Alex's Psyonic fingers): robot_state_publisher moves
    # such a joint by its own position, and yourdfpy puts it at its offset: sent at its offset, by name.
    orphans = {n: m.offset for n, m in mimic.items() if m.joint not in robot.joint_map}
    mimic = {n: m for n, m in mimic.items() if n not in orphans}

    def exists(visual) -> bool:  # a visual the monitor must draw: a shape, or a mesh whose file is there
        if visual.geometry.mesh is None:
            return True
        try:
            return resolve_mesh(visual.geometry.mesh.filename).is_file()
        except MeshError:
            return False

    records = []
    app = StandaloneApp(project(name, tmp_path), node_name=f"monitor_{name}"[:60], headless=True, output=records.append)
    try:
        app.open()
        said = [r for r in records if r.get("event") == "description"]
        assert len(said) == 1, records
        print(said[0]["line"])
        assert LINES.get(rel, "") in said[0]["line"]
        assert ("following another (mimic)" in said[0]["line"]) == bool(mimic), said[0]["line"]
        warned = [r["message"] for r in records if r.get("event") == "warning"]
        assert all("no such file" in w or "not found" in w for w in warned), warned  # only missing files
        body = app.bodies[name]
        for link in robot.robot.links:  # every visual whose file exists, on its own link
            b = mujoco.mj_name2id(app.model, mujoco.mjtObj.mjOBJ_BODY, f"{name}/{link.name}")
            wanted = sum(exists(v) for v in link.visuals)
            drawn = sum(1 for g in body.geom_ids if app.model.geom_bodyid[g] == b and app.model.geom_group[g] < 3)
            assert drawn >= wanted if b >= 0 else link.name == robot.base_link, (link.name, drawn, wanted)

        final = None
        for k in range(40):  # a sine, joint by joint, inside each joint's limits
            q = []
            for j, joint_name in enumerate(moving):
                joint = robot.joint_map[joint_name]
                lo, hi = (joint.limit.lower, joint.limit.upper) if joint.limit else (-math.pi, math.pi)
                lo, hi = (lo, hi) if lo is not None and hi is not None and hi > lo else (-1.0, 1.0)
                q.append(lo + (hi - lo) * (0.5 + 0.4 * math.sin(0.3 * k + j)))
            q += [m.multiplier * q[moving.index(m.joint)] + m.offset for m in mimic.values()]
            msg = JointState(name=moving + list(mimic) + list(orphans), position=q + list(orphans.values()))
            msg.header.stamp.sec = k
            states.publish(msg)
            final = dict(zip(moving, q[: len(moving)]))
        monitor = app.controller("RttJointStateMonitor")
        app.loop.run_until(
            lambda: body.joint_positions() and all(abs(body.joint(n).q - final[n]) <= 1e-6 for n in moving),
            timeout=30,
        )
        shown = body.joint_positions()
        assert all(abs(shown[n] - final[n]) <= 1e-6 for n in moving), (shown, final)
        assert monitor.summary()["rejected"] == {}

        robot.update_cfg({n: final[n] for n in moving})  # yourdfpy applies the mimic joints itself
        checked = 0
        for link in robot.robot.links:
            b = mujoco.mj_name2id(app.model, mujoco.mjtObj.mjOBJ_BODY, f"{name}/{link.name}")
            if b < 0 and link.name == robot.base_link:
                continue  # the root link, fixed to the world: MuJoCo makes it part of the world body
            assert b >= 0, f"no body for link {link.name}"
            checked += 1
            expected = robot.get_transform(link.name, robot.base_link)
            assert np.abs(app.data.xpos[b] - expected[:3, 3]).max() <= 1e-6, link.name
            assert np.abs(app.data.xmat[b].reshape(3, 3) - expected[:3, :3]).max() <= 1e-6, link.name
        assert checked >= len(robot.robot.links) - 1
    finally:
        app.close()


@pytest.mark.more  # make test checks TIAGo's line (test_the_monitor_mirrors_every_robot_of_example_robot_data)
def test_the_description_line_says_what_was_changed_to_draw_it(tmp_path, monkeypatch):
    """HyQ's inertias MuJoCo refuses are replaced, and said once, the first links named; Baxter's thin visual
    meshes have no volume, which a drawing does not need: nothing to say."""
    from tutorial.tools.urdf.mujoco_load import mujoco_text

    monkeypatch.setenv("AMENT_PREFIX_PATH", str(PREFIX))
    hyq = mujoco_text((ROBOTS / "hyq_description/robots/hyq_no_sensors.urdf").read_text(), cache=tmp_path)
    assert hyq.left_out == [] and hyq.changed == [
        "the inertia of 5 links replaced, which MuJoCo refuses (base_link, lf_foot, rf_foot, lh_foot and 1 more)"
    ]
    baxter = mujoco_text((ROBOTS / "baxter_description/urdf/baxter.urdf").read_text(), cache=tmp_path)
    assert baxter.left_out == [] and baxter.changed == []


def test_a_mesh_that_cannot_be_found_or_read_leaves_out_only_its_visual(tmp_path, monkeypatch):
    from tutorial.tools.urdf.mujoco_load import mujoco_text

    monkeypatch.setenv("RTT_MESH_CACHE", str(tmp_path / "meshes"))
    broken = tmp_path / "broken.dae"
    broken.write_text("<COLLADA><library_geometries>")  # cut short
    truncated = tmp_path / "cut.stl"
    truncated.write_bytes((ROBOTS / "so_arm_description" / "meshes" / "so100" / "Base.stl").read_bytes()[:300])
    good = ROBOTS / "so_arm_description" / "meshes" / "so100" / "Base.stl"
    foreign = tmp_path / "picture.stl"  # a file of the wrong format under a mesh's name
    foreign.write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(range(256)) * 4)
    foreign_dae = tmp_path / "picture.dae"
    foreign_dae.write_bytes(foreign.read_bytes())
    # a real description's other tags: ros2_control and Gazebo's are for other programs, not for drawing
    urdf = f"""<robot name="r">
  <link name="a"><visual><geometry><mesh filename="package://nowhere/meshes/a.stl"/></geometry></visual></link>
  <link name="b"><visual><geometry><mesh filename="file://{broken}"/></geometry></visual></link>
  <link name="c"><visual><geometry><mesh filename="file://{truncated}"/></geometry></visual></link>
  <link name="d"><visual><geometry><mesh filename="file://{good}"/></geometry></visual></link>
  <link name="e"><visual><geometry><mesh filename="file://{foreign}"/></geometry></visual></link>
  <link name="f"><visual><geometry><mesh filename="file://{foreign_dae}"/></geometry></visual></link>
  <joint name="ab" type="fixed"><parent link="a"/><child link="b"/></joint>
  <joint name="bc" type="fixed"><parent link="b"/><child link="c"/></joint>
  <joint name="cd" type="fixed"><parent link="c"/><child link="d"/></joint>
  <joint name="de" type="fixed"><parent link="d"/><child link="e"/></joint>
  <joint name="ef" type="fixed"><parent link="e"/><child link="f"/></joint>
  <ros2_control name="r" type="system">
    <hardware><plugin>mock_components/GenericSystem</plugin></hardware>
    <joint name="de"><command_interface name="position"/></joint>
  </ros2_control>
  <gazebo reference="d"><material>Gazebo/Grey</material><mu1>0.2</mu1></gazebo>
  <gazebo><plugin name="control" filename="libgz_ros2_control-system.so"/></gazebo>
</robot>"""
    text, left_out, _ = mujoco_text(urdf, environ={"AMENT_PREFIX_PATH": str(tmp_path / "ros")})
    assert len(left_out) == 5 and all("\n" not in line for line in left_out), left_out
    assert left_out[0].startswith("link a: visual left out: package://nowhere/meshes/a.stl: not found (looked in ")
    assert str(tmp_path / "ros" / "share" / "nowhere") in left_out[0]
    assert left_out[1].startswith("link b: visual left out:") and "broken.dae" in left_out[1]
    assert left_out[2].startswith("link c: visual left out:") and "cut.stl" in left_out[2]
    assert left_out[3].startswith("link e: visual left out:") and "picture.stl" in left_out[3]
    assert left_out[4].startswith("link f: visual left out:") and "picture.dae" in left_out[4]
    import mujoco

    model = mujoco.MjModel.from_xml_string(text)
    assert model.nmesh == 1 and model.ngeom == 1  # link d still drawn
    assert "ros2_control" not in text and "gazebo" not in text.lower() and "plugin" not in text


def one_link(inertia: dict, visual: str = "<box size='0.1 0.1 0.1'/>") -> str:
    values = " ".join(f'{k}="{v!r}"' for k, v in inertia.items())
    return f"""<robot name="r"><link name="base"/><link name="l">
  <inertial><mass value="1.0"/><inertia {values}/></inertial>
  <visual><geometry>{visual}</geometry></visual></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="l"/><axis xyz="0 0 1"/>
  <limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>"""


def test_an_inertia_mujoco_refuses_is_replaced_and_only_then(tmp_path):
    """Any inertia matrix: the description compiles; one MuJoCo accepts as it is, is kept as it is."""
    import warnings

    import mujoco
    from hypothesis import given
    from hypothesis import strategies as st

    from tutorial.core.world import drawing_spec
    from tutorial.tools.urdf.mujoco_load import mujoco_text

    from fuzzing import examples

    def accepted(text: str) -> bool:  # MuJoCo's own verdict on the description as it came
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                mujoco.MjSpec.from_string(
                    text.replace(
                        "</robot>", "<mujoco><compiler boundmass='1e-6' boundinertia='1e-9'/></mujoco></robot>"
                    )
                ).compile()
                return True
            except ValueError:
                return False

    moment = st.floats(-1e-3, 1.0) | st.sampled_from([0.0, 1e-12, 1e-6])
    product = st.floats(-0.5, 0.5) | st.just(0.0)

    @examples(60)
    @given(xx=moment, yy=moment, zz=moment, xy=product, xz=product, yz=product)
    def property_(xx, yy, zz, xy, xz, yz):
        urdf = one_link({"ixx": xx, "ixy": xy, "ixz": xz, "iyy": yy, "iyz": yz, "izz": zz})
        prepared = mujoco_text(urdf, cache=tmp_path)
        drawing_spec(prepared.text).compile()  # drawn, whatever the inertia
        assert prepared.left_out == []
        if accepted(urdf):
            assert prepared.changed == [], (xx, yy, zz, xy, xz, yz)
        else:
            assert prepared.changed == ["the inertia of 1 link replaced, which MuJoCo refuses (l)"]

    property_()


def test_a_mesh_over_mujocos_limit_is_simplified_and_one_it_refuses_is_left_out(tmp_path):
    """An STL of 327,680 triangles, over the 200,000 MuJoCo's reader takes, is drawn with 200,000 (and said);
    a mesh of one triangle, which MuJoCo refuses (fewer than 4 vertices), leaves out its visual only."""
    import trimesh

    from tutorial.core.world import drawing_spec
    from tutorial.tools.urdf.mesh_files import MAX_FACES, drawable_meshes
    from tutorial.tools.urdf.meshes import write_stl
    from tutorial.tools.urdf.mujoco_load import mujoco_text

    sphere = trimesh.creation.icosphere(subdivisions=7, radius=0.05)
    big = write_stl(tmp_path / "big.stl", sphere.vertices, sphere.faces)
    one = write_stl(tmp_path / "one.stl", np.eye(3) * 0.1, np.array([[0, 1, 2]]))
    parts = drawable_meshes(big, tmp_path / "cache")
    assert [p.simplified_from for p in parts] == [327_680] and parts[0].path != big
    assert len(trimesh.load(parts[0].path).faces) == MAX_FACES
    urdf = one_link(
        {"ixx": 0.1, "ixy": 0.0, "ixz": 0.0, "iyy": 0.1, "iyz": 0.0, "izz": 0.1}, f"<mesh filename='file://{big}'/>"
    )
    urdf = urdf.replace("</link>", f"<visual><geometry><mesh filename='file://{one}'/></geometry></visual></link>", 1)
    prepared = mujoco_text(urdf, cache=tmp_path / "cache")
    assert prepared.changed == ["1 mesh over MuJoCo's 200,000 triangles simplified to that many (big.stl had 327,680)"]
    assert len(prepared.left_out) == 1 and prepared.left_out[0].startswith(
        f"link l: visual left out: file://{one}: MuJoCo refuses it (at least 4 vertices required"
    ), prepared.left_out
    model = drawing_spec(prepared.text).compile()
    assert model.nmesh == 1 and model.mesh_facenum[0] == MAX_FACES


def test_package_uris_are_found_as_ros_finds_them(tmp_path):
    from tutorial.tools.urdf.mesh_files import MeshError, resolve_mesh

    ament, ros1 = tmp_path / "install", tmp_path / "src"
    (ament / "share" / "arm" / "meshes").mkdir(parents=True)
    (ament / "share" / "arm" / "meshes" / "a.stl").write_text("solid")
    (ros1 / "gripper" / "meshes").mkdir(parents=True)
    (ros1 / "gripper" / "meshes" / "g.stl").write_text("solid")
    env = {"AMENT_PREFIX_PATH": f"{tmp_path / 'other'}{os.pathsep}{ament}", "ROS_PACKAGE_PATH": str(ros1)}
    assert resolve_mesh("package://arm/meshes/a.stl", env) == ament / "share" / "arm" / "meshes" / "a.stl"
    assert resolve_mesh("package://gripper/meshes/g.stl", env) == ros1 / "gripper" / "meshes" / "g.stl"
    assert resolve_mesh(f"file://{ament}/share/arm/meshes/a.stl", env).name == "a.stl"
    with pytest.raises(MeshError, match=r"package://arm/meshes/b.stl: not found \(looked in .*other/share/arm"):
        resolve_mesh("package://arm/meshes/b.stl", env)
    with pytest.raises(MeshError, match="http:// names cannot be read here"):
        resolve_mesh("http://example.com/a.stl", env)


def test_a_converted_mesh_is_cached(tmp_path):
    from tutorial.tools.urdf.mesh_files import drawable_meshes

    dae = ROBOTS / "panda_description" / "meshes" / "visual" / "link0.dae"
    cold = drawable_meshes(dae, tmp_path)
    warm = drawable_meshes(dae, tmp_path)
    assert cold == warm and all(p.path.suffix == ".stl" and p.path.is_file() for p in cold)
    assert len({p.rgba for p in cold}) == len(cold) > 1  # the file's colours, one STL each
    assert {p.simplified_from for p in cold} == {None}
    stamps = [p.path.stat().st_mtime_ns for p in warm]
    drawable_meshes(dae, tmp_path)
    assert [p.path.stat().st_mtime_ns for p in warm] == stamps  # not written again


def light_grey_pixels(image: np.ndarray) -> int:
    """Pixels of a white or light grey robot (the Panda's paint) against meshcat's blue background."""
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    return int(np.count_nonzero((abs(r - b) < 0.08) & (abs(r - g) < 0.08) & (r > 0.6)))


PICTURED = {
    "Panda": "panda_description/urdf/panda.urdf",
    "UR5": "ur_description/urdf/ur5_robot.urdf",
    "SO100": "so_arm_description/urdf/so100.urdf",
    "Go2": "go2_description/urdf/go2.urdf",
}


@pytest.mark.browser
@pytest.mark.parametrize(
    "name", [n if n == "Panda" else pytest.param(n, marks=pytest.mark.slow) for n in PICTURED]
)  # make test draws the Panda; make test-robots the other three
def test_the_robot_is_drawn_with_its_meshes(ros, node, tmp_path, monkeypatch, name):
    """In Chromium: the robot's meshes are on the page; with its meshes unfound, only meshcat's background is."""
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from std_msgs.msg import String

    from tutorial.core.project import load_project
    from tutorial.tools.standalone.app import StandaloneApp

    from browser import chromium, screenshot

    if not chromium():
        pytest.skip("no chromium (make test installs Debian's)")
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(PREFIX))
    monkeypatch.setenv("RTT_MESH_CACHE", str(tmp_path / "meshes"))
    latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE)
    urdf = (ROBOTS / PICTURED[name]).read_text()
    pictures, camera = {}, []
    for case, text in (("meshes", urdf), ("no meshes", urdf.replace("package://", "package://missing_"))):
        topic = f"/{name}_{len(pictures)}/robot_description"
        node.create_publisher(String, topic, latched).publish(String(data=text))
        records = []
        (tmp_path / "p.yaml").write_text(f"name: p\nmodels:\n  - name: {name}\n    description: {topic}\n")
        app = StandaloneApp(load_project(tmp_path / "p.yaml"), node_name=f"page_{len(pictures)}", output=records.append)
        try:
            app.open()
            camera += [] if camera else [app.camera]  # the robot framed, then the same view without its meshes
            app.scene.set_camera(*camera[0])
            app.step(0.1)
            url = next(r["url"] for r in records if r.get("event") == "meshcat")
            pictures[case] = screenshot(url, tmp_path / f"{len(pictures)}.png")
            warnings = [r for r in records if r.get("event") == "warning"]
            assert (len(warnings) == 0) == (case == "meshes"), warnings
        finally:
            app.close()
    changed = int(np.count_nonzero(np.abs(pictures["meshes"] - pictures["no meshes"]).sum(axis=-1) > 0.15))
    print(f"{name}: {changed} pixels drawn by its meshes, {light_grey_pixels(pictures['meshes'])} light grey")
    assert changed > 600, changed  # the meshes are drawn: not a blank page (the small SO-100: about 1,300)
    if name == "Panda":  # white and light grey paint against meshcat's blue; none without the meshes
        assert light_grey_pixels(pictures["meshes"]) > 1000 and light_grey_pixels(pictures["no meshes"]) < 500


def test_a_floating_base_stands_where_its_odometry_puts_it(ros, node, tmp_path, monkeypatch):
    """Unitree's Go2 (Collada visuals, a floating base): the root link follows /Go2/odom, refused poses are counted.

    Started after the robot's last pose, the viewer shows it (a late joiner).

    Each link must land where the odometry's pose times ``yourdfpy``'s forward
    kinematics puts it; a pose with a NaN, another child frame, a zero
    quaternion or 2,000 km away must leave the robot where it was.
    """
    import mujoco
    import yourdfpy
    from nav_msgs.msg import Odometry
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from sensor_msgs.msg import JointState
    from std_msgs.msg import String

    from tutorial.core.project import load_project
    from tutorial.interfaces.joint_state import joint_state_qos
    from tutorial.tools.standalone.app import StandaloneApp

    monkeypatch.setenv("AMENT_PREFIX_PATH", str(PREFIX))
    monkeypatch.setenv("RTT_MESH_CACHE", str(tmp_path / "meshes"))
    path = ROBOTS / "go2_description" / "urdf" / "go2.urdf"
    latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE)
    node.create_publisher(String, "/Go2/robot_description", latched).publish(String(data=path.read_text()))
    states = node.create_publisher(JointState, "/Go2/joint_state", joint_state_qos())
    odometry = node.create_publisher(Odometry, "/Go2/odom", joint_state_qos())
    (tmp_path / "go2.yaml").write_text(
        "name: go2\nmodels:\n  - name: Go2\n    description: /Go2/robot_description\n    odometry: /Go2/odom\n"
        "    controllers:\n      - name: RttJointStateMonitor\n"
        "        class: tutorial.controllers.joint_state_subscriber:RttJointStateMonitor\n"
    )
    robot = yourdfpy.URDF.load(str(path), load_meshes=False, build_collision_scene_graph=False)
    moving = list(robot.actuated_joint_names)

    def pose(x, y, z, q, child="base"):
        msg = Odometry()
        msg.header.frame_id, msg.child_frame_id = "odom", child
        p, o = msg.pose.pose.position, msg.pose.pose.orientation
        p.x, p.y, p.z = x, y, z
        o.w, o.x, o.y, o.z = q
        return msg

    odometry.publish(pose(-2.0, 1.0, 0.25, (1.0, 0.0, 0.0, 0.0)))  # kept (transient local) for a viewer to come
    records = []
    app = StandaloneApp(
        load_project(tmp_path / "go2.yaml"), node_name="monitor_go2", headless=True, output=records.append
    )
    try:
        app.open()
        assert [r for r in records if r.get("event") == "warning"] == []
        body, base = app.bodies["Go2"], app.controller("Go2/floating_base")
        assert base.root_link == robot.base_link == "base"
        app.loop.run_until(lambda: base.applied == 1, timeout=10)  # the late joiner stands where the robot was
        assert base.summary()["position"] == [-2.0, 1.0, 0.25] and base.late_subscription is None
        app.loop.run_until(lambda: odometry.get_subscription_count() > 0, timeout=10)

        def handled():
            return base.applied + sum(base.rejected.values())

        yaw, roll = 0.7, 0.1  # a turn and a lean: w x y z of Rz(yaw) Rx(roll)
        q = (
            math.cos(yaw / 2) * math.cos(roll / 2),
            math.cos(yaw / 2) * math.sin(roll / 2),
            math.sin(yaw / 2) * math.sin(roll / 2),
            math.sin(yaw / 2) * math.cos(roll / 2),
        )
        good = (1.5, -0.5, 0.3)
        for msg in (
            pose(*good, q=tuple(1.004 * c for c in q)),  # a little off unit: renormalised
            pose(float("nan"), 0.0, 0.3, q),
            pose(9.0, 9.0, 9.0, q, child="odom_base"),
            pose(9.0, 9.0, 9.0, (0.0, 0.0, 0.0, 0.0)),
            pose(9.0, 9.0, 9.0, (2.0, 0.0, 0.0, 0.0)),
            pose(2e6, 0.0, 0.3, q),  # 2,000 km away
        ):
            before = handled()
            odometry.publish(msg)
            app.loop.run_until(lambda before=before: handled() > before, timeout=10)
        assert base.applied == 2
        assert base.rejected == {"not_finite": 1, "wrong_frame": 1, "not_a_unit_quaternion": 2, "too_far": 1}
        warned = [r["message"] for r in records if r.get("event") == "warning"]
        assert len(warned) == 4 and "'odom_base'" in warned[1], warned  # once per reason, naming the frame

        final = {}  # inside each joint's limits (yourdfpy would clamp a position outside them)
        for j, n in enumerate(moving):
            limit = robot.joint_map[n].limit
            final[n] = limit.lower + (limit.upper - limit.lower) * (0.5 + 0.4 * math.sin(j + 1.0))
        states.publish(JointState(name=moving, position=list(final.values())))
        app.loop.run_until(lambda: all(abs(body.joint(n).q - final[n]) <= 1e-9 for n in moving), timeout=30)

        root = np.eye(4)
        rotation = np.zeros(9)
        mujoco.mju_quat2Mat(rotation, np.array(q) / np.linalg.norm(q))
        root[:3, :3], root[:3, 3] = rotation.reshape(3, 3), good
        robot.update_cfg(final)
        for link in robot.robot.links:
            b = mujoco.mj_name2id(app.model, mujoco.mjtObj.mjOBJ_BODY, f"Go2/{link.name}")
            assert b >= 0, f"no body for link {link.name}"
            expected = root @ robot.get_transform(link.name, robot.base_link)
            assert np.abs(app.data.xpos[b] - expected[:3, 3]).max() <= 1e-6, link.name
            assert np.abs(app.data.xmat[b].reshape(3, 3) - expected[:3, :3]).max() <= 1e-6, link.name
        summary = base.summary()
        assert summary["position"] == list(good) and summary["applied"] == 2
        assert np.allclose(summary["orientation_wxyz"], q, atol=1e-9)  # renormalised, w first
    finally:
        app.close()


def test_odometry_needs_a_root_free_of_the_world(tmp_path):
    """A root already floating keeps its free joint; one on a hinge, or two roots, cannot take a pose, and say so."""
    import mujoco

    from tutorial.core.world import ModelEntry, ModelError, build_world

    floating = "<mujoco><worldbody><body name='base'><freejoint/><geom size='.1'/></body></worldbody></mujoco>"
    hinged = "<mujoco><worldbody><body name='base'><joint type='hinge'/><geom size='.1'/></body></worldbody></mujoco>"
    welded = "<mujoco><worldbody><body name='base'><geom size='.1'/></body></worldbody></mujoco>"
    for text, joints in ((floating, 1), (welded, 1)):
        model = build_world([ModelEntry("R", None, text=text, odometry="/R/odom")])
        assert model.njnt == joints and model.jnt_type[0] == 0  # one free joint, whichever way it came
    assert build_world([ModelEntry("R", None, text=welded)]).njnt == 0  # without odometry: welded, as it was
    with pytest.raises(ModelError, match="its root link base moves on 1 other joint"):
        build_world([ModelEntry("R", None, text=hinged, odometry="/R/odom")])
    two = "<mujoco><worldbody><body name='a'><geom size='.1'/></body>"
    two += "<body name='b'><geom size='.1'/></body></worldbody></mujoco>"
    with pytest.raises(ModelError, match=r"has 2 top-level bodies \(a, b\): odometry places one root link"):
        build_world([ModelEntry("R", None, text=two, odometry="/R/odom")])
    named = "<mujoco><worldbody><body name='base'><geom size='.1'/><body name='c'><joint name='floating_base'/>"
    named += "<geom size='.1'/></body></body></worldbody></mujoco>"
    model = build_world([ModelEntry("R", None, text=named, odometry="/R/odom")])  # the name is taken: another
    names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(model.njnt)]
    assert names == ["R/floating_base_1", "R/floating_base"] and model.jnt_type[0] == 0
