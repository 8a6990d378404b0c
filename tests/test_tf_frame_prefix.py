"""Two tanks in one TF tree (tutorial/tools/bag/record_tf.py): with ``frame_prefix="{body}/"`` their frames are
apart, without it a warning says they collide.

Unit tier: messages are serialized with rclpy (no context, no node) and fed to a :class:`TfRecording` writing
into a list; ``rtt-bag record --tf-frame-prefix`` is checked for its arguments only."""

from __future__ import annotations

import io

import pytest

from tutorial.interfaces.tf import decode_tf_message
from tutorial.tools.bag.record_tf import TfRecording, check_frame_prefix
from tutorial.tools.urdf.export import export_model_file

from conftest import MODEL


class ListWriter:
    """What TfRecording writes, as ``(topic, log_time, data)`` in order."""

    def __init__(self):
        self.topics, self.messages = {}, []

    def add_topic(self, topic, type_name, definition, profiles):
        self.topics[topic] = type_name

    def write(self, topic, log_time, publish_time, data) -> bool:
        self.messages.append((topic, log_time, data))
        return True


@pytest.fixture(scope="module")
def tank_urdf() -> str:
    _, export = export_model_file(MODEL / "tank.xml", "Tank")
    return export.xml()


def feed(recording: TfRecording, body: str, urdf: str, t_ns: int) -> None:
    """``body``'s description, one joint state and one odometry, at ``t_ns``."""
    from nav_msgs.msg import Odometry
    from rclpy.serialization import serialize_message
    from sensor_msgs.msg import JointState
    from std_msgs.msg import String

    recording.on_message(
        f"/{body}/robot_description", "std_msgs/msg/String", serialize_message(String(data=urdf)), t_ns
    )
    state = JointState(name=["TURRET_Y", "TURRET_P"], position=[0.5, -0.2])
    state.header.stamp.sec, state.header.stamp.nanosec = divmod(t_ns, 1_000_000_000)
    recording.on_message(f"/{body}/joint_state", "sensor_msgs/msg/JointState", serialize_message(state), t_ns)
    odom = Odometry(child_frame_id="CHASSIS")
    odom.header.frame_id = "world"
    odom.header.stamp = state.header.stamp
    odom.pose.pose.orientation.w = 1.0
    recording.on_message(f"/{body}/odom", "nav_msgs/msg/Odometry", serialize_message(odom), t_ns)


def frames(writer: ListWriter) -> tuple[set, set, set]:
    """(parents, children) of every transform written, and the static children of the newest /tf_static."""
    parents, children, static = set(), set(), set()
    for topic, _, data in writer.messages:
        if topic in ("/tf", "/tf_static"):
            transforms = decode_tf_message(data)
            parents |= {t.parent for t in transforms}
            children |= {t.child for t in transforms}
            if topic == "/tf_static":
                static = {t.child for t in transforms}
    return parents, children, static


def description_written(writer: ListWriter) -> str:
    from rclpy.serialization import deserialize_message
    from std_msgs.msg import String

    [data] = [d for topic, _, d in writer.messages if topic == "/robot_description"]
    return deserialize_message(data, String).data


def test_with_a_body_prefix_two_tanks_have_frames_of_their_own(tank_urdf):
    writer, said = ListWriter(), []
    recording = TfRecording(writer, said.append, frame_prefix="{body}/")
    feed(recording, "Tank", tank_urdf, 1_000_000_000)
    feed(recording, "Tank2", tank_urdf, 2_000_000_000)
    parents, children, static = frames(writer)
    for body in ("Tank", "Tank2"):
        assert {f"{body}/CHASSIS", f"{body}/TURRET_Y", f"{body}/TURRET_P"} <= children
    assert parents - children == {"world"}  # one tree: every frame but the world has a parent written
    assert all(c.startswith(("Tank/", "Tank2/")) for c in children)
    assert len([c for c in static if c.startswith("Tank/")]) == len([c for c in static if c.startswith("Tank2/")]) > 0
    assert recording.collisions == [] and not [line for line in said if "WARNING" in line]
    assert any(line.startswith("TF of Tank2: root link Tank2/CHASSIS,") for line in said), said
    # /robot_description is the first body's, its links named as its frames are; its joints keep their names.
    import yourdfpy

    robot = yourdfpy.URDF.load(
        io.BytesIO(description_written(writer).encode()), build_scene_graph=False, load_meshes=False
    )
    assert robot.link_map and all(name.startswith("Tank/") for name in robot.link_map)
    assert "TURRET_Y" in robot.joint_map and robot.joint_map["TURRET_Y"].child == "Tank/TURRET_Y"
    assert recording.rejected == {}


