"""``rtt-bag record --tf``: the /tf in a recording puts every link where the simulation had it.

A Step 2 simulation (with the robot model publisher) drives the demo script
in real time while a recorder with ``tf=True`` runs in the same process (two
nodes, over ROS 2); a probe controller keeps the simulation's ``qpos`` at
every step.  ``rosbags``, a reader we did not write, decodes ``/tf`` and
``/tf_static`` from the file (``tf2_msgs/msg/TFMessage``, from the definition
stored in it); for each stamp on ``/tf`` the tree gives the root link's pose
and every link's pose in ``world``, which must equal MuJoCo's forward
kinematics of the probe's ``qpos`` at that step.  The road wheels' spin is
the one thing left out, by design: their joints (group 3, not in JointState)
are fixed in the URDF, so a wheel's pose is checked with its joint at its
reference angle, and its position against the spinning wheel's.
"""

from __future__ import annotations

import numpy as np
import pytest

from tutorial.core.controller import SimpleController

from conftest import PROJECT

pytestmark = pytest.mark.ros

TOLERANCE = 1e-9  # m, and a rotation matrix's entries


class Probe(SimpleController):
    """Keeps ``qpos`` of every step, by step number (simulation thread; read after the run)."""

    def initialize(self, io) -> bool:
        self.io, self.qpos = io, {}
        return True

    def control(self) -> bool:
        self.qpos[round(self.io.current_time / self.io.time_step)] = self.io.data.qpos.copy()
        return True

    def stop(self) -> None:  # the final state, which the publishers send once more
        self.control()


def transform_matrix(t) -> np.ndarray:
    from tutorial.tools.urdf.frames import pose_matrix

    r, p = t.transform.rotation, t.transform.translation
    return pose_matrix((p.x, p.y, p.z), (r.w, r.x, r.y, r.z))


def test_tf_in_a_recording_is_the_simulation(ros, tmp_path):
    import mujoco
    from rosbags.highlevel import AnyReader

    from tutorial.app.app import App
    from tutorial.app.reference.robot_model_publisher import RttRobotModelPublisher
    from tutorial.core.project import load_project
    from tutorial.joystick.scripted import ScriptedJoy
    from tutorial.tools.bag.record import BagRecorder

    path = tmp_path / "drive_tf.mcap"
    recorder = BagRecorder(path, [], tf=True, output=None, node_name="tf_test_bag").start()
    probe = Probe()
    app = App(
        load_project(PROJECT / "step2.yaml").with_controller("Tank", "RttRobotModelPublisher", RttRobotModelPublisher),
        node_name="tf_test_sim",
        headless=True,
        realtime_sync=True,
        duration=4.0,
        output=lambda record: None,
        attach=[("Tank", "Probe", probe)],
    )
    app.attach.insert(0, ("Tank", "ScriptedJoy", ScriptedJoy(lambda: app.controller("RttTankController"))))
    try:
        app.open()
        app.run()
    finally:
        app.close()
        stats = recorder.close()
    assert recorder.tf.rejected == {}
    assert {"/tf", "/tf_static", "/robot_description", "/Tank/odom", "/Tank/joint_state"} <= set(stats.per_topic)

    static, moving = {}, []  # child -> matrix; (stamp ns, [transforms]) in log order
    with AnyReader([path]) as reader:
        types = {c.topic: c.msgtype for c in reader.connections}
        assert types["/tf"] == types["/tf_static"] == "tf2_msgs/msg/TFMessage"
        for connection, _, raw in reader.messages():
            if connection.topic not in ("/tf", "/tf_static"):
                continue
            msg = reader.deserialize(raw, connection.msgtype)
            if connection.topic == "/tf_static":
                static = {t.child_frame_id: (t.header.frame_id, transform_matrix(t)) for t in msg.transforms}
            else:
                for t in msg.transforms:
                    stamp = t.header.stamp.sec * 1_000_000_000 + t.header.stamp.nanosec
                    moving.append((stamp, t))
    assert len(static) == 10

    # The tree at each stamp: the fixed joints, and the moving transforms stamped then.
    by_stamp: dict[int, dict] = {}
    for stamp, t in moving:
        by_stamp.setdefault(stamp, {})[t.child_frame_id] = (t.header.frame_id, transform_matrix(t))
    complete = {s: tree for s, tree in by_stamp.items() if {"CHASSIS", "TURRET_Y", "TURRET_P"} <= set(tree)}
    assert len(complete) > 100, len(complete)  # 4 s at 50 Hz, less what came before discovery

    model = app.model
    data = mujoco.MjData(model)
    body = app.bodies["Tank"]
    links = {mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b).split("/", 1)[1]: b for b in body.body_ids}
    step = model.opt.timestep
    spinning = mujoco.MjData(model)
    wheels = [model.jnt_qposadr[j] for j in body.joint_ids if model.jnt_group[j] == 3]
    assert len(wheels) == 8
    worst, moved, wheel_position = 0.0, 0.0, 0.0
    first_root = None
    for stamp, tree in sorted(complete.items()):
        qpos = probe.qpos[round(stamp * 1e-9 / step)]
        spinning.qpos[:] = qpos
        mujoco.mj_kinematics(model, spinning)
        # The road wheels' joints (group 3, not in JointState) are fixed in the URDF at their
        # reference angle (tutorial/tools/urdf/export.py): the simulation's pose with them there.
        data.qpos[:] = qpos
        data.qpos[wheels] = model.qpos0[wheels]
        mujoco.mj_kinematics(model, data)
        frames = {**static, **tree}
        assert frames["CHASSIS"][0] == "world"
        for link, b in links.items():
            pose, frame = np.eye(4), link
            while frame != "world":
                parent, matrix = frames[frame]
                pose, frame = matrix @ pose, parent
            simulated = np.eye(4)
            simulated[:3, :3] = data.xmat[b].reshape(3, 3)
            simulated[:3, 3] = data.xpos[b]
            worst = max(worst, np.abs(pose - simulated).max())
            wheel_position = max(wheel_position, np.abs(pose[:3, 3] - spinning.xpos[b]).max())
        root = frames["CHASSIS"][1]
        first_root = root if first_root is None else first_root
        moved = max(moved, np.linalg.norm(root[:3, 3] - first_root[:3, 3]))
    assert worst <= TOLERANCE, worst
    assert wheel_position <= TOLERANCE  # a wheel turns about its own origin: where it is, exactly
    assert moved > 0.1  # the tank drove: the root's pose on /tf followed it
