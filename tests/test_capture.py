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
