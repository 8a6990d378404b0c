"""The exercises' capturing node (tutorial/exercises/capture.py) over a stand-in node: no ROS, no network."""

from tutorial.exercises.capture import CapturingNode, CapturingPublisher


class RealPublisher:
    def __init__(self):
        self.destroyed = 0

    def destroy(self):
        self.destroyed += 1


class RealNode:
    """What rclpy's Node is asked for: each publisher made with its arguments, each destroyed."""

    def __init__(self):
        self.made, self.destroyed = [], []

    def create_publisher(self, msg_type, topic, qos_profile, **kwargs):
        self.made.append((msg_type, topic, qos_profile, kwargs))
        return RealPublisher()

    def destroy_publisher(self, publisher):
        self.destroyed.append(publisher)
        return True

    def get_name(self):
        return "real"


def test_a_publisher_is_made_with_every_argument_and_given_back_to_the_real_node():
    real = RealNode()
    node = CapturingNode(real)
    group = object()
    pub = node.create_publisher(str, "/a", 10, callback_group=group)
    assert real.made == [(str, "/a", 10, {"callback_group": group})]  # a controller's own options reach rclpy
    assert node.published("/a") == [pub] and node.published("/b") == [] and node.get_name() == "real"
    assert pub.destroyed is False and node.destroyed == []
    assert node.destroy_publisher(pub) is True
    assert real.destroyed == [pub.real]  # the real publisher, not the wrapper, is destroyed in rclpy
    assert pub.destroyed is True and node.destroyed == [pub]
    other = RealPublisher()
    node.destroy_publisher(other)  # a publisher the node did not wrap goes to rclpy as it is
    assert real.destroyed == [pub.real, other]


def test_a_publisher_made_alone_notes_its_own_destruction_once():
    real = RealPublisher()
    pub = CapturingPublisher(real, str, "/a")
    pub.destroy()
    pub.note_destroyed()
    assert real.destroyed == 1 and pub.destroyed is True and pub._noted == [pub]


def test_a_message_the_real_publisher_refuses_is_not_kept_and_bytes_are_kept_as_they_are():
    from std_msgs.msg import Float64

    class Refusing(RealPublisher):
        def publish(self, msg):  # as rclpy's Publisher.publish
            if not isinstance(msg, (Float64, bytes)):
                raise TypeError(f"Expected {Float64}, got {type(msg)}")

    publisher = CapturingPublisher(Refusing(), Float64, "/Tank/peak")
    try:
        publisher.publish(1.5)
    except TypeError as exc:
        assert "got <class 'float'>" in str(exc)
    else:
        raise AssertionError("a bare float was published")
    publisher.publish(b"\x00\x01\x00\x00" + bytes(8))
    publisher.publish(Float64(data=2.5))
    assert [m.data for m in publisher.messages()] == [0.0, 2.5]


class LiveNode(RealNode):
    """A stand-in that, as rclpy's Node, lists its live publishers (``publishers``), each with its QoS."""

    def __init__(self):
        super().__init__()
        self.publishers = []

    def create_publisher(self, msg_type, topic, qos_profile, **kwargs):
        publisher = super().create_publisher(msg_type, topic, qos_profile, **kwargs)
        publisher.qos_profile = qos_profile
        self.publishers.append(publisher)
        return publisher

    def destroy_publisher(self, publisher):
        self.publishers.remove(publisher)
        return super().destroy_publisher(publisher)


def test_the_record_says_destroyed_only_of_a_publisher_gone_from_the_real_node():
    """One of two publishers destroyed: that one alone, though the other still lives; a publisher the class only
    marked destroyed (gone from nothing) is not."""
    from rclpy.qos import QoSProfile
    from std_msgs.msg import Float64

    from tutorial.exercises.capture import publishers_record

    real = LiveNode()
    node = CapturingNode(real)
    gone, kept, marked = (node.create_publisher(Float64, t, QoSProfile(depth=1)) for t in ("/gone", "/kept", "/marked"))
    node.destroy_publisher(gone)
    marked.destroyed = True  # written by a class on the capturing publisher it was handed
    record = publishers_record(node)
    assert [(r["topic"], r["destroyed"]) for r in record] == [("/gone", True), ("/kept", False), ("/marked", False)]
    assert [r["type"] for r in record] == ["std_msgs/msg/Float64"] * 3


def test_a_recorded_qos_that_is_no_qos_profile_is_refused_by_name():
    import pytest

    from tutorial.exercises.capture import RecordedPublisher

    record = {"topic": "/a", "qos": "reliable", "type": "std_msgs/msg/Float64", "destroyed": False, "messages": []}
    with pytest.raises(TypeError, match=r"^a publisher's QoS recorded as 'reliable'$"):
        RecordedPublisher(record)


def test_a_recorded_node_holds_each_recorded_publisher_by_topic():
    from rclpy.qos import QoSProfile
    from std_msgs.msg import Float64

    from tutorial.exercises.capture import RecordedNode

    def record(topic):
        return {"topic": topic, "qos": QoSProfile(depth=1), "type": "std_msgs/msg/Float64", "destroyed": False,
                "messages": [Float64(data=1.0)]}  # fmt: skip

    node = RecordedNode([record("/a"), record("/b")])
    assert [p.topic for p in node.published()] == ["/a", "/b"] and [p.topic for p in node.published("/b")] == ["/b"]
    assert node.published("/a")[0].msg_type is Float64 and node.published("/a")[0].messages() == [Float64(data=1.0)]


def test_a_recorded_type_not_checked_is_a_class_of_its_name_alone():
    """A type no check names is not imported: a class of that name stands for it (what a failing line says), or of
    the name "message" when the part after the first /msg/ is no Python name."""
    from tutorial.exercises.capture import _message_class

    fake = _message_class("std_msgs/msg/Float32")
    assert fake.__name__ == "Float32" and fake.__module__ != "std_msgs.msg._float32"
    assert _message_class("pkg/msg/not a name").__name__ == "message"
    assert _message_class("pkg/msg/sub/msg/Name").__name__ == "message"  # "sub/msg/Name" is no name
