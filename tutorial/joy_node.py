"""``rtt-joy``: publish ``sensor_msgs/Joy`` on ``/joy`` from a gamepad, the keyboard or a demo script.

    rtt-joy              # a gamepad if one is connected, else this terminal's keyboard
    rtt-joy --demo       # scripted input: drive, turn, swing the turret (loops; starts
                         # when /joy has a subscriber)
    rtt-joy --demo --duration 10
    rtt-joy --demo --script wall   # Step 5's: ram the wall ahead, back off, again

Like ROS 2's ``joy_node`` it publishes when the input changes (at most
``--rate`` Hz, 60 by default) and repeats the current state at
``--autorepeat`` Hz (20 by default) so a subscriber that starts late, or
missed a message, still gets the sticks' state.  Node name ``rtt_joy``.
"""

from __future__ import annotations

import argparse
import contextlib
import sys
import time

from tutorial import ros_env

NODE_NAME = "rtt_joy"
TOPIC = "/joy"


class JoyPublisher:
    """Publishes an input source on ``/joy`` from a timer (spin thread).

    Args:
        node: the ``rclpy`` node.
        source: an object with ``read(now) -> (axes, buttons) | None``.
        rate: how often the source is read, Hz.
        autorepeat: how often an unchanged state is published again, Hz (0: never).
        duration: stop after this many seconds (None: never), counted from the
            start of a demo that waits for a subscriber, else from now.

    QoS: reliable, keep last 10 (the ROS 2 default): a Joy is small, and a
    subscriber with queue 1 drops what it does not need.
    """

    def __init__(self, node, source, rate=60.0, autorepeat=20.0, duration=None):
        from sensor_msgs.msg import Joy

        self.node = node
        self.source = source
        self.msg_type = Joy
        self.publisher = node.create_publisher(Joy, TOPIC, 10)
        self.autorepeat = autorepeat
        self.duration = duration
        self.until = None if duration is None or getattr(source, "waiting", False) else time.monotonic() + duration
        self.last = None
        self.last_sent = 0.0
        self.published = 0
        self.done = False
        self.timer = node.create_timer(1.0 / rate, self.tick)

    def tick(self) -> None:
        now = time.monotonic()
        if getattr(self.source, "waiting", False) and self.publisher.get_subscription_count() > 0:
            # A scripted demo starts when someone listens, so no part of it is lost.
            self.source.begin(now)
            if self.duration is not None:
                self.until = now + self.duration
            print(f"[{self.node.get_fully_qualified_name()}] {TOPIC} has a subscriber: the demo starts", flush=True)
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


def choose_source(args, stack: contextlib.ExitStack):
    """The input source the command line asks for, and a line saying which it is."""
    from tutorial.joy_input import SCRIPTS, KEYBOARD_HELP, DemoInput, GamepadInput, KeyboardInput

    if args.demo:
        return (DemoInput(script=SCRIPTS[args.script]),
                f"demo script {args.script!r} (it starts when /joy has a subscriber)")
    try:
        pad = GamepadInput()
        return pad, f"gamepad {pad.name}"
    except RuntimeError as why:
        reason = str(why)
    try:
        keyboard = stack.enter_context(KeyboardInput())
        return keyboard, f"keyboard ({reason}); {KEYBOARD_HELP}"
    except RuntimeError:
        raise SystemExit(f"rtt-joy: {reason} and standard input is not a terminal; use --demo") from None


def main(argv: list[str] | None = None) -> int:
    """``rtt-joy``: choose the input source, publish ``/joy`` until stopped; the exit status."""
    import rclpy
    from rclpy.executors import ExternalShutdownException
    from rclpy.utilities import remove_ros_args

    argv = list(sys.argv if argv is None else argv)
    parser = argparse.ArgumentParser(prog="rtt-joy", description="Publish sensor_msgs/Joy on /joy.")
    parser.add_argument("--demo", action="store_true", help="scripted input (drive, turn, turret), looped")
    parser.add_argument("--script", choices=["drive", "wall"], default="drive",
                        help="with --demo: 'drive' (around the room) or 'wall' (ram the wall ahead, Step 5)")
    parser.add_argument("--duration", type=float, default=None, metavar="SECONDS",
                        help="stop after this long (with --demo: this long after the demo starts)")
    parser.add_argument("--rate", type=float, default=60.0, help="input polling rate, Hz (default 60)")
    parser.add_argument("--autorepeat", type=float, default=20.0,
                        help="republish an unchanged state at this rate, Hz (default 20, 0: only on change)")
    args = parser.parse_args(remove_ros_args(argv)[1:])
    if args.rate <= 0 or args.autorepeat < 0:
        parser.error("--rate must be > 0 and --autorepeat >= 0")
    ros_env.use_localhost_by_default()
    with contextlib.ExitStack() as stack:
        source, what = choose_source(args, stack)
        rclpy.init(args=argv)
        node = rclpy.create_node(NODE_NAME)
        pub = JoyPublisher(node, source, rate=args.rate, autorepeat=args.autorepeat, duration=args.duration)
        print(f"[{node.get_fully_qualified_name()}] publishing {TOPIC} from {what}", flush=True)
        try:
            while rclpy.ok() and not pub.done:
                rclpy.spin_once(node, timeout_sec=0.1)
        except (KeyboardInterrupt, ExternalShutdownException):
            pass
        finally:
            ros_env.ignore_stop_signals()  # a second Ctrl-C must not break the clean-up
            node.destroy_node()
            rclpy.try_shutdown()
        print(f"[{NODE_NAME}] published {pub.published} messages", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
