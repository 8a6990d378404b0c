"""Which messages arrive? One numbered stream, read by both executors at once (not part of ``make bench``).

    python -m benchmarks.delivery --messages 15000 --gap 0.02 --busy     # the tutorial's QoS, viewer-like readers
    python -m benchmarks.delivery --messages 3000 --gap 0.005 --depth 500

A publisher process sends ``--messages`` JointStates ``--gap`` s apart, each
numbered in ``header.frame_id``.  Two subscriber processes read the same
stream at the same time, each spun by :class:`tutorial.ros.spin.SpinThread`:
one on rclpy's ``SingleThreadedExecutor``, one on its ``EventsExecutor``.
The publisher starts only after both subscribers' own sides have matched
(their *matched* events), so no message can be lost to discovery.  With
``--busy`` each subscriber's main thread holds the interpreter lock for
1.5 ms sixty times a second, as a viewer drawing its frames does.

Reading one stream together, both executors see the same publisher and the
same stalls of the machine, so a message one of them misses and the other
receives says something about that executor; a message both miss says
something about the publisher or the machine.  For each message only one
executor missed, it prints how long the publisher waited before sending the
next one, and how long after the missing one was sent that subscriber took
its next.  With keep-last-1 (depth 1) a newer message replaces one not yet
taken: a burst from the publisher (the first figure much below ``--gap``)
or a subscriber stalled for longer than the gap (the second figure above
it) explains a missing message.  The figures cannot prove which happened.
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
EXECUTORS = ("single", "events")
BUSY_CHUNK = 0.0015  # s of interpreter-lock-holding work per frame with --busy
BUSY_RATE = 60.0  # frames/s with --busy


def _qos(depth: int):
    from tutorial.interfaces.joint_state import joint_state_qos

    qos = joint_state_qos()
    qos.depth = depth
    return qos


def _wait_for(path: Path, timeout: float, busy: bool) -> None:
    """Wait (at most ``timeout`` s) until ``path`` exists; with ``busy``, hold the interpreter lock in chunks
    meanwhile."""
    end = time.monotonic() + timeout
    while time.monotonic() < end and not path.exists():
        if busy:
            t = time.perf_counter()
            while time.perf_counter() - t < BUSY_CHUNK:
                sum(i * i for i in range(50))
            time.sleep(1 / BUSY_RATE)
        else:
            time.sleep(0.05)  # polling a file the other process writes; bounded by the timeout


def subscriber(out: Path, depth: int, messages: int, timeout: float, busy: bool) -> None:
    """Record (number, arrival ns) of every message until the publisher is done and the last one is in.

    Runs in its own process; the executor is the one ``RTT_EXECUTOR`` names.
    """
    import rclpy
    from rclpy.event_handler import SubscriptionEventCallbacks
    from sensor_msgs.msg import JointState

    from tutorial.ros import env as ros_env
    from tutorial.ros import spin as ros_spin

    ros_env.init()
    node = rclpy.create_node("delivery_sub_" + os.environ[ros_spin.EXECUTOR_VARIABLE])
    log: list[tuple[int, int]] = []

    def matched(status):
        if status.current_count:
            out.with_suffix(".matched").touch()

    node.create_subscription(
        JointState,
        TOPIC,
        lambda m: log.append((int(m.header.frame_id), time.monotonic_ns())),
        _qos(depth),
        event_callbacks=SubscriptionEventCallbacks(matched=matched),
    )
    spin = ros_spin.SpinThread(node).start()
    _wait_for(out.parent / "done", timeout, busy)
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


def publisher(folder: Path, depth: int, messages: int, gap: float) -> None:
    """Wait until every subscriber's side has matched, then send the numbered messages on a fixed schedule."""
    import rclpy
    from rclpy.duration import Duration
    from sensor_msgs.msg import JointState

    from tutorial.ros import env as ros_env

    ros_env.init()
    node = rclpy.create_node("delivery_pub")
    pub = node.create_publisher(JointState, TOPIC, _qos(depth))
    deadline = time.monotonic() + 30
    while not (
        pub.get_subscription_count() >= len(EXECUTORS) and all((folder / f"{e}.matched").exists() for e in EXECUTORS)
    ):
        if time.monotonic() > deadline:
            raise SystemExit("the subscribers did not match within 30 s")
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
    (folder / "sent.json").write_text(json.dumps(sent_ns))
    (folder / "done").touch()
    node.destroy_node()
    rclpy.try_shutdown()


