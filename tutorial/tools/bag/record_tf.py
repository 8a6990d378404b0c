"""``rtt-bag record --tf``: ``/tf``, ``/tf_static`` and ``/robot_description`` computed while recording.

Foxglove, Lichtblick and RViz2 (after ``ros2 bag play``) draw a robot in 3D
from its URDF and TF.  The simulation publishes neither TF message (no
``tf2_msgs`` wheel: rclpy cannot), but it publishes all a TF tree is made
of: each body's robot description, odometry and joint states.  A
:class:`TfRecording` attached to a :class:`tutorial.tools.bag.record.BagRecorder`
records those (it asks for them: :meth:`TfRecording.wants`) and, from each
message as it arrives, writes what ``robot_state_publisher`` and an
odometry-to-TF broadcaster would have published at that moment:

=====================================  ===========================================================
received                               written (same log time)
=====================================  ===========================================================
``/<body>/robot_description``          ``/tf_static``: one ``TFMessage`` with every fixed joint of
                                       every body so far (tf2's static topic keeps only its newest
                                       message); ``/robot_description``: the same text (its links
                                       prefixed, with a frame prefix), for the first body (the
                                       topic a URDF display reads by default)
``/<body>/joint_state``                ``/tf``: the moving joints it names, stamped with its stamp
                                       (:class:`tutorial.tools.urdf.kinematics.UrdfKinematics`)
``/<body>/odom``                       ``/tf``: ``world`` -> root link, its pose, its stamp
=====================================  ===========================================================

Joint states and odometry that come before their body's description are
kept (the newest of each) and turned into transforms once it has come.

``robot_state_publisher`` limits itself to ``publish_frequency`` (20 Hz);
here every state becomes a transform, so the file holds them all.

Several robots: two tanks have the same link names, so their frames would
collide in one TF tree.  ``frame_prefix`` does what ``robot_state_publisher``'s
parameter of that name does, per body: ``"{body}/"`` names Tank2's chassis
``Tank2/CHASSIS``, on ``/tf_static``, on ``/tf`` and as the odometry's child
(its parent, ``world``, is shared).  ``/robot_description`` (one body's)
is written with the prefix in its link names too, so a display that reads
it draws that body with no setting of its own; the recorded
``/<body>/robot_description`` stay as they came: a RobotModel display in
RViz2 given one of them takes the body's name as its "TF Prefix"
(``Tank2``, without the slash: RViz2 puts one between); a Foxglove URDF
layer's handling of prefixes was not checked here.  Without a ``{body}`` in the
prefix, a body whose link names another body already has gets one warning.

Threads: :meth:`TfRecording.on_message` runs on the recorder's spin thread
(the subscription callbacks, one at a time: a single-threaded executor);
the :class:`~tutorial.tools.bag.writer.BagWriter` it writes to has its own lock.
"""

from __future__ import annotations

from string import Formatter

from tutorial.interfaces.robot_description import DescriptionError, check_robot_description
from tutorial.interfaces.tf import (
    TF_MESSAGE_TYPE,
    TF_STATIC_TOPIC,
    TF_TOPIC,
    Transform,
    encode_tf_message,
    tf_definition,
    tf_qos,
)
from tutorial.tools.urdf.kinematics import UrdfKinematics

DESCRIPTION_TOPIC = "/robot_description"
SOURCES = {
    "robot_description": "std_msgs/msg/String",
    "joint_state": "sensor_msgs/msg/JointState",
    "odom": "nav_msgs/msg/Odometry",
}


def check_frame_prefix(frame_prefix: str) -> str:
    """``frame_prefix`` if it is text and ``{body}`` fields only, and does not start with ``/`` (any thread).

    Raises:
        ValueError: another field (``{name}``, ``{body.x}``, ``{body!r}``...),
            a lone brace, or a leading ``/`` (tf2 refuses such frame names);
            the text says which.
    """
    try:
        fields = [(name, spec, conversion) for _, name, spec, conversion in Formatter().parse(frame_prefix)]
    except ValueError as exc:  # a lone { or }
        raise ValueError(f"bad frame prefix {frame_prefix!r}: {exc}") from None
    if any(name is not None and (name != "body" or spec or conversion) for name, spec, conversion in fields):
        raise ValueError(f"bad frame prefix {frame_prefix!r}: only {{body}} may stand in it")
    if frame_prefix.startswith("/"):
        raise ValueError(f"bad frame prefix {frame_prefix!r}: a TF frame name does not start with /")
    return frame_prefix


def per_body(frame_prefix: str) -> bool:
    """Whether ``frame_prefix`` (checked) names each body's frames apart: it has a ``{body}`` field."""
    return any(name == "body" for _, name, _, _ in Formatter().parse(frame_prefix))


