"""What a controller publishes, captured in-process, for the exercises' checks, and the scripted run it is captured in.

:class:`CapturingNode` stands in for the ``rclpy`` node a controller gets in
``configure``: everything goes to the real node, except that each publisher
it creates also keeps a copy of every message published through it (a
serialized copy: a controller may refill and reuse its message object).
Nothing depends on the network or on timing, so a check sees exactly what
was published, in order.  Used by one thread at a time, as a node is.

:func:`scripted_drive` is the run the checks of notebooks 02 and 04 capture
in: the tank in its room, driven by a script by simulated time (deaf to the
network, so always the same run), on the calling thread.
"""

from __future__ import annotations


class CapturingPublisher:
    """A publisher that forwards to a real one and keeps ``(topic, type, bytes)`` of each message."""

    def __init__(self, real, msg_type, topic: str, noted: list | None = None):
        self.real, self.msg_type, self.topic = real, msg_type, topic
        self.sent: list[bytes] = []
        self.destroyed = False  # the controller gave it back (node.destroy_publisher), as unconfigure() should
        self._noted = noted if noted is not None else []  # its node's publishers destroyed, in order

    def note_destroyed(self) -> None:
        """Noted once, however it was destroyed (its ``destroy()``, or its node's ``destroy_publisher``)."""
        if not self.destroyed:
            self.destroyed = True
            self._noted.append(self)

    def publish(self, msg) -> None:
        """Keep the message's bytes, then publish it on the real publisher.

        Kept first: a message published after its real publisher was destroyed still counts as sent (the checks
        tell that mistake by its order).  One of another type is not kept.

        Raises:
            TypeError: ``msg`` is neither a ``msg_type`` nor bytes (rclpy's own refusal, which a learner reads).
        """
        from rclpy.serialization import serialize_message

        if isinstance(msg, (self.msg_type, bytes)):
            self.sent.append(msg if isinstance(msg, bytes) else serialize_message(msg))
        self.real.publish(msg)

    def destroy(self) -> None:
        """Destroy the real publisher (rclpy's ``Publisher.destroy``), noted as ``node.destroy_publisher`` is."""
        self.note_destroyed()
        self.real.destroy()

    def require_destroyed(self, call: str, hint: str) -> None:
        """Raise the check's ``CaseFailed`` unless the controller destroyed this publisher (in ``unconfigure()``)."""
        from tutorial.exercises.grader import CaseFailed

        if not self.destroyed:
            raise CaseFailed(f"{call} left the publisher of {self.topic} in place, expected it destroyed.", hint)

    def messages(self) -> list:
        """Every message published so far, deserialized, oldest first."""
        from rclpy.serialization import deserialize_message

        return [deserialize_message(b, self.msg_type) for b in self.sent]

    def __getattr__(self, name):
        return getattr(self.real, name)


class CapturingNode:
    """A node wrapper whose publishers capture what they publish; see the module text.

    Args:
        node: the real ``rclpy.node.Node``.
    """

    def __init__(self, node):
        self.node = node
        self.publishers: list[CapturingPublisher] = []
        self.destroyed: list[CapturingPublisher] = []  # in the order they were destroyed, either way

    def create_publisher(self, msg_type, topic, qos_profile, **kwargs):
        real = self.node.create_publisher(msg_type, topic, qos_profile, **kwargs)
        pub = CapturingPublisher(real, msg_type, topic, self.destroyed)
        self.publishers.append(pub)
        return pub

    def destroy_publisher(self, publisher) -> bool:
        if isinstance(publisher, CapturingPublisher):
            publisher.note_destroyed()
        return self.node.destroy_publisher(getattr(publisher, "real", publisher))

    def published(self, topic: str | None = None) -> list[CapturingPublisher]:
        """The capturing publishers made so far (of one topic, or all)."""
        return [p for p in self.publishers if topic is None or p.topic == topic]

    def __getattr__(self, name):
        return getattr(self.node, name)


