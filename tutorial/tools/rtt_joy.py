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

from tutorial.interfaces import joy
from tutorial.ros import env as ros_env
from tutorial.ros import program as ros_program
from tutorial.ros.spin import SpinThread
from tutorial.tools.joystick.publisher import JoyPublisher

NODE_NAME = "rtt_joy"


def choose_source(args, stack: contextlib.ExitStack):
    """The input source the command line asks for, and a line saying which it is."""
    from tutorial.joystick.demo import SCRIPTS, DemoInput
    from tutorial.tools.joystick.sources import KEYBOARD_HELP, GamepadInput, KeyboardInput

    if args.demo:
        return (
            DemoInput(script=SCRIPTS[args.script]),
            f"demo script {args.script!r} (it starts when /joy has a subscriber)",
        )
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
    from rclpy.signals import SignalHandlerOptions

    argv = list(sys.argv if argv is None else argv)
    parser = argparse.ArgumentParser(prog="rtt-joy", description="Publish sensor_msgs/Joy on /joy.")
    parser.add_argument("--demo", action="store_true", help="scripted input (drive, turn, turret), looped")
    parser.add_argument(
        "--script",
        choices=["drive", "wall"],
        default="drive",
        help="with --demo: 'drive' (around the room) or 'wall' (ram the wall ahead, Step 5)",
    )
    parser.add_argument(
        "--duration",
        type=float,
        default=None,
        metavar="SECONDS",
        help="stop after this long (with --demo: this long after the demo starts)",
    )
    parser.add_argument("--rate", type=float, default=60.0, help="input polling rate, Hz (default 60)")
    parser.add_argument(
        "--autorepeat",
        type=float,
        default=joy.AUTOREPEAT,
        help="republish an unchanged state at this rate, Hz (default 20, 0: only on change)",
    )
    args = ros_program.parse_command_line(parser, argv)
    if args.rate <= 0 or args.autorepeat < 0:
        parser.error("--rate must be > 0 and --autorepeat >= 0")
    ros_env.use_localhost_by_default()
    with contextlib.ExitStack() as stack:
        source, what = choose_source(args, stack)
        # Ctrl-C and SIGTERM end the loop below through a flag: raised as KeyboardInterrupt inside rclpy,
        # they could leave one of its tasks half made, whose clean-up then printed a traceback.
        stop = ros_program.StopRequest().install()
        rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
        node = rclpy.create_node(NODE_NAME)
        pub = JoyPublisher(node, source, rate=args.rate, autorepeat=args.autorepeat, duration=args.duration)
        print(f"[{node.get_fully_qualified_name()}] publishing {joy.TOPIC} from {what}", flush=True)
        spin = None
        try:
            spin = SpinThread(node).start()  # the node's own services answer there; the ticks run here
            pub.run(lambda: stop.requested or not rclpy.ok() or spin.error is not None)
        except ExternalShutdownException:
            pass
        finally:
            ros_program.ignore_stop_signals()  # a second Ctrl-C must not break the clean-up
            if spin is None or spin.stop():  # a spin thread still running must keep its node
                node.destroy_node()
            rclpy.try_shutdown()
        if spin is not None and spin.error is not None:
            print(f"[{NODE_NAME}] spinning ended: {spin.error!r}", file=sys.stderr, flush=True)
        print(f"[{NODE_NAME}] published {pub.published} messages", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
