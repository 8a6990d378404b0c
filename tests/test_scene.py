"""The scene sends a body's pose only when it moved, and each moved body exactly once per frame."""

import mujoco
import numpy as np

from tutorial.body import Body
from tutorial.scene import POSE_TOLERANCE, Scene
from tutorial.world import ModelEntry, build_world
from conftest import MODEL


class RecordingVisualizer:
    """Stands in for ``meshcat.Visualizer``: records the transforms sent, by path (no server, no pipeline)."""

    def __init__(self, sent=None, path="meshcat"):
        self.sent = {} if sent is None else sent
        self.path = path

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
