"""The baseline: a bare rclpy publisher and subscriber of ``sensor_msgs/JointState``.

    python -m benchmarks.bare_pair pub --rate 1000 --duration 8 --joints 2
    python -m benchmarks.bare_pair sub --duration 10 [--executor events]   # writes RTT_PROBE_FILE

Same message, same topic name pattern and same QoS as the tutorial's
publisher and viewer, nothing else: the publisher stamps each message with
``time.monotonic_ns()`` and the subscriber's callback notes when it arrived.
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

from tutorial.interfaces.joint_state import joint_state_qos
from tutorial.ros import env as ros_env

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
    args = p.parse_args()
    ros_env.use_localhost_by_default()
    rclpy.init()
    node = rclpy.create_node(f"bare_{args.role}")
    if args.executor == "events":
        from rclpy.experimental import EventsExecutor

        executor = EventsExecutor()
    else:
        executor = SingleThreadedExecutor()
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
    else:

        def on_message(msg):
            log.append((msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec, time.monotonic_ns()))

        node.create_subscription(JointState, TOPIC, on_message, joint_state_qos())
    end = time.monotonic() + args.duration
    try:
        while time.monotonic() < end:
            executor.spin_once(timeout_sec=0.05)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if args.role == "sub" and os.environ.get("RTT_PROBE_FILE"):
            with open(os.environ["RTT_PROBE_FILE"], "w") as f:
                json.dump({"received": log}, f)
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
