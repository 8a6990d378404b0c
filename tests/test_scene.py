"""The scene sends a body's pose only when it moved, and each moved body exactly once per frame."""

import mujoco
import numpy as np

from tutorial.core.body import Body
from tutorial.core.world import ModelEntry, build_world
from tutorial.view.scene import POSE_TOLERANCE, Scene

from conftest import MODEL


class RecordingWindow:
    """Stands in for meshcat's window: records each ``SetTransform`` sent, by path."""

    def __init__(self, sent: dict):
        self.sent = sent

    def send(self, command):
        self.sent[str(command.path)] = np.array(command.matrix)


class RecordingVisualizer:
    """Stands in for ``meshcat.Visualizer``: records the transforms sent, by path (no server, no pipeline)."""

    def __init__(self, sent=None, path="meshcat"):
        self.sent = {} if sent is None else sent
        self.path = path
        self.window = RecordingWindow(self.sent)

    def __getitem__(self, path):
        return RecordingVisualizer(self.sent, f"{self.path}/{path}")

    def set_transform(self, matrix):
        self.sent[self.path] = np.array(matrix)

    def set_object(self, *args):
        pass

    def set_property(self, *args):
        pass

    def delete(self):
        pass


def tank_scene():
    model = build_world([ModelEntry("Tank", MODEL / "tank.xml")])
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    vis = RecordingVisualizer()
    scene = Scene(vis, model)
    scene.build(data)
    return model, data, vis, scene


def test_first_frame_sends_every_moving_body_then_nothing_until_one_moves():
    model, data, vis, scene = tank_scene()
    assert scene.transforms_sent == len(scene.moving_bodies) > 1  # build() drew the first frame
    vis.sent.clear()
    assert scene.update(data) == 0 and vis.sent == {}

    Body(model, data, "Tank").joint("TURRET_P").q = 0.3  # only the barrel moves
    mujoco.mj_kinematics(model, data)
    assert scene.update(data) == 1
    [(path, pose)] = vis.sent.items()
    barrel = next(b for b in scene.moving_bodies if path.endswith(scene.body_path(b)))
    np.testing.assert_allclose(pose[:3, 3], data.xpos[barrel])
    np.testing.assert_allclose(pose[:3, :3], data.xmat[barrel].reshape(3, 3))
    assert scene.update(data) == 0  # sent once, not again


def test_a_move_within_the_tolerance_is_not_sent_and_a_nan_pose_is():
    model, data, vis, scene = tank_scene()
    b = scene.moving_bodies[0]
    data.xpos[b, 0] += 0.5 * POSE_TOLERANCE
    assert scene.update(data) == 0
    data.xpos[b, 0] += 4 * POSE_TOLERANCE
    assert scene.update(data) == 1
    data.xpos[b, 1] = np.nan  # never equal to what was sent: sent, as the view must show something is wrong
    assert scene.update(data) == 1


WELDED = """
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="2 2 0.1"/>
    <body name="base" pos="0.1 0.2 0.3" quat="0.9 0.1 0.3 0.2">
      <freejoint/>
      <geom name="hull" type="box" size="0.2 0.1 0.05"/>
      <body name="plate" pos="0.05 -0.1 0.02" quat="0.7 0.7 0 0">
        <geom name="plate" type="box" size="0.02 0.03 0.04" pos="0.01 0.02 0.03" quat="0.8 0 0.6 0"/>
        <body name="bracket" pos="0.2 0.05 -0.1" quat="0.5 0.5 0.5 0.5">
          <geom name="bracket" type="box" size="0.03 0.01 0.02" pos="0.02 0 0.01"/>
        </body>
        <body name="arm" pos="0 0 0.1">
          <joint name="hinge" type="hinge" axis="0 1 0"/>
          <geom name="arm" type="box" size="0.1 0.01 0.01" pos="0.1 0 0"/>
        </body>
      </body>
    </body>
    <body name="target" mocap="true" pos="1 0 0.5">
      <geom name="target" type="sphere" size="0.05" contype="0" conaffinity="0"/>
    </body>
  </worldbody>
</mujoco>
"""


def drawn_world_poses(vis, scene, model):
    """Each box or sphere geom's world pose as drawn: its frame body's transform times its own."""
    out = {}
    for gid in range(model.ngeom):
        if model.geom_type[gid] not in (int(mujoco.mjtGeom.mjGEOM_BOX), int(mujoco.mjtGeom.mjGEOM_SPHERE)):
            continue  # drawn with an extra local pose of their own (planes, cylinders, capsules)
        frame = scene.frame_body(int(model.geom_bodyid[gid]))
        parent = f"meshcat/{scene.root}/static" if frame == 0 else f"meshcat/{scene.body_path(frame)}"
        geom = vis.sent[f"{parent}/geom{gid}"]
        out[gid] = geom if frame == 0 else vis.sent[parent] @ geom
    return out


