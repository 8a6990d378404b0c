# Frozen from notebooks/03_step3_viewer.ipynb by scripts/freeze_reference.py: the later steps
# stand on this copy, so editing that notebook changes its own step only.

"""Step 3: show a body's joint state received over ROS 2, in a second program.

Built in ``notebooks/03_step3_viewer.ipynb``: edit it there, then run
``make export``.  :class:`RttJointStateSubscriber` is the viewer: its
subscription callback runs on the spin thread and only hands each message
to the main thread (``call_later``), which matches, applies and draws.
:class:`RttJointStateMonitor` adds what a monitor needs: a status line,
the publishers it hears, late joiners, and stamps that go back.
"""

from __future__ import annotations

from collections import Counter

from tutorial.interfaces.joint_state import (
    joint_state_qos,
    joint_state_topic,
    joint_state_viewer_qos,
    match_joint_state,
)

from ...core.controller import ControllerConfig, SimpleController
from ...view.status import STALE_CHECK_PERIOD, ViewerStatus


class RttJointStateSubscriber(SimpleController):
    """Step 3 controller: subscribes ``/<body>/joint_state``, poses the body to match.

    It runs in a project without a simulator, so all its work hangs off
    ``configure``: the subscription's callback (spin thread) posts each
    message to the main thread, whose model the viewer draws.  Received
    data is never trusted: :func:`tutorial.interfaces.joint_state.match_joint_state`
    decides what to apply, and rejections are counted.
    """

    # ---- main thread ------------------------------------------------------
    def configure(self, config: ControllerConfig) -> bool:
        from sensor_msgs.msg import JointState

        self.config = config
        self.body = config.body
        self.applied = 0
        self.rejected: Counter = Counter()
        self.subscription = config.node.create_subscription(
            JointState,
            joint_state_topic(config.body_name),
            self.on_joint_state,
            joint_state_viewer_qos(),
            event_callbacks=self.subscription_events(),
        )
        self.topic = self.subscription.topic_name  # as remapped (-r): what it hears
        return True

    def subscription_events(self):
        """Event callbacks for the subscription: none here (the monitor's are)."""
        return None

    def unconfigure(self) -> None:
        self.config.node.destroy_subscription(self.subscription)

    # ---- spin thread --------------------------------------------------------
    def on_joint_state(self, msg) -> None:
        """Subscription callback (spin thread): hand the message over, touch nothing.

        ``call_later`` coalesces: a newer message replaces one still waiting,
        so the view shows the newest state and no backlog can build up.  The
        message is handed over whole and nobody else keeps it: no lock.
        """
        self.config.call_later(self.update_joint_state, msg)

    # ---- main thread ------------------------------------------------------
    def update_joint_state(self, msg):
        """Apply one message to the model and count it (main thread); its report."""
        report = self.apply(msg)
        self.applied += 1
        self.rejected.update(report.counts())
        return report

    def apply(self, msg):
        """Match ``msg`` to the body's joints, set them, update the link poses."""
        report = match_joint_state(self.body.joint_infos, msg.name, msg.position, self.body.following)
        for name, q in report.applied.items():
            self.body.joint(name).q = q
        self.body.notify_kinematic_state_change()  # forward kinematics, then redrawn
        return report

    def summary(self) -> dict:
        return {
            "topic": self.topic,
            "applied": self.applied,
            "rejected": dict(sorted(self.rejected.items())),
            "last_positions": {k: round(v, 9) for k, v in self.body.joint_positions().items()},
        }


__all__ = ["RttJointStateSubscriber", "RttJointStateMonitor"]