def one_run(messages: int, gap: float, depth: int, busy: bool) -> dict:
    """One publisher and one subscriber per executor, all at once; returns, per executor, what went missing."""
    with tempfile.TemporaryDirectory() as d:
        folder = Path(d)
        me = [sys.executable, "-m", "benchmarks.delivery"]
        common = ["--depth", str(depth), "--messages", str(messages), "--gap", str(gap)] + (["--busy"] if busy else [])
        procs = {
            e: subprocess.Popen(
                me + ["--role", "sub", "--out", str(folder / f"{e}.json")] + common,
                env={**os.environ, "RTT_EXECUTOR": e},
            )
            for e in EXECUTORS
        }
        procs["publisher"] = subprocess.Popen(me + ["--role", "pub", "--out", str(folder / "sent.json")] + common)
        limit = messages * gap + 60
        codes = {name: p.wait(timeout=limit) for name, p in procs.items()}
        if any(codes.values()):
            raise RuntimeError(f"exit codes {codes}")
        sent_ns = json.loads((folder / "sent.json").read_text())
        results = {e: json.loads((folder / f"{e}.json").read_text()) for e in EXECUTORS}
    got = {e: {n for n, _ in r["received"]} for e, r in results.items()}  # the numbers each executor received
    missing = {e: sorted(set(range(messages)) - got[e]) for e in EXECUTORS}
    both = set(missing[EXECUTORS[0]]) & set(missing[EXECUTORS[1]])
    report = {"sent": messages, "missed_by_both": len(both)}
    for e, r in results.items():
        received = r["received"]
        only = []  # (number, next sent after ms, next taken after ms), see the module text
        for m in missing[e]:
            if m in both:
                continue
            nxt = next((t for n, t in received if n > m), None)
            only.append(
                (
                    m,
                    round((sent_ns[m + 1] - sent_ns[m]) * 1e-6, 1) if m + 1 < messages else None,
                    round((nxt - sent_ns[m]) * 1e-6, 1) if nxt is not None else None,
                )
            )
        report[e] = {
            "received": len(got[e]),
            "duplicates": len(received) - len(got[e]),
            "missing": len(missing[e]),
            "only_this_executor": only,
            "spin_error": r["spin_error"],
        }
    return report


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--messages", type=int, default=15000)
    p.add_argument("--gap", type=float, default=0.02, help="s between messages (default 0.02)")
    p.add_argument("--depth", type=int, default=1, help="QoS history depth (default 1, the tutorial's)")
    p.add_argument("--busy", action="store_true", help="subscribers' main threads busy like a viewer's")
    p.add_argument("--role", choices=["sub", "pub"], help=argparse.SUPPRESS)
    p.add_argument("--out", type=Path, help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    if args.role == "sub":
        subscriber(args.out, args.depth, args.messages, args.messages * args.gap + 40, args.busy)
        return 0
    if args.role == "pub":
        publisher(args.out.parent, args.depth, args.messages, args.gap)
        return 0
    os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 100)))
    report = one_run(args.messages, args.gap, args.depth, args.busy)
    print(
        f"{report['sent']} messages {args.gap * 1000:g} ms apart, depth {args.depth}"
        f"{', busy readers' if args.busy else ''}: missed by both executors {report['missed_by_both']}"
    )
    for e in EXECUTORS:
        r = report[e]
        only = r["only_this_executor"]
        print(
            f"  {e:6s}: received {r['received']}, missing {r['missing']}, of which only here {len(only)}; "
            f"duplicates {r['duplicates']}, spin error {r['spin_error']}"
        )
        print(
            f"          only here (number, next sent after ms, next taken after ms): {only[:12]}"
            f"{' ...' if len(only) > 12 else ''}"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