def prefixed_urdf(text: str, prefix: str) -> str:
    """The URDF ``text`` with ``prefix`` before every link's name, where it is named and where a joint names it.

    Joint names stay (joint states name joints).  Any thread.

    Raises:
        ValueError: ``text`` is not XML.
    """
    from lxml import etree

    try:
        robot = etree.fromstring(text.encode("utf-8"))
    except etree.XMLSyntaxError as exc:
        raise ValueError(f"not a URDF: {exc}") from None
    for link in robot.iter("link"):
        if link.getparent() is robot and link.get("name") is not None:
            link.set("name", prefix + link.get("name"))
    for joint in robot.iter("joint"):
        for end in ("parent", "child"):
            for element in joint.findall(end):
                if element.get("link") is not None:
                    element.set("link", prefix + element.get("link"))
    return etree.tostring(robot, xml_declaration=True, encoding="utf-8").decode("utf-8")


def add_frame_prefix_argument(parser) -> None:
    """``--tf-frame-prefix PREFIX`` on an ``argparse`` parser, checked as it is parsed (a bad one: exit 2)."""
    import argparse

    def checked(text: str) -> str:
        try:
            return check_frame_prefix(text)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    parser.add_argument(
        "--tf-frame-prefix",
        type=checked,
        default="",
        metavar="PREFIX",
        help="put PREFIX before every frame of a body, {body} standing for its name: '{body}/' keeps several "
        "robots' frames apart (Tank2/CHASSIS); in RViz2 give a RobotModel display the body's name (Tank2, "
        "no slash: RViz2 adds it) as its TF prefix",
    )


def body_and_kind(topic: str, type_name: str) -> tuple[str, str] | None:
    """``("Tank", "odom")`` for ``/Tank/odom`` of type ``nav_msgs/msg/Odometry``; None for any other topic."""
    parts = topic.split("/")
    if len(parts) != 3 or parts[0] or not parts[1]:
        return None
    kind = parts[2]
    if SOURCES.get(kind) != type_name:
        return None
    return parts[1], kind


