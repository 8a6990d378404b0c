"""Does ``rtt-bag record`` keep up at 1 kHz, and what does its write-through cost?  (Not part of ``make test``.)

    python -m benchmarks.bag                      # 1000 Hz for 10 s
    python -m benchmarks.bag --seconds 60 --compression none

One publisher process sends numbered ``sensor_msgs/JointState`` messages
(2 joints, as the tank's) at ``--rate`` Hz for ``--seconds`` s, reliable,
keep last 1000, so the publisher itself drops nothing.  Three processes
read the same stream at the same time:

* a bare raw subscriber that only counts, with the QoS the recorder
  requests and on the same executor (``SpinThread``);
* the recorder with its write-through policy (:mod:`tutorial.tools.bag.writer`:
  a chunk closed at least every 0.5 s, flushed and fsync'ed): the
  :class:`tutorial.tools.bag.record.BagRecorder` that ``rtt-bag record`` runs;
* the same recorder without write-through (``write_through=False``: 1 MiB
  chunks, no flush, no fsync, the policy before issue 26): the baseline.

It prints, for each, messages received and written, how many numbers are
missing from the file, and CPU time over the sending window (user +
system, from ``psutil``); then the write-through's cost: its CPU against
the baseline's (measured, baseline, ratio), how many chunks were written
through and how long the fsyncs took.  The publisher starts when it counts
the three subscribers, plus 2 s for their own sides to match it.  Traffic
stays on this machine (localhost discovery, a ROS_DOMAIN_ID of its own).
Figures on a busy machine are noisy: rerun on a quiet one for the record.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
TOPIC = "/Bench/joint_state"
DEPTH = 1000  # keep last, publisher and readers: no drop by history under a short stall


def _qos():
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

    return QoSProfile(
        history=HistoryPolicy.KEEP_LAST,
        depth=DEPTH,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.VOLATILE,
    )


# ---------------------------------------------------------------- the two roles run as processes
def publish(rate: float, seconds: float, subscribers: int) -> int:
    """Send ``rate * seconds`` JointStates numbered in ``position[0]``; print one JSON line."""
    import rclpy
    from rclpy.duration import Duration
    from sensor_msgs.msg import JointState

    from tutorial.ros import env as ros_env

    ros_env.use_localhost_by_default()
    rclpy.init()
    node = rclpy.create_node("bench_bag_pub")
    pub = node.create_publisher(JointState, TOPIC, _qos())
    deadline = time.monotonic() + 60
    while pub.get_subscription_count() < subscribers:
        if time.monotonic() > deadline:
            print(json.dumps({"error": f"{pub.get_subscription_count()} of {subscribers} subscribers"}), flush=True)
            return 1
        time.sleep(0.05)
    time.sleep(2.0)  # the subscribers' own sides match the publisher (discovery is not symmetric)
    msg = JointState(name=["TURRET_Y", "TURRET_P"], position=[0.0, 0.0], velocity=[0.0, 0.0], effort=[0.0, 0.0])
    count = int(rate * seconds)
    print(json.dumps({"event": "start"}), flush=True)
    t0 = time.perf_counter()
    for i in range(count):
        # Send times are planned from t0, so a late wake-up is made up, never accumulated.
        delay = t0 + i / rate - time.perf_counter()
        if delay > 0:
            time.sleep(delay)
        now = time.time_ns()
        msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(now, 1_000_000_000)
        msg.position[0] = float(i)
        pub.publish(msg)
    elapsed = time.perf_counter() - t0
    acked = pub.wait_for_all_acked(Duration(seconds=10))
    print(json.dumps({"event": "done", "sent": count, "seconds": elapsed, "acked": acked}), flush=True)
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


def count() -> int:
    """The baseline: a raw subscriber that counts, until SIGINT; print one JSON line."""
    import rclpy
    from rclpy.signals import SignalHandlerOptions
    from sensor_msgs.msg import JointState

    from tutorial.ros import env as ros_env
    from tutorial.ros import program as ros_program
    from tutorial.ros import spin as ros_spin

    stop = ros_program.StopRequest()
    signal.signal(signal.SIGINT, stop)  # SIGINT only (the harness sends it); SIGTERM keeps its default
    ros_env.use_localhost_by_default()
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node("bench_bag_count")
    received = [0]

    def on_message(data: bytes, info: dict) -> None:  # the recorder's callback signature, minus the write
        received[0] += 1

    node.create_subscription(JointState, TOPIC, on_message, _qos(), raw=True)
    spin = ros_spin.SpinThread(node).start()
    print(json.dumps({"event": "ready"}), flush=True)
    while not stop.requested:
        time.sleep(0.05)
    spin.stop()
    print(json.dumps({"event": "done", "received": received[0]}), flush=True)
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


def record(path: str, compression: str, write_through: bool) -> int:
    """A recorder (``BagRecorder``, as ``rtt-bag record`` runs it) until SIGINT; print its stats as one JSON line."""
    import rclpy
    from rclpy.signals import SignalHandlerOptions

    from tutorial.ros import env as ros_env
    from tutorial.ros import program as ros_program
    from tutorial.tools.bag.record import BagRecorder

    stop = ros_program.StopRequest()
    signal.signal(signal.SIGINT, stop)  # SIGINT only, as count()
    ros_env.use_localhost_by_default()
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    recorder = BagRecorder(
        path, [TOPIC], compression=compression, overwrite=True, output=None, write_through=write_through
    ).start()
    print(json.dumps({"event": "ready"}), flush=True)
    while not stop.requested and not recorder.failure:
        time.sleep(0.05)
    stats = recorder.close()
    print(
        json.dumps(
            {
                "event": "done",
                "received": sum(recorder.received.values()),
                "written": stats.messages,
                "write_throughs": stats.write_throughs,
                "sync_s": stats.sync_s,
                "max_sync_s": stats.max_sync_s,
                "failure": recorder.failure,
            }
        ),
        flush=True,
    )
    rclpy.try_shutdown()
    return 0


# ---------------------------------------------------------------- the run
def cpu_seconds(pid: int) -> float:
    import psutil

    t = psutil.Process(pid).cpu_times()
    return t.user + t.system


def py(*args: str) -> list[str]:
    return [sys.executable, "-u", "-m", *args]


def wait_line(proc: subprocess.Popen, predicate, timeout: float) -> str:
    """The first stdout line satisfying ``predicate`` (lines are read as they come)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        line = proc.stdout.readline()
        if not line:
            raise RuntimeError(f"{proc.args} ended: {proc.stderr.read()}")
        if predicate(line):
            return line
    raise RuntimeError(f"{proc.args}: no such line in {timeout} s")


