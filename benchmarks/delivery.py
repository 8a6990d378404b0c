"""Which messages arrive? Numbered JointStates through each executor (not part of ``make bench``).

    python -m benchmarks.delivery --messages 2000 --gap 0.01 --rounds 4            # the tutorial's QoS
    python -m benchmarks.delivery --messages 3000 --gap 0.005 --rounds 2 --depth 500

A publisher process sends ``--messages`` JointStates ``--gap`` s apart, each
numbered in ``header.frame_id``, and a subscriber process spun by
:class:`tutorial.ros_env.SpinThread` records the numbers it receives.  The
publisher starts only after the subscriber's own side has matched (its
*matched* event), so the first messages cannot be lost to discovery.  The
executors alternate round by round.  For each missing message it prints how
long the publisher waited before sending the next one, and how long after
the missing one was sent the subscriber took its next.  With keep-last-1
(depth 1), a newer message replaces one the subscriber has not taken yet:
a burst from the publisher (the first figure much below ``--gap``) or a
subscriber stalled for longer than ``--gap`` (the second figure well above
it) can explain a missing message; one with neither was lost.  The
figures cannot prove which: a stall may end just as the next message comes.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import subprocess
import sys
import tempfile
import time
from pathlib import Path

TOPIC = "/Delivery/joint_state"


def _qos(depth: int):
    from tutorial.controllers.joint_state_publisher import joint_state_qos

    qos = joint_state_qos()
    qos.depth = depth
    return qos


def subscriber(out: Path, depth: int, messages: int, timeout: float) -> None:
    """Record (number, arrival ns) of every message until the publisher is done and the last one is in."""
    import rclpy
    from rclpy.event_handler import SubscriptionEventCallbacks
    from sensor_msgs.msg import JointState

    from tutorial import ros_env

    ros_env.init()
    node = rclpy.create_node("delivery_sub")
    log: list[tuple[int, int]] = []

    def matched(status):
        if status.current_count:
            out.with_suffix(".matched").touch()

    node.create_subscription(JointState, TOPIC, lambda m: log.append((int(m.header.frame_id), time.monotonic_ns())),
                             _qos(depth), event_callbacks=SubscriptionEventCallbacks(matched=matched))
    spin = ros_env.SpinThread(node).start()
    end = time.monotonic() + timeout
    while time.monotonic() < end and not out.with_suffix(".done").exists():
        time.sleep(0.05)  # polling a file the other process writes; bounded by the timeout
    # The publisher is done once the last message is acknowledged; wait (at most 2 s)
    # until the executor has also handed it to the callback.  Nothing comes after the
    # last message to replace it, so it must arrive.
    end = time.monotonic() + 2.0
    while time.monotonic() < end and not (log and log[-1][0] == messages - 1):
        time.sleep(0.01)
    spin.stop()
    out.write_text(json.dumps({"received": log, "spin_error": repr(spin.error) if spin.error else None}))
    node.destroy_node()
    rclpy.try_shutdown()


def publisher(out: Path, depth: int, messages: int, gap: float) -> None:
    """Wait for the subscriber's side to match, then send the numbered messages on a fixed schedule."""
    import rclpy
    from rclpy.duration import Duration
    from sensor_msgs.msg import JointState

    from tutorial import ros_env

    ros_env.init()
    node = rclpy.create_node("delivery_pub")
    pub = node.create_publisher(JointState, TOPIC, _qos(depth))
    deadline = time.monotonic() + 30
    while not (pub.get_subscription_count() and out.with_suffix(".matched").exists()):
        if time.monotonic() > deadline:
            raise SystemExit("the subscriber did not match within 30 s")
        time.sleep(0.01)
    msg = JointState(name=["A", "B"], position=[0.0, 0.0], velocity=[0.0, 0.0], effort=[0.0, 0.0])
    sent_ns = []
    t0 = time.monotonic()
    for i in range(messages):
        left = t0 + i * gap - time.monotonic()
        if left > 0:
            time.sleep(left)
        msg.header.frame_id = str(i)
        sent_ns.append(time.monotonic_ns())
        pub.publish(msg)
    pub.wait_for_all_acked(Duration(seconds=2))
    out.with_suffix(".sent").write_text(json.dumps(sent_ns))
    out.with_suffix(".done").touch()
    node.destroy_node()
    rclpy.try_shutdown()


