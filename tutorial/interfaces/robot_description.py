"""``/<body>/robot_description`` (``std_msgs/String``): the body's URDF, for the stock ROS 2 tools.

``robot_state_publisher`` publishes a robot's URDF on ``/robot_description``
so that RViz2's RobotModel display, Foxglove and any monitor started at any
time can draw the robot.  The simulation does the same for each body, on a
topic named after it (:func:`robot_description_topic`), with the same QoS
(:func:`robot_description_qos`): published once, kept for late joiners.

The text is the URDF of :mod:`tutorial.tools.urdf.export`.  A received description
is checked by :func:`check_robot_description` before anything is built from
it: it may come from any publisher on the network.
"""

from __future__ import annotations

import time

MAX_DESCRIPTION_BYTES = 16 * 1024 * 1024  # a URDF is text: far larger is not a robot description


class DescriptionError(ValueError):
    """A robot description that cannot be used, or none arrived; the message says which (one line)."""


def robot_description_topic(body_name: str) -> str:
    """``/<body name>/robot_description``, e.g. ``/Tank/robot_description``."""
    return f"/{body_name}/robot_description"


def robot_description_qos():
    """The description's QoS, as ``robot_state_publisher`` offers it: reliable, keep last 1, transient local.

    * transient local: published once, when the publisher starts; the
      publisher keeps it for every subscriber that joins later (RViz2
      opened an hour after the simulation still gets it);
    * reliable, keep last 1: one message that must arrive, and only the
      newest matters.

    A subscriber must ask for transient local too, or it gets only
    descriptions published after it joined (none).
    """
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

    return QoSProfile(
        depth=1,
        history=HistoryPolicy.KEEP_LAST,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
    )


def check_robot_description(text, source: str = "the robot description") -> str:
    """The URDF text, if ``text`` is one that can be used (any thread).

    Args:
        text: the received ``std_msgs/String.data``.
        source: named in the error (e.g. the topic).

    Returns:
        ``text``, unchanged.

    Raises:
        DescriptionError: not a string, empty, larger than
            :data:`MAX_DESCRIPTION_BYTES`, not XML, or not a ``<robot>`` with
            a name and at least one link.
    """
    from lxml import etree

    if not isinstance(text, str) or not text.strip():
        raise DescriptionError(f"{source}: empty")
    if len(text.encode("utf-8", errors="replace")) > MAX_DESCRIPTION_BYTES:
        raise DescriptionError(f"{source}: larger than {MAX_DESCRIPTION_BYTES // (1024 * 1024)} MiB")
    try:
        root = etree.fromstring(text.encode("utf-8"), parser=etree.XMLParser(resolve_entities=False))
    except etree.XMLSyntaxError as exc:
        raise DescriptionError(f"{source}: not XML ({exc})") from None
    if root.tag != "robot":
        raise DescriptionError(f"{source}: the root element is <{root.tag}>, not <robot> (not a URDF)")
    if not root.get("name"):
        raise DescriptionError(f"{source}: the <robot> has no name")
    if root.find("link") is None:
        raise DescriptionError(f"{source}: the <robot> has no <link>")
    return text


def receive_robot_description(node, topic: str, timeout: float, use=None, on_refused=None, stopped=None):
    """Wait for a usable description on ``topic``; what ``use`` made of it (owner thread of ``node``).

    Subscribes with :func:`robot_description_qos`, so the message a
    transient-local publisher kept arrives at once, and spins ``node`` on an
    executor of its own until one has come that ``use`` takes, or
    ``timeout`` s have passed with none at all.  The node must not be
    spinning elsewhere yet (the App calls this before its spin thread starts).

    Args:
        use: called with each description's text, on this thread; returns
            what this function returns, or raises :class:`DescriptionError`.
            Default: :func:`check_robot_description` (the text, checked).
        on_refused: called with each :class:`DescriptionError` ``use``
            raised; then the wait goes on for a corrected description, with
            no deadline (a publisher is there, and ``robot_state_publisher``
            publishes a fixed file again).  None: the first refusal is raised.
        stopped: asked every 0.1 s; when it says True (Ctrl-C in ``rtt-run``),
            the wait ends with ``KeyboardInterrupt``, as a Ctrl-C would.

    Raises:
        DescriptionError: nothing arrived within ``timeout`` s (with a hint),
            or, without ``on_refused``, what arrived is not usable.
        KeyboardInterrupt: ``stopped`` said True.
    """
    from rclpy.event_handler import SubscriptionEventCallbacks
    from rclpy.executors import SingleThreadedExecutor
    from std_msgs.msg import String

    use = use or (lambda text: check_robot_description(text, topic))
    received: list[str] = []  # filled by the callback, on this thread (the executor below runs here)
    heard = False  # a description has arrived, usable or not: the deadline no longer applies
    refused: list[str] = []  # a publisher that offers too little (volatile, best effort): the policy it lacks
    subscription = node.create_subscription(
        String,
        topic,
        lambda msg: received.append(msg.data),
        robot_description_qos(),
        # said in the error below, with what to do, instead of rclpy's own warning
        event_callbacks=SubscriptionEventCallbacks(
            incompatible_qos=lambda event: refused.append(_policy_name(event.last_policy_kind))
        ),
    )
    topic = subscription.topic_name  # as remapped (-r): the topic it really waits on
    executor = SingleThreadedExecutor(context=node.context)
    executor.add_node(node)
    try:
        deadline = time.monotonic() + timeout
        while heard or time.monotonic() < deadline:
            executor.spin_once(timeout_sec=0.1 if heard else min(0.1, max(0.0, deadline - time.monotonic())))
            if stopped is not None and stopped():
                raise KeyboardInterrupt
            if received:
                heard, text = True, received[-1]  # the newest: an older one is superseded
                received.clear()
                try:
                    return use(text)
                except DescriptionError as exc:
                    if on_refused is None:
                        raise
                    on_refused(exc)
    finally:
        executor.remove_node(node)
        executor.shutdown(timeout_sec=0)
        node.destroy_subscription(subscription)
    if refused:
        raise DescriptionError(
            f"no robot description on {topic} within {timeout:g} s: a publisher offers it with an incompatible "
            f"QoS ({refused[-1]}): publish it as robot_state_publisher does, reliable, keep last 1, transient "
            "local, so a program that starts later still gets it"
        )
    raise DescriptionError(
        f"no robot description on {topic} within {timeout:g} s: start its publisher first (the tank's "
        "simulation: its RttRobotModelPublisher; another robot: robot_state_publisher, or a publisher of "
        "your own, transient local), or name a model file instead"
    )


def _policy_name(kind) -> str:
    """rclpy's ``QoSPolicyKind`` as a word: ``rmw_qos_policy_durability`` -> ``durability``."""
    return getattr(kind, "name", str(kind)).lower().removeprefix("rmw_qos_policy_")
