"""The baseline: a bare rclpy publisher and subscriber of ``sensor_msgs/JointState``.

    python -m benchmarks.bare_pair pub --rate 1000 --duration 8 --joints 2
    python -m benchmarks.bare_pair sub --duration 10 [--executor events | --hand-off]   # writes RTT_PROBE_FILE

Same message, same topic name pattern and same QoS as the tutorial's
publisher and viewer, nothing else: the publisher stamps each message with
``time.monotonic_ns()`` and the subscriber's callback notes when it arrived.
With ``--hand-off`` the subscriber takes one more step, the one the
tutorial's viewer takes: the callback runs on a
:class:`tutorial.ros.spin.SpinThread` and hands the stamp over
(:class:`tutorial.core.hand_over.HandOverLoop`) to the main thread, which
notes the time it ran.  Not a baseline of any target: it shows what that
hop alone costs on this machine (``benchmarks.experiments.cross_process``'s
A/B, ``--variants bare,bare_hand_off,pipeline``).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

import rclpy
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from sensor_msgs.msg import JointState

from tutorial.core.hand_over import HandOverLoop
from tutorial.interfaces.joint_state import joint_state_qos
from tutorial.ros import env as ros_env
from tutorial.ros.spin import SpinThread

TOPIC = "/Bare/joint_state"


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("role", choices=["pub", "sub"])
    p.add_argument("--rate", type=float, default=1000.0)
    p.add_argument("--duration", type=float, default=8.0)
    p.add_argument("--joints", type=int, default=2)
    p.add_argument(
        "--executor",
        choices=["single", "events"],
        default="single",
        help="single: rclpy's default SingleThreadedExecutor (the baseline); events: EventsExecutor",
    )
    p.add_argument(
        "--hand-off",
        action="store_true",
        help="sub: spin on a SpinThread and note the arrival on the main thread, after the tutorial's hand-off",
    )
    args = p.parse_args()
    if args.hand_off and (args.role != "sub" or args.executor != "single"):
        p.error("--hand-off is for the sub role with the single executor")
    ros_env.use_localhost_by_default()
    rclpy.init()
    node = rclpy.create_node(f"bare_{args.role}")
    spin = executor = None  # with --hand-off the node's SpinThread makes its own executor
    if args.executor == "events":
        from rclpy.experimental import EventsExecutor

        executor = EventsExecutor()
    elif not args.hand_off:
        executor = SingleThreadedExecutor()
    if executor is not None:
        executor.add_node(node)
    log: list[tuple[int, int]] = []
    if args.role == "pub":
        pub = node.create_publisher(JointState, TOPIC, joint_state_qos())
        names = [f"J{i}" for i in range(args.joints)]

        def tick():
            now = time.monotonic_ns()
            msg = JointState()
            msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(now, 1_000_000_000)
            msg.name = names
            msg.position = [0.1] * len(names)
            msg.velocity = [0.0] * len(names)
            msg.effort = [0.0] * len(names)
            pub.publish(msg)

        node.create_timer(1.0 / args.rate, tick)
    elif args.hand_off:
        loop = HandOverLoop()  # owned by this (the main) thread

        def noted(stamp_ns: int) -> None:  # main thread
            log.append((stamp_ns, time.monotonic_ns()))

        def on_message(msg):  # spin thread
            loop.call_later(noted, msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec)

        node.create_subscription(JointState, TOPIC, on_message, joint_state_qos())
        spin = SpinThread(node, hand_over_to=loop)
    else:

        def on_message(msg):
            log.append((msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec, time.monotonic_ns()))

        node.create_subscription(JointState, TOPIC, on_message, joint_state_qos())
    end = time.monotonic() + args.duration
    try:
        if spin is not None:
            spin.start()
        while time.monotonic() < end:
            if spin is not None:
                loop.run_once(0.05)
            else:
                executor.spin_once(timeout_sec=0.05)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if spin is not None:
            spin.stop()
        if args.role == "sub" and os.environ.get("RTT_PROBE_FILE"):
            with open(os.environ["RTT_PROBE_FILE"], "w") as f:
                json.dump({"received": log}, f)
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