def test_a_welded_body_rides_in_its_parents_frame_and_is_drawn_where_mujoco_puts_it():
    model = mujoco.MjModel.from_xml_string(WELDED)
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    vis = RecordingVisualizer()
    scene = Scene(vis, model)
    scene.build(data)

    def name(b):
        return mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b)

    assert [name(b) for b in scene.moving_bodies] == ["base", "arm", "target"]  # plate, bracket ride with the base
    assert scene.frame_body(model.body("plate").id) == model.body("base").id
    assert scene.frame_body(model.body("bracket").id) == model.body("base").id  # two welds up

    rng = np.random.default_rng(3)
    for _ in range(3):  # move everything: the free joint, the hinge, the mocap body
        data.qpos[:3] += rng.normal(size=3)
        quat = rng.normal(size=4)
        data.qpos[3:7] = quat / np.linalg.norm(quat)
        data.qpos[7] = rng.uniform(-3, 3)
        data.mocap_pos[0] += rng.normal(size=3)
        mujoco.mj_kinematics(model, data)
        assert scene.update(data) == 3
        drawn_poses = drawn_world_poses(vis, scene, model)
        assert len(drawn_poses) == 5
        for gid, drawn in drawn_poses.items():
            np.testing.assert_allclose(drawn[:3, 3], data.geom_xpos[gid], atol=1e-12)
            np.testing.assert_allclose(drawn[:3, :3], data.geom_xmat[gid].reshape(3, 3), atol=1e-12)


def test_a_tank_frame_sends_chassis_turret_and_barrel_not_its_tracks():
    model, data, vis, scene = tank_scene()
    names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b) for b in scene.moving_bodies]
    assert names == ["Tank/CHASSIS", "Tank/TURRET_Y", "Tank/TURRET_P"]


def test_the_pipeline_packs_what_meshcat_python_packs():
    import umsgpack
    from meshcat.commands import SetTransform

    from tutorial.tools.standalone.sinks import pack_command

    class Path:
        def lower(self):
            return "/meshcat/rtt/Tank/CHASSIS"

    pose = np.eye(4)
    pose[:3, 3] = (0.1234567890123, -2.5, 1e-300)
    command = SetTransform(pose, Path()).lower()
    assert pack_command(command) == umsgpack.packb(command)


# ---- overlays: arrows a controller draws over the view ----------------------------------


class CommandVisualizer(RecordingVisualizer):
    """A RecordingVisualizer that also keeps every command, in order: (kind, path, value)."""

    def __init__(self, sent=None, path="meshcat", log=None):
        super().__init__(sent, path)
        self.log = [] if log is None else log

    def __getitem__(self, path):
        return CommandVisualizer(self.sent, f"{self.path}/{path}", self.log)

    def set_transform(self, matrix):
        super().set_transform(matrix)
        self.log.append(("transform", self.path, np.array(matrix)))

    def set_object(self, geometry, material=None):
        self.log.append(("object", self.path, geometry))

    def set_property(self, key, value):
        self.log.append((key, self.path, value))

    def delete(self):
        self.log.append(("delete", self.path, None))


def tip_of(shaft, head):
    """Where an arrow drawn with these transforms ends: the cone's apex, and where its shaft starts."""
    from tutorial.view.meshcat_overlays import HEAD_LENGTH

    apex = head @ np.array([0.0, HEAD_LENGTH / 2, 0.0, 1.0])
    tail = shaft @ np.array([0.0, -0.5, 0.0, 1.0])  # the shaft is a unit cylinder along meshcat's Y
    return tail[:3], apex[:3]


def test_an_arrow_is_drawn_from_its_origin_to_origin_plus_vector():
    from tutorial.view.meshcat_overlays import arrow_transforms

    for origin, vector in [
        ((0, 0, 0.1), (0.3, 0.4, 0.0)),
        ((1, 2, 3), (0, 0, -0.5)),
        ((0, 0, 0), (0.01, 0, 0.02)),
        ((0.5, 0, 0), (1e-3, 0, 0)),
    ]:
        shaft, head = arrow_transforms(origin, vector)
        tail, tip = tip_of(shaft, head)
        np.testing.assert_allclose(tail, origin, atol=1e-6)
        np.testing.assert_allclose(tip, np.add(origin, vector), atol=1e-12)
        np.testing.assert_allclose(np.linalg.norm(head[:3, 0]), 1.0)  # the head's radius is never scaled