def scripted_drive(name: str, cls, parameters: dict, node: CapturingNode, script, duration: float, probe, first=None):
    """Run the tank world for ``duration`` s of simulated time with the learner's ``cls`` attached as ``name``.

    Args:
        parameters: the learner's controller's parameters.
        node: the capturing node the run's controllers get.
        script: ``ScriptedJoy``'s script (None: the demo drive), through the frozen Step 1 tank controller.
        probe: the check's own controller, attached after the drive (it reads each step's state).
        first: a controller attached before everything else (a start of the check's own), or None.

    Returns:
        The ``App`` that ran (:func:`tutorial.notebook.runs.run_headless`).

    Raises:
        tutorial.core.project.ProjectError: the project refuses ``cls`` or ``parameters`` (``node`` destroyed).
        tutorial.app.app.ControllerError: the learner's controller refused to configure (or raised there).
        tutorial.exercises.grader.CaseFailed: the simulation failed.
    """
    from tutorial.app.reference.tank_controller import RttTankController
    from tutorial.exercises.grader import raise_run_error
    from tutorial.joystick.scripted import ScriptedJoy
    from tutorial.notebook.runs import load, run_headless

    try:
        project = load("tank_world.yaml").with_controller("Tank", name, cls, parameters)
    except BaseException:  # a parameter or class the project refuses: the run that would destroy the node never starts
        node.destroy_node()
        raise
    tank = RttTankController()
    attach = [("Tank", "ScriptedJoy", ScriptedJoy(tank, script=script)), ("Tank", "RttTankController", tank)]
    attach = ([("Tank", "First", first)] if first is not None else []) + attach + [("Tank", "Probe", probe)]
    summary, app = run_headless(project, duration, node=node, attach=attach)
    raise_run_error(summary)
    return app


def publishers_record(node: CapturingNode) -> list[dict]:
    """What each capturing publisher of ``node`` saw, as data (an experiment's, see
    :func:`~tutorial.exercises.grader.experiments`): ``{"topic", "type"`` (``pkg/msg/Name``), ``"qos"``,
    ``"destroyed"``, ``"messages"}``.

    The QoS is the real publisher's, and destroyed means gone from the real node too: a class can write
    ``qos_profile`` or ``destroyed`` on the capturing publisher it was handed, not make rclpy's say so.
    """
    live = node.node.publishers
    return [
        {
            "topic": p.topic,
            "type": f"{p.msg_type.__module__.split('.')[0]}/msg/{p.msg_type.__name__}",
            "qos": p.real.qos_profile,
            "destroyed": p.destroyed and not any(p.real is q for q in live),
            "messages": p.messages(),
        }
        for p in node.published()
    ]


class RecordedPublisher:
    """A capturing publisher as :func:`publishers_record` recorded it: what a check reads of one."""

    def __init__(self, record: dict):
        from rclpy.qos import QoSProfile

        self.topic, self.qos_profile = str(record["topic"]), record["qos"]
        if not isinstance(self.qos_profile, QoSProfile):
            raise TypeError(f"a publisher's QoS recorded as {self.qos_profile!r:.60}")
        self.msg_type = _message_class(str(record["type"]))
        self.destroyed = record["destroyed"] is True
        self._messages = list(record["messages"])

    def messages(self) -> list:
        return list(self._messages)

    require_destroyed = CapturingPublisher.require_destroyed


class RecordedNode:
    """A capturing node's publishers as :func:`publishers_record` recorded them (``published``, as its own)."""

    def __init__(self, records: list[dict]):
        self.publishers = [RecordedPublisher(r) for r in records]

    published = CapturingNode.published


# The message types a check of a publisher names (what a recorded publisher's type is compared with).
CHECKED_MESSAGES = (
    "sensor_msgs/msg/JointState",
    "geometry_msgs/msg/PoseStamped",
    "sensor_msgs/msg/Imu",
    "std_msgs/msg/Float64",
    "geometry_msgs/msg/Vector3Stamped",
    "sensor_msgs/msg/Image",
    "sensor_msgs/msg/CameraInfo",
)


def _message_class(name: str) -> type:
    """The class of message type ``name`` (``pkg/msg/Name``) if it is one of :data:`CHECKED_MESSAGES`; else a class
    of that name alone (no other module is imported for a name a recording gives)."""
    import importlib

    package, _, kind = name.partition("/msg/")
    if name in CHECKED_MESSAGES:
        return getattr(importlib.import_module(f"{package}.msg"), kind)
    return type(kind if kind.isidentifier() else "message", (), {})
