"""Publish an input source on ``/joy``: the node behind ``rtt-joy``.

Like ROS 2's ``joy_node``, :class:`JoyPublisher` publishes when the input
changes (at most ``rate`` Hz) and repeats the current state at
``autorepeat`` Hz, so a subscriber that starts late, or missed a message,
still gets the sticks' state.  Its sources are in :mod:`tutorial.tools.joystick.sources`
and :mod:`tutorial.joystick.demo`.
"""

from __future__ import annotations

import time

from tutorial.interfaces import joy


class JoyPublisher:
    """Publishes an input source on ``/joy``, reading it ``rate`` times a second (:meth:`run`'s thread).

    Args:
        node: the ``rclpy`` node.
        source: an object with ``read(now) -> (axes, buttons) | None``.
        rate: how often the source is read, Hz.
        autorepeat: how often an unchanged state is published again, Hz (0: never).
        duration: stop after this many seconds (None: never), counted from the
            start of a demo that waits for a subscriber, else from now.

    QoS: :func:`tutorial.interfaces.joy.joy_publisher_qos`.

    It reads the source on a plain loop, not an rclpy timer: an executor's
    ``spin_once`` builds its wait set again at every tick, and at 60 Hz that
    cost ``rtt-joy --demo`` 0.067 cores; the loop, with an idle spin thread
    beside it for the node's services, 0.031 to 0.034 (``benchmarks/RESULTS.md``,
    *What a learner costs a class's server*).
    """

    def __init__(self, node, source, rate=60.0, autorepeat=20.0, duration=None):
        from sensor_msgs.msg import Joy

        self.node = node
        self.source = source
        self.msg_type = Joy
        self.publisher = node.create_publisher(Joy, joy.TOPIC, joy.joy_publisher_qos())
        self.autorepeat = autorepeat
        self.duration = duration
        self.until = None if duration is None or getattr(source, "waiting", False) else time.monotonic() + duration
        self.last = None
        self.last_sent = 0.0
        self.published = 0
        self.done = False
        self.period = 1.0 / rate  # s

    def run(self, stop_requested) -> None:
        """Read and publish every ``1/rate`` s until the source ends, the duration is up or ``stop_requested()``.

        Ticks that come late are not made up: after a stall the next tick is at once, and the ones after it
        a period apart.  ``stop_requested`` is asked at least every 0.1 s, whatever the rate.
        """
        due = time.monotonic()
        while not self.done and not stop_requested():
            now = time.monotonic()
            if now >= due:
                self.tick()
                due = max(due + self.period, now)
            time.sleep(min(0.1, max(0.0, due - time.monotonic())))

    def tick(self) -> None:
        """Read the source once; publish on a change, or when the autorepeat is due (:meth:`run`'s thread)."""
        now = time.monotonic()
        if getattr(self.source, "waiting", False) and self.publisher.get_subscription_count() > 0:
            # A scripted demo starts when someone listens, so no part of it is lost.
            self.source.begin(now)
            if self.duration is not None:
                self.until = now + self.duration
            print(f"[{self.node.get_fully_qualified_name()}] {joy.TOPIC} has a subscriber: the demo starts", flush=True)
        state = self.source.read(now)
        if state is None or (self.until is not None and now >= self.until):
            self.done = True
            return
        repeat_due = self.autorepeat > 0 and now - self.last_sent >= 1.0 / self.autorepeat
        if state != self.last or repeat_due:
            msg = self.msg_type()
            msg.header.stamp = self.node.get_clock().now().to_msg()
            msg.axes = [float(a) for a in state[0]]
            msg.buttons = [int(b) for b in state[1]]
            self.publisher.publish(msg)
            self.published += 1
            self.last = state
            self.last_sent = now