def run(rate: float, seconds: float, compression: str, keep: str | None) -> dict:
    folder = Path(tempfile.mkdtemp(prefix="rtt_bench_bag_"))
    bags = {"write_through": folder / "write_through.mcap", "baseline": folder / "baseline.mcap"}
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    popen = dict(cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    counter = subprocess.Popen(py("benchmarks.bag", "count"), **popen)
    recorders = {
        name: subprocess.Popen(
            py("benchmarks.bag", "record", str(path), "--compression", compression, "--write-through", name), **popen
        )
        for name, path in bags.items()
    }
    readers = [counter, *recorders.values()]
    procs = list(readers)
    try:
        for proc in readers:
            wait_line(proc, lambda line: '"ready"' in line, 60)
        publisher = subprocess.Popen(
            py("benchmarks.bag", "pub", "--rate", str(rate), "--seconds", str(seconds), "--subscribers", "3"), **popen
        )
        procs.append(publisher)
        wait_line(publisher, lambda line: '"start"' in line, 90)
        cpu0 = {p.pid: cpu_seconds(p.pid) for p in readers}
        t0 = time.monotonic()
        done = json.loads(wait_line(publisher, lambda line: '"done"' in line, seconds * 3 + 60))
        time.sleep(1.0)  # what was still queued is taken (the readers' idle polling costs ~nothing)
        wall = time.monotonic() - t0
        cpu = {p.pid: cpu_seconds(p.pid) - cpu0[p.pid] for p in readers}
        for p in readers:
            p.send_signal(signal.SIGINT)
        outs = {p.pid: p.communicate(timeout=30) for p in readers}
        publisher.communicate(timeout=30)
    finally:
        for p in procs:
            if p.poll() is None:
                p.kill()
                p.wait()

    def last_done(proc) -> dict:
        out, err = outs[proc.pid]
        lines = [line for line in out.splitlines() if '"done"' in line]
        if proc.returncode != 0 or not lines:
            raise RuntimeError(f"{proc.args} exited {proc.returncode}:\n{out}\n{err}")
        return json.loads(lines[-1])

    sent = done["sent"]
    result = {
        "rate_hz": rate,
        "seconds": seconds,
        "compression": compression,
        "sent": sent,
        "send_seconds": round(done["seconds"], 3),
        "acked": done["acked"],
        "bare": {"received": last_done(counter)["received"], "cpu_s": round(cpu[counter.pid], 3)},
        "window_s": round(wall, 3),
    }
    for name, proc in recorders.items():
        stats = last_done(proc)
        numbers = file_numbers(bags[name])
        result[name] = {
            **stats,
            "in_file": len(numbers),
            "missing_from_file": sent - len(set(numbers) & set(range(sent))),
            "in_order": numbers == sorted(numbers),
            "cpu_s": round(cpu[proc.pid], 3),
            "file_bytes": bags[name].stat().st_size,
        }
    base_cpu = result["baseline"]["cpu_s"]
    result["cpu_ratio"] = round(result["write_through"]["cpu_s"] / base_cpu, 2) if base_cpu > 0 else None
    if keep:
        bags["write_through"].replace(keep)
    for path in bags.values():
        path.unlink(missing_ok=True)
    folder.rmdir()
    return result


def file_numbers(path: Path) -> list[int]:
    """The message numbers in the file, in log-time order (decoded without ROS, as a reader would)."""
    from tutorial.tools.bag.reader import read_messages

    return [int(msg.position[0]) for _topic, _t, msg in read_messages(path)]


def report(r: dict) -> None:
    w = r["window_s"]
    print(
        f"\nrtt-bag record at {r['rate_hz']:.0f} Hz for {r['seconds']:.0f} s: sensor_msgs/JointState, 2 joints, "
        f"reliable, keep last {DEPTH}; chunk compression {r['compression']}"
    )
    print(f"sent {r['sent']} messages in {r['send_seconds']:.1f} s (all acknowledged: {r['acked']})")
    print(f"{'':34}{'received':>10}{'written':>10}{'missing':>9}{'CPU s':>8}{'CPU %':>7}{'us/msg':>8}{'chunks':>8}")
    rows = (
        ("bare raw subscriber", r["bare"], "-", r["sent"] - r["bare"]["received"], "-"),
        ("recorder, write-through (rtt-bag)", r["write_through"], None, None, None),
        ("recorder, no write-through (old)", r["baseline"], None, None, None),
    )
    for name, x, written, missing, chunks in rows:
        written = x["written"] if written is None else written
        missing = x["missing_from_file"] if missing is None else missing
        chunks = x.get("write_throughs", "-") if chunks is None else chunks
        if name.startswith("recorder, no"):
            chunks = "1 MiB"
        per = x["cpu_s"] / max(1, x["received"]) * 1e6
        print(
            f"{name:<34}{x['received']:>10}{written!s:>10}{missing:>9}{x['cpu_s']:>8.2f}"
            f"{100 * x['cpu_s'] / w:>6.1f}%{per:>8.1f}{chunks!s:>8}"
        )
    wt, base = r["write_through"], r["baseline"]
    syncs = max(1, wt["write_throughs"])
    print(
        f"write-through cost, recorder CPU: measured {wt['cpu_s']:.2f} s, baseline {base['cpu_s']:.2f} s, "
        f"ratio {r['cpu_ratio']}  (over the {w:.1f} s window: sending, then 1 s for the tail)"
    )
    print(
        f"write-through: {wt['write_throughs']} chunks flushed and fsync'ed "
        f"({wt['write_throughs'] / r['send_seconds']:.1f} per s of sending); "
        f"fsync {1000 * wt['sync_s'] / syncs:.2f} ms each on average, {1000 * wt['max_sync_s']:.2f} ms at most, "
        f"{1000 * wt['sync_s']:.0f} ms in all"
    )
    for name, x in (("write-through", wt), ("baseline", base)):
        size = x["file_bytes"]
        print(
            f"file ({name}): {size / 2**20:.2f} MiB, {size / max(1, x['written']):.1f} bytes per message; "
            f"{x['in_file']} messages in the file, in order: {x['in_order']}"
        )


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="role")
    pub = sub.add_parser("pub")
    pub.add_argument("--rate", type=float, default=1000.0)
    pub.add_argument("--seconds", type=float, default=10.0)
    pub.add_argument("--subscribers", type=int, default=3)
    sub.add_parser("count")
    rec = sub.add_parser("record")
    rec.add_argument("path")
    rec.add_argument("--compression", default="zstd")
    rec.add_argument("--write-through", choices=["write_through", "baseline"], default="write_through")
    p.add_argument("--rate", type=float, default=1000.0, help="messages per second (default 1000)")
    p.add_argument("--seconds", type=float, default=10.0, help="how long to send (default 10)")
    p.add_argument("--compression", choices=["zstd", "lz4", "none"], default="zstd")
    p.add_argument("--keep", metavar="FILE.mcap", help="keep the write-through recording here")
    p.add_argument("--json", action="store_true", help="also print the result as one JSON line")
    args = p.parse_args(argv)
    if args.role == "pub":
        return publish(args.rate, args.seconds, args.subscribers)
    if args.role == "count":
        return count()
    if args.role == "record":
        return record(args.path, args.compression, args.write_through == "write_through")
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 100)))
    result = run(args.rate, args.seconds, args.compression, args.keep)
    report(result)
    if args.json:
        print(json.dumps(result))
    ok = all(
        result[name]["written"] == result[name]["received"] and result[name]["missing_from_file"] == 0
        for name in ("write_through", "baseline")
    )
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