class TfRecording:
    """Derives TF from a body's recorded topics, writing into the recorder's file.

    Args:
        writer: the :class:`tutorial.tools.bag.writer.BagWriter` of the recording.
        say: called with a line of text for each event worth a status line.
        frame_prefix: put before every frame of a body (not ``world``);
            ``{body}`` in it is the body's name (``"{body}/"``); ``""``: none.

    Raises:
        ValueError: a bad ``frame_prefix`` (:func:`check_frame_prefix`).

    Attributes:
        written: messages written per derived topic.
        rejected: descriptions and messages that could not be used, by reason.
        collisions: ``(body, other)`` for each body whose links share names with
            an earlier body's, recorded without a ``{body}`` in the prefix (warned once).
        newest: ``(body, "joint_state" or "odom")`` -> the stamp ``(sec, nanosec)``
            of the newest message turned into transforms (read from any thread:
            each value is replaced whole).
    """

    def __init__(self, writer, say=print, frame_prefix: str = ""):
        check_frame_prefix(frame_prefix)
        # Imported here, on the owner's thread: not in the first callback (yourdfpy takes about 1 s).
        import yourdfpy  # noqa: F401
        from rclpy.qos import QoSProfile  # noqa: F401 - fail here, not in a callback, without rclpy

        self.writer = writer
        self.say = say
        self.frame_prefix = frame_prefix
        self.bodies: dict[str, UrdfKinematics] = {}
        self.pending: dict[str, dict[str, tuple]] = {}  # body -> kind -> (data, log_time) before its description
        self.static: dict[str, list[Transform]] = {}
        self.description_body: str | None = None
        self.written = {TF_TOPIC: 0, TF_STATIC_TOPIC: 0, DESCRIPTION_TOPIC: 0}
        self.rejected: dict[str, int] = {}
        self.collisions: list[tuple[str, str]] = []  # (body, a body before it with links of the same names)
        self.newest: dict[tuple[str, str], tuple[int, int]] = {}
        self._topics_added: set[str] = set()

    # ---- what the recorder subscribes to (spin thread) ----------------------------------
    def wants(self, topic: str, type_name: str) -> bool:
        """Whether the recorder should record ``topic`` for TF (a body's description, joint state or odometry)."""
        return body_and_kind(topic, type_name) is not None

    # ---- each recorded message (spin thread) ------------------------------------------
    def on_message(self, topic: str, type_name: str, data: bytes, log_time: int) -> None:
        """Derive what this message adds to TF, and write it at ``log_time`` (ns since the epoch)."""
        found = body_and_kind(topic, type_name)
        if found is None:
            return
        body, kind = found
        if kind == "robot_description":
            self._description(body, data, log_time)
        elif body in self.bodies:
            self._state(body, kind, data, log_time)
        else:
            self.pending.setdefault(body, {})[kind] = (data, log_time)

    def _description(self, body: str, data: bytes, log_time: int) -> None:
        from rclpy.serialization import deserialize_message
        from std_msgs.msg import String

        topic = f"/{body}/robot_description"
        try:
            text = check_robot_description(deserialize_message(data, String).data, topic)
            kinematics = UrdfKinematics(text)
        except (DescriptionError, ValueError) as exc:
            self._reject("bad_description", f"not using {topic}: {exc}")
            return
        first = body not in self.bodies
        self.bodies[body] = kinematics
        stamp = divmod(log_time, 1_000_000_000)
        self.static[body] = kinematics.static_transforms(stamp, self._prefix(body))
        if first and not per_body(self.frame_prefix):
            self._warn_if_frames_collide(body, kinematics)
        every = [t for transforms in self.static.values() for t in transforms]
        self._write(TF_STATIC_TOPIC, tf_qos(static=True), encode_tf_message(every), log_time)
        if self.description_body in (None, body):
            from tutorial.interfaces.robot_description import robot_description_qos

            self.description_body = body
            if self._prefix(body):  # its links named as its frames are, so a display needs no prefix of its own
                from rclpy.serialization import serialize_message

                data = serialize_message(String(data=prefixed_urdf(text, self._prefix(body))))
            self._write(DESCRIPTION_TOPIC, robot_description_qos(), data, log_time, "std_msgs/msg/String")
        if first:
            self.say(
                f"TF of {body}: root link {self._prefix(body)}{kinematics.root}, "
                f"{len(kinematics.moving)} moving joints, {len(self.static[body])} fixed ones on {TF_STATIC_TOPIC}"
            )
        for kind, (pending, pending_time) in sorted(self.pending.pop(body, {}).items()):
            self._state(body, kind, pending, pending_time)

    def _state(self, body: str, kind: str, data: bytes, log_time: int) -> None:
        from rclpy.serialization import deserialize_message

        if kind == "joint_state":
            from sensor_msgs.msg import JointState

            msg = deserialize_message(data, JointState)
            kinematics = self.bodies[body]
            stamp = (msg.header.stamp.sec, msg.header.stamp.nanosec)
            values = kinematics.joint_values(msg.name, msg.position)
            transforms = kinematics.moving_transforms(values, stamp, self._prefix(body))
        else:
            from nav_msgs.msg import Odometry

            msg = deserialize_message(data, Odometry)
            p, o = msg.pose.pose.position, msg.pose.pose.orientation
            values = (p.x, p.y, p.z, o.x, o.y, o.z, o.w)
            if not all(abs(v) < float("inf") for v in values) or not msg.header.frame_id or not msg.child_frame_id:
                self._reject("bad_odometry", f"/{body}/odom: a pose that is not finite, or a frame with no name")
                return
            stamp = (msg.header.stamp.sec, msg.header.stamp.nanosec)
            child = self._prefix(body) + msg.child_frame_id  # the root link; its parent (world) is shared
            transforms = [Transform(stamp, msg.header.frame_id, child, values[:3], values[3:])]
        self.newest[(body, kind)] = stamp
        if transforms:
            self._write(TF_TOPIC, tf_qos(), encode_tf_message(transforms), log_time)

    # ---- several bodies -----------------------------------------------------------------
    def _prefix(self, body: str) -> str:
        return self.frame_prefix.format(body=body)

    def _warn_if_frames_collide(self, body: str, kinematics: UrdfKinematics) -> None:
        links = set(kinematics.links)
        for other, known in self.bodies.items():
            shared = sorted(links & set(known.links)) if other != body else []
            if shared:
                more = f" and {len(shared) - 3} more" if len(shared) > 3 else ""
                self.collisions.append((body, other))
                self.say(
                    f"WARNING: {body} and {other} have links of the same name ({', '.join(shared[:3])}{more}): "
                    "their TF frames collide; use --tf-frame-prefix '{body}/'"
                )
                return

    # ---- writing ------------------------------------------------------------------------
    def _write(self, topic: str, qos, data: bytes, log_time: int, type_name: str = TF_MESSAGE_TYPE) -> None:
        if topic not in self._topics_added:
            from tutorial.interfaces.definitions import full_text
            from tutorial.tools.bag.qos import profile_dict, serialize_profiles

            definition = tf_definition() if type_name == TF_MESSAGE_TYPE else full_text(type_name)
            self.writer.add_topic(topic, type_name, definition, serialize_profiles([profile_dict(qos)]))
            self._topics_added.add(topic)
        if self.writer.write(topic, log_time, log_time, data):
            self.written[topic] += 1

    def _reject(self, reason: str, text: str) -> None:
        self.rejected[reason] = self.rejected.get(reason, 0) + 1
        if self.rejected[reason] == 1:
            self.say(f"WARNING: {text}")
