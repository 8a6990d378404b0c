"""Step 3: show a body's joint state received over ROS 2, in a second process.

There is no simulation here: the controller does its work in ``configure``
and ``unconfigure``, and the model it updates belongs to the main thread
(it is what the viewer draws).  The subscription callback runs on the spin
thread, so it must not touch the model.  It hands the message to the main
thread with ``call_later`` and returns; the main thread then matches the
joints, applies them and runs forward kinematics.

``call_later`` coalesces: if messages arrive faster than the main thread
draws, each new one replaces the one still waiting, so the view always
shows the newest state and no backlog can build up.  The message object is
handed over whole and nobody else keeps it, so no lock is needed for it.

Received data is never trusted: :func:`tutorial.joint_matching.match_joint_state`
decides what to apply, and the rejections are counted and reported.

The viewer also says when a publisher of its topic appears or goes (the
subscription's "matched" event).  Discovery is not instant and not
symmetric: a publisher may already count this subscription while this side
has not yet matched the publisher, and whatever it sends in between is
dropped.  Only this side's ``publishers`` record says that what is sent
from then on can reach the viewer.
"""

from __future__ import annotations

from tutorial.controller import ControllerConfig, SimpleController
from tutorial.controllers.joint_state_publisher import joint_state_qos, joint_state_topic
from tutorial.joint_matching import match_joint_state
from tutorial.viewer_status import ViewerStatus

STATUS_PERIOD = 1.0  # s


class RttJointStateSubscriber(SimpleController):
    """Step 3 controller: subscribes ``/<body>/joint_state`` and poses the body to match."""

    def configure(self, config: ControllerConfig) -> bool:
        from rclpy.event_handler import SubscriptionEventCallbacks
        from sensor_msgs.msg import JointState

        self.config = config
        self.body = config.body
        self.node = config.node
        self.node_name = config.node.get_fully_qualified_name()
        self.topic = joint_state_topic(config.body_name)
        self.status = ViewerStatus(self.body.num_joints)
        self.subscription = config.node.create_subscription(
            JointState, self.topic, self.on_joint_state, joint_state_qos(),
            event_callbacks=SubscriptionEventCallbacks(matched=self.on_matched))
        config.call_every(STATUS_PERIOD, self.report_status)
        return True

    # ---- spin thread ------------------------------------------------------------
    def on_joint_state(self, msg) -> None:
        """Subscription callback (spin thread): count it and hand it to the main thread."""
        arrival = self.status.received()
        self.config.call_later(self.update_joint_state, msg, arrival)

    def on_matched(self, status) -> None:
        """The subscription's "matched" event (spin thread): a publisher appeared or went.

        ``status.current_count`` is how many publishers this subscription is
        matched with now.  The record is written on the main thread; if the
        count changes twice before it runs, the newest count wins.
        """
        self.config.call_later(self.report_publishers, status.current_count)

    # ---- main thread --------------------------------------------------------------
    def report_publishers(self, count: int) -> None:
        """Output a ``publishers`` record: how many publishers the subscription is matched with."""
        self.config.output({"event": "publishers", "node": self.node_name, "topic": self.topic, "count": count})

    def update_joint_state(self, msg, arrival: float):
        """Apply one message to the model (main thread, via ``call_later``).

        Returns:
            the :class:`tutorial.joint_matching.MatchReport`.
        """
        report = match_joint_state(self.body.joint_infos, msg.name, msg.position)
        for name, q in report.applied.items():
            self.body.joint(name).q = q
        self.body.notify_kinematic_state_change()
        first = self.status.applied == 0
        self.status.applied_message(arrival, report.matched, report.counts(), report.applied)
        if first:
            self.config.output({"event": "first_state", "node": self.node_name, "topic": self.topic,
                                "matched": report.matched, "joints": self.body.num_joints})
        return report

    def report_status(self) -> None:
        for record in self.status.report():
            record["node"] = self.node_name
            self.config.output(record)

    def unconfigure(self) -> None:
        if self.subscription is not None:
            self.node.destroy_subscription(self.subscription)
            self.subscription = None

    def summary(self) -> dict:
        s = self.status
        return {
            "topic": self.topic,
            "received": s.received_count(),
            "applied": s.applied,
            "rejected": dict(sorted(s.rejections.items())),
            "last_positions": {k: round(v, 9) for k, v in s.last_positions.items()},
        }