def test_without_a_prefix_colliding_frames_are_warned_once(tank_urdf):
    writer, said = ListWriter(), []
    recording = TfRecording(writer, said.append)
    feed(recording, "Tank", tank_urdf, 1_000_000_000)
    assert recording.collisions == []
    feed(recording, "Tank2", tank_urdf, 2_000_000_000)
    feed(recording, "Tank2", tank_urdf, 3_000_000_000)  # Tank2's description again: no second warning
    assert recording.collisions == [("Tank2", "Tank")]
    [warning] = [line for line in said if line.startswith("WARNING")]
    assert "Tank2 and Tank have links of the same name" in warning and "--tf-frame-prefix '{body}/'" in warning
    _, children, _ = frames(writer)
    assert "CHASSIS" in children and not any("/" in c for c in children)  # unprefixed, as before
    assert description_written(writer) == tank_urdf  # the first body's, as it came


@pytest.mark.parametrize(
    "bad",
    ["{name}/", "{0}/", "{}/", "{body", "body}", "{body.x}/", "{body[3]}/", "{body!r}/", "{body:>8}/", "/{body}/"],
)
def test_a_bad_prefix_is_refused(bad):
    with pytest.raises(ValueError, match="bad frame prefix"):
        check_frame_prefix(bad)
    with pytest.raises(ValueError, match="bad frame prefix"):
        TfRecording(ListWriter(), print, frame_prefix=bad)


def test_a_prefix_without_body_still_collides_and_is_warned(tank_urdf):
    writer, said = ListWriter(), []
    recording = TfRecording(writer, said.append, frame_prefix="robot/")
    feed(recording, "Tank", tank_urdf, 1_000_000_000)
    feed(recording, "Tank2", tank_urdf, 2_000_000_000)
    assert recording.collisions == [("Tank2", "Tank")]
    _, children, _ = frames(writer)
    assert "robot/CHASSIS" in children and not any(c.startswith("Tank") for c in children)


@pytest.mark.parametrize("program", ["rtt-bag", "rtt-foxglove"])
def test_the_programs_refuse_a_bad_prefix_before_anything_starts(tmp_path, capsys, program):
    from tutorial.tools import rtt_bag, rtt_foxglove

    out = tmp_path / "x.mcap"
    argv = ["rtt-bag", "record", "--tf", "-o", str(out)] if program == "rtt-bag" else ["rtt-foxglove"]
    with pytest.raises(SystemExit) as exit_:
        (rtt_bag.main if program == "rtt-bag" else rtt_foxglove.main)([*argv, "--tf-frame-prefix", "{name}/"])
    assert exit_.value.code == 2
    assert "argument --tf-frame-prefix: bad frame prefix '{name}/'" in capsys.readouterr().err
    assert not out.exists()


def test_rtt_bag_record_wants_tf_for_a_prefix(tmp_path, capsys):
    from tutorial.tools import rtt_bag

    out = tmp_path / "x.mcap"
    assert rtt_bag.main(["rtt-bag", "record", "/joy", "--tf-frame-prefix", "{body}/", "-o", str(out)]) == 2
    assert "--tf-frame-prefix needs --tf" in capsys.readouterr().err
    assert not out.exists()