def test_overlays_send_only_changed_arrows_and_hide_without_moving():
    from tutorial.view.meshcat_overlays import MeshcatOverlays, Overlays

    overlays = Overlays()
    red = overlays.arrow("Tank/acceleration", (1.0, 0.2, 0.2))
    blue = overlays.arrow("Tank/angular_velocity", (0.2, 0.2, 1.0))
    vis = CommandVisualizer()
    drawer = MeshcatOverlays(vis, overlays)
    assert vis.log == [("delete", "meshcat/rtt_overlays", None)]  # a previous run's arrows go
    vis.log.clear()
    assert drawer.update() == 2  # both created, both hidden: no transforms yet
    assert [c[0] for c in vis.log] == ["object", "object", "visible", "object", "object", "visible"]
    assert {c[2] for c in vis.log if c[0] == "visible"} == {False}
    vis.log.clear()
    assert drawer.update() == 0 and vis.log == []
    red.set((0, 0, 0.1), (0.5, 0, 0))
    assert drawer.update() == 1
    assert [(c[0], c[1].rsplit("/", 2)[-2:]) for c in vis.log] == [
        ("transform", ["acceleration", "shaft"]),
        ("transform", ["acceleration", "head"]),
        ("visible", ["Tank", "acceleration"]),
    ]
    vis.log.clear()
    red.set((0, 0, 0.1), (0.5, 0, 0))  # the same: nothing to send
    blue.set((0, 0, 0.1), (0, 0, 0.001), visible=False)  # hidden was hidden: no command either
    assert drawer.update() == 1 and vis.log == []
    red.set((0, 0, 0.1), (0.4, 0, 0), visible=False)
    drawer.update()
    assert [c[0] for c in vis.log] == ["visible"]
    assert red.record() == {"length": 0.4, "visible": False}


def test_an_arrow_refuses_non_finite_numbers_and_a_second_arrow_of_the_same_name():
    import pytest

    from tutorial.core.overlays import Overlays

    overlays = Overlays()
    arrow = overlays.arrow("a", (1, 0, 0))
    with pytest.raises(ValueError, match="finite"):
        arrow.set((0, 0, 0), (np.nan, 0, 0))
    with pytest.raises(ValueError, match="exists already"):
        overlays.arrow("a", (0, 0, 1))


def test_a_robot_of_any_size_is_framed_whole_and_stands_on_a_grid():
    """A robot drawn from its description has no room around it: the camera aims at the centre of its geoms and
    backs off until they fit meshcat's 75-degree view (a 1 m arm and the Panda reached the page's top edge from
    the tank's close-up), and a grid is its ground; the tank in its room keeps meshcat's grid hidden."""
    from tutorial.view.scene import look_at_geoms

    xml = """<mujoco><worldbody>
      <body name="R/base"><geom type="box" size="0.2 0.2 0.05" pos="0 0 0.05"/>
        <body name="R/arm" pos="0 0 0.1"><joint type="hinge"/><geom type="capsule" fromto="0 0 0 0 0 1.8" size="0.05"/>
        <geom type="sphere" size="0.1" pos="0 0 1.9" group="3"/></body></body>
      <geom type="plane" size="0 0 1"/></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    position, target = look_at_geoms(model, data, range(model.ngeom))
    shown = [g for g in range(model.ngeom) if model.geom_group[g] < 3 and model.geom_type[g] != 0]  # 0: plane
    for g in shown:  # each geom's bounding sphere inside the view cone
        to = data.geom_xpos[g] - position
        axis = (target - position) / np.linalg.norm(target - position)
        off_axis = np.degrees(np.arccos(np.dot(to, axis) / np.linalg.norm(to)))
        reach = np.degrees(np.arcsin(min(1.0, model.geom_rbound[g] / np.linalg.norm(to))))
        assert off_axis + reach <= 37.5, (g, off_axis, reach)
    assert 0.8 < target[2] < 1.2  # the middle of the 2 m robot, not its root
    assert look_at_geoms(model, data, [g for g in range(model.ngeom) if g not in shown]) is None  # hidden, plane

    class Vis(RecordingVisualizer):
        objects: dict = {}
        properties: dict = {}

        def __getitem__(self, path):
            return Vis(self.sent, f"{self.path}/{path}")

        def set_object(self, obj, *args):
            Vis.objects[self.path] = obj

        def set_property(self, key, value):
            Vis.properties[(self.path, key)] = value

    Scene(Vis(), model).build(data, grid=True)
    ground = next(obj for path, obj in Vis.objects.items() if path.endswith("/ground"))
    points = ground.geometry.position
    assert points.shape[0] == 3 and np.all(points[2] == 0.0) and points[:2].min() == -5.0 and points[:2].max() == 5.0
    assert Vis.properties[("meshcat//Grid", "visible")] is False  # meshcat's own stays still when the camera aims
    Vis.objects.clear()
    Scene(Vis(), model).build(data)
    assert not any(path.endswith("/ground") for path in Vis.objects)