class RttJointStateMonitor(RttJointStateSubscriber):
    """The Step 3 viewer as a monitor you can trust; what ``rtt-run`` runs for Step 3.

    On top of :class:`RttJointStateSubscriber`:

    * a status line once a second (rate, age of the newest state, joints
      matched, rejections), ``stale`` within 1.25 s of silence and
      ``live`` again when states resume (:class:`tutorial.view.status.ViewerStatus`);
    * how many publishers it is matched with (the subscription's "matched"
      event), with a warning at two or more: it cannot tell which robot
      it is showing;
    * late joiners: a second, transient-local subscription receives the
      newest state a transient-local publisher kept from before the viewer
      started; it is shown if no live state has come (and the status line
      says so: its age, the joints matched), then dropped;
    * a state stamped earlier than the one before (a publisher restarted
      from t = 0) is reported, and the new run is mirrored.
    """

    STATUS_PERIOD = 1.0  # s

    # ---- main thread ------------------------------------------------------
    def configure(self, config: ControllerConfig) -> bool:
        from rclpy.event_handler import SubscriptionEventCallbacks
        from sensor_msgs.msg import JointState

        self.status = ViewerStatus(config.body.num_joints)
        self.node_name = config.node.get_fully_qualified_name()
        self.late_states = 0
        if not super().configure(config):
            return False
        # Transient local: matches transient-local publishers only, which hand it
        # the newest state they kept.  Live states come through the first one.
        # A volatile publisher cannot match it, as meant: the handler of that
        # event keeps rclpy from warning "no messages will be received from it".
        self.late_subscription = config.node.create_subscription(
            JointState,
            self.topic,
            self.on_late_state,
            joint_state_qos(),
            event_callbacks=SubscriptionEventCallbacks(incompatible_qos=lambda _: None),
        )
        config.call_every(self.STATUS_PERIOD, self.report_status)
        config.call_every(STALE_CHECK_PERIOD, self.check_stale)
        return True

    def subscription_events(self):
        from rclpy.event_handler import SubscriptionEventCallbacks

        return SubscriptionEventCallbacks(matched=self.on_matched)

    def unconfigure(self) -> None:
        self.drop_late_subscription()
        super().unconfigure()

    # ---- spin thread --------------------------------------------------------
    def on_joint_state(self, msg) -> None:
        arrival = self.status.received()  # counted here, under the status's lock
        self.config.call_later(self.update_joint_state, msg, arrival)

    def on_late_state(self, msg) -> None:
        self.config.call_later(self.show_late_state, msg, self.status.clock())

    def on_matched(self, info) -> None:
        """A publisher appeared or went; newest count wins if two come at once."""
        self.config.call_later(self.report_publishers, info.current_count)

    # ---- main thread ------------------------------------------------------
    def update_joint_state(self, msg, arrival: float | None = None):
        stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
        before = self.status.stamp(stamp)  # the one before, if it went back
        if before is not None:
            self.say(
                "stamps_back",
                f"{self.topic}: stamps went back from {before:.3f} s to {stamp:.3f} s (a new run?): showing it",
            )
        first = self.status.applied == 0
        report = super().update_joint_state(msg)
        self.status.applied_message(arrival, report.matched, report.rejected, report.applied)
        if first:
            self.drop_late_subscription()  # live states flow: no more need for it
            self.say(
                "first_state",
                f"first joint state on {self.topic}: {report.matched}/{self.body.num_joints} joints matched",
                matched=report.matched,
                joints=self.body.num_joints,
            )
        return report

    def show_late_state(self, msg, arrival: float | None = None) -> None:
        """The newest state from before the viewer started: shown if none live came.

        The status line shows it too (its age, the joints matched): a
        monitor of a slow publisher shows the posture at once, not after
        the next live state.
        """
        if self.status.applied == 0 and self.late_subscription is not None:
            report = self.apply(msg)
            self.status.late_state_shown(arrival, report.matched, report.applied)
            self.late_states += 1
            stamp = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
            self.say(
                "late_state",
                f"{self.topic}: showing the newest state published before this viewer started (t = {stamp:.3f} s)",
                stamp=stamp,
                matched=report.matched,
                joints=self.body.num_joints,
            )
        self.drop_late_subscription()

    def drop_late_subscription(self) -> None:
        if getattr(self, "late_subscription", None) is not None:
            self.config.node.destroy_subscription(self.late_subscription)
            self.late_subscription = None

    def report_publishers(self, count: int) -> None:
        self.config.output(
            {
                "event": "publishers",
                "node": self.node_name,
                "topic": self.topic,
                "count": count,
            }
        )
        if count > 1:
            self.say(
                "warning",
                f"{count} publishers on {self.topic}: the view mixes "
                "their states and cannot tell which robot it is showing",
            )

    def report_status(self) -> None:
        for record in self.status.report():
            self.config.output({**record, "node": self.node_name})

    def check_stale(self) -> None:
        for record in self.status.check_stale():
            self.config.output({**record, "node": self.node_name})

    def say(self, event: str, text: str, **fields) -> None:
        """Output one status record with its line of text (main thread)."""
        self.config.output(
            {
                "event": event,
                "node": self.node_name,
                "topic": self.topic,
                "message": text,
                "line": f"[{self.node_name}] {text}",
                **fields,
            }
        )

    def summary(self) -> dict:
        return {
            **super().summary(),
            "received": self.status.received_count(),
            "late_states": self.late_states,
            "stamps_back": self.status.stamps_back,
        }
