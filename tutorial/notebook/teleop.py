"""A teleop panel: on-screen sticks (sliders) and a real gamepad that publish ``sensor_msgs/Joy``.

It is a ROS 2 node like ``rtt-joy``: it publishes ``/joy`` when a stick
moves and repeats the current state at 20 Hz, as ``rtt-joy`` and a stock
``joy_node`` do (``autorepeat_rate``), so a controller with a Joy timeout
(Step 1's safe stop) keeps driving while you hold a stick still.

Threads: the widget callbacks run on the kernel thread and publish at
once; the 20 Hz repeat is a timer on the panel's own spin thread.  The two
share one thing, the current stick values, as one tuple that is replaced
whole (a single reference assignment), so the timer always reads a state
some callback wrote in full and no lock is needed.
"""

from __future__ import annotations

from tutorial.interfaces import joy
from tutorial.notebook import session
from tutorial.notebook.panels import Panel


class TeleopPanel(Panel):
    """Sliders for the two sticks, a "release sticks" button, and a gamepad, publishing ``/joy``.

    Args:
        node_name: the panel's node name.

    QoS: :func:`tutorial.interfaces.joy.joy_publisher_qos`, as ``rtt-joy``.
    """

    AXES = ("left H", "left V", "right H", "right V")

    def __init__(self, node_name: str = "rtt_teleop"):
        import ipywidgets as w
        import rclpy
        from sensor_msgs.msg import Joy

        from tutorial.ros.spin import SpinThread

        super().__init__(
            f"Teleop panel /{node_name}",
            f"sliders for the left and right sticks that publish {joy.TOPIC} (sensor_msgs/Joy)",
        )
        session.init_ros()
        self.node = rclpy.create_node(node_name)
        self.publisher = self.node.create_publisher(Joy, joy.TOPIC, joy.joy_publisher_qos())
        self.msg_type = Joy
        self.published = 0
        self._axes = (0.0,) * joy.NUM_AXES  # replaced whole by the kernel thread, read by the timer
        self._listeners = -1
        self.sliders = [
            w.FloatSlider(value=0.0, min=-1.0, max=1.0, step=0.05, description=d, continuous_update=True)
            for d in self.AXES
        ]
        for s in self.sliders:
            s.observe(lambda change: self._changed(), names="value")
        self.center = w.Button(description="release sticks")
        self.center.on_click(lambda _: self.release())
        self.gamepad = w.Controller(index=0)
        self.gamepad.observe(self._on_gamepad, names="axes")
        self.controls = [*self.sliders, self.center]
        convention = w.HTML(
            '<span style="color: #444; font-size: 90%">Each slider is a Joy axis, as ROS counts it: '
            "+ is the stick up or to the left (right H at +0.5 turns the turret left).</span>"
        )
        self.widget = w.VBox(
            [
                convention,
                w.HBox(self.sliders[:2]),
                w.HBox(self.sliders[2:]),
                w.HBox([self.center, self.line]),
                self.gamepad,
            ]
        )
        self.node.create_timer(1.0 / joy.AUTOREPEAT, self.publish)
        self.spin = SpinThread(self.node).start()
        self.say(f"publishing {joy.TOPIC} at {joy.AUTOREPEAT:.0f} Hz")
        session.register(self)

    def _on_gamepad(self, change) -> None:
        # The browser's standard mapping: axes 0/1 left stick, 2/3 right stick, right and down positive.
        axes = [a.value for a in self.gamepad.axes]
        for i, slider in enumerate(self.sliders):
            if i < len(axes):
                slider.value = round(-axes[i], 2)

    def _changed(self) -> None:
        self._axes = tuple(s.value for s in self.sliders) + (0.0,) * (joy.NUM_AXES - len(self.sliders))
        self.publish()

    def axes(self) -> list[float]:
        """The current stick values in the ROS joy convention (8 axes; stick up and left +1)."""
        return list(self._axes)

    def publish(self) -> None:
        """Publish the current sticks once (kernel thread on a change, spin thread on the repeat)."""
        if self.closed:
            return
        msg = self.msg_type()
        msg.header.stamp = self.node.get_clock().now().to_msg()
        msg.axes = list(self._axes)
        msg.buttons = [0] * joy.NUM_BUTTONS
        self.publisher.publish(msg)
        self.published += 1
        listeners = self.publisher.get_subscription_count()
        if listeners != self._listeners:
            self._listeners = listeners
            with self._lock:  # the panel's lock (Panel): close() on the kernel thread may have said why meanwhile
                if self.closed:
                    return
                if listeners:
                    self.say(f"publishing {joy.TOPIC} at {joy.AUTOREPEAT:.0f} Hz to {listeners} subscriber(s)")
                else:
                    self.say(f"nothing subscribes to {joy.TOPIC}: start the simulation to drive", warning=True)

    def release(self) -> None:
        """All sticks back to the centre (kernel thread)."""
        for s in self.sliders:
            s.value = 0.0
        self._changed()

    def close(self) -> None:
        """Stop publishing, disable the sliders and say why (kernel thread)."""
        if self.closed:
            return
        super().close()
        self.spin.stop()
        self.node.destroy_node()
        session.forget(self)