def one_round(executor: str, messages: int, gap: float, depth: int) -> dict:
    """One publisher/subscriber pair on ``executor``; returns what went missing, with the timings around it."""
    env = {**os.environ, "RTT_EXECUTOR": executor}
    with tempfile.TemporaryDirectory() as d:
        out = Path(d) / "log.json"
        me = [sys.executable, "-m", "benchmarks.delivery"]
        common = ["--out", str(out), "--depth", str(depth), "--messages", str(messages), "--gap", str(gap)]
        sub = subprocess.Popen(me + ["--role", "sub"] + common, env=env)
        pub = subprocess.Popen(me + ["--role", "pub"] + common, env=env)
        limit = messages * gap + 60
        if pub.wait(timeout=limit) != 0 or sub.wait(timeout=limit) != 0:
            raise RuntimeError(f"{executor}: publisher exited {pub.returncode}, subscriber {sub.returncode}")
        result = json.loads(out.read_text())
        sent_ns = json.loads(out.with_suffix(".sent").read_text())
    received = result["received"]
    got = {n for n, _ in received}
    missing = [i for i in range(messages) if i not in got]
    # For each missing message: the publisher's wait before the next send, and how long after
    # the missing one was sent the subscriber took its next (see the module text).
    next_sent_ms, next_taken_ms = [], []
    for m in missing:
        nxt = next((t for n, t in received if n > m), None)
        if nxt is None or m + 1 >= messages:
            continue
        next_sent_ms.append(round((sent_ns[m + 1] - sent_ns[m]) * 1e-6, 1))
        next_taken_ms.append(round((nxt - sent_ns[m]) * 1e-6, 1))
    return {"executor": executor, "sent": messages, "received": len(got), "duplicates": len(received) - len(got),
            "missing": missing, "next_sent_after_ms": next_sent_ms, "next_taken_after_ms": next_taken_ms,
            "spin_error": result["spin_error"]}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--messages", type=int, default=2000)
    p.add_argument("--gap", type=float, default=0.01, help="s between messages (default 0.01)")
    p.add_argument("--depth", type=int, default=1, help="QoS history depth (default 1, the tutorial's)")
    p.add_argument("--rounds", type=int, default=2, help="rounds per executor, alternating (default 2)")
    p.add_argument("--role", choices=["sub", "pub"], help=argparse.SUPPRESS)
    p.add_argument("--out", type=Path, help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    if args.role == "sub":
        subscriber(args.out, args.depth, args.messages, args.messages * args.gap + 40)
        return 0
    if args.role == "pub":
        publisher(args.out, args.depth, args.messages, args.gap)
        return 0
    os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 100)))
    totals: dict[str, list[int]] = {}
    for r in range(args.rounds):
        for executor in ("single", "events") if r % 2 == 0 else ("events", "single"):
            res = one_round(executor, args.messages, args.gap, args.depth)
            print(f"round {r} {executor:6s}: received {res['received']} of {res['sent']}, missing "
                  f"{len(res['missing'])} {res['missing'][:8]}, next sent after (ms) "
                  f"{res['next_sent_after_ms'][:8]}, next taken after (ms) {res['next_taken_after_ms'][:8]}, "
                  f"duplicates {res['duplicates']}, spin error {res['spin_error']}", flush=True)
            t = totals.setdefault(executor, [0, 0])
            t[0] += len(res["missing"])
            t[1] += res["sent"]
    for executor, (missing, sent) in totals.items():
        print(f"{executor}: {missing} missing of {sent} (depth {args.depth}, {args.gap * 1000:g} ms apart)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
