"""Does ``rtt-bag record`` keep up at 1 kHz?  (Not part of ``make test`` or ``make bench``.)

    python -m benchmarks.bag                      # 1000 Hz for 60 s
    python -m benchmarks.bag --seconds 10 --compression none

One publisher process sends numbered ``sensor_msgs/JointState`` messages
(2 joints, as the tank's) at ``--rate`` Hz for ``--seconds`` s, reliable,
keep last 1000, so the publisher itself drops nothing.  Two processes read
the same stream at the same time:

* the baseline: a bare raw subscriber that only counts, with the QoS the
  recorder requests and on the same executor (``SpinThread``);
* ``rtt-bag record`` writing the stream to an MCAP file.

It prints messages sent, received and written, how many numbers are
missing from the file, the file size, and each reader's CPU time over the
sending window (user + system, from ``psutil``), with the recorder's ratio
to the baseline.  The publisher starts when it counts both subscribers,
plus 2 s for their own sides to match it.  Traffic stays on this machine
(localhost discovery, a ROS_DOMAIN_ID of its own).
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

    stop = []
    signal.signal(signal.SIGINT, lambda *a: stop.append(1))  # a plain list: see tutorial/bag/cli.py
    ros_env.use_localhost_by_default()
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node("bench_bag_count")
    received = [0]

    def on_message(data: bytes, info: dict) -> None:  # the recorder's callback signature, minus the write
        received[0] += 1

    node.create_subscription(JointState, TOPIC, on_message, _qos(), raw=True)
    spin = ros_env.SpinThread(node).start()
    print(json.dumps({"event": "ready"}), flush=True)
    while not stop:
        time.sleep(0.05)
    spin.stop()
    print(json.dumps({"event": "done", "received": received[0]}), flush=True)
    node.destroy_node()
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
    bag = Path(keep) if keep else folder / "bench.mcap"
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    popen = dict(cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    counter = subprocess.Popen(py("benchmarks.bag", "count"), **popen)
    recorder = subprocess.Popen(
        py("tutorial.bag", "record", TOPIC, "-o", str(bag), "--compression", compression, "--overwrite"), **popen
    )
    procs = [counter, recorder]
    try:
        wait_line(counter, lambda line: '"ready"' in line, 60)
        wait_line(recorder, lambda line: "recording" in line, 60)
        publisher = subprocess.Popen(
            py("benchmarks.bag", "pub", "--rate", str(rate), "--seconds", str(seconds)), **popen
        )
        procs.append(publisher)
        wait_line(publisher, lambda line: '"start"' in line, 90)
        cpu0 = {p.pid: cpu_seconds(p.pid) for p in (counter, recorder)}
        t0 = time.monotonic()
        done = json.loads(wait_line(publisher, lambda line: '"done"' in line, seconds * 3 + 60))
        time.sleep(1.0)  # what was still queued is taken (the readers' idle polling costs ~nothing)
        wall = time.monotonic() - t0
        cpu = {p.pid: cpu_seconds(p.pid) - cpu0[p.pid] for p in (counter, recorder)}
        for p in (counter, recorder):
            p.send_signal(signal.SIGINT)
        base_out, _ = counter.communicate(timeout=30)
        rec_out, rec_err = recorder.communicate(timeout=30)
        publisher.communicate(timeout=30)
    finally:
        for p in procs:
            if p.poll() is None:
                p.kill()
                p.wait()
    baseline = json.loads([line for line in base_out.splitlines() if '"done"' in line][-1])
    wrote = [line for line in rec_out.splitlines() if "] wrote " in line]
    if recorder.returncode != 0 or not wrote:
        raise RuntimeError(f"recorder exited {recorder.returncode}:\n{rec_out}\n{rec_err}")
    written = int(wrote[-1].split("] wrote ")[1].split()[0])
    received = int(wrote[-1].split(" of ")[1].split()[0])
    numbers = file_numbers(bag)
    sent = done["sent"]
    result = {
        "rate_hz": rate,
        "seconds": seconds,
        "compression": compression,
        "sent": sent,
        "send_seconds": round(done["seconds"], 3),
        "acked": done["acked"],
        "baseline": {"received": baseline["received"], "cpu_s": round(cpu[counter.pid], 3)},
        "recorder": {
            "received": received,
            "written": written,
            "in_file": len(numbers),
            "missing_from_file": sent - len(set(numbers) & set(range(sent))),
            "in_order": numbers == sorted(numbers),
            "cpu_s": round(cpu[recorder.pid], 3),
        },
        "window_s": round(wall, 3),
        "file_bytes": bag.stat().st_size,
    }
    result["cpu_ratio"] = round(cpu[recorder.pid] / cpu[counter.pid], 2) if cpu[counter.pid] > 0 else None
    if not keep:
        bag.unlink()
        folder.rmdir()
    return result


def file_numbers(path: Path) -> list[int]:
    """The message numbers in the file, in log-time order (decoded without ROS, as a reader would)."""
    from tutorial.bag.reader import read_messages

    return [int(msg.position[0]) for _topic, _t, msg in read_messages(path)]


def report(r: dict) -> None:
    w = r["window_s"]
    b, rec = r["baseline"], r["recorder"]
    print(
        f"\nrtt-bag record at {r['rate_hz']:.0f} Hz for {r['seconds']:.0f} s: sensor_msgs/JointState, 2 joints, "
        f"reliable, keep last {DEPTH}; chunk compression {r['compression']}"
    )
    print(f"sent {r['sent']} messages in {r['send_seconds']:.1f} s (all acknowledged: {r['acked']})")
    print(f"{'':24}{'received':>10}{'written':>10}{'missing':>9}{'CPU s':>8}{'CPU %':>7}{'us/msg':>8}")
    for name, x, written, missing in (
        ("bare raw subscriber", b, "-", r["sent"] - b["received"]),
        ("rtt-bag record", rec, rec["written"], rec["missing_from_file"]),
    ):
        per = x["cpu_s"] / max(1, x["received"]) * 1e6
        print(
            f"{name:<24}{x['received']:>10}{written!s:>10}{missing:>9}{x['cpu_s']:>8.2f}"
            f"{100 * x['cpu_s'] / w:>6.1f}%{per:>8.1f}"
        )
    print(f"recorder / baseline CPU: {r['cpu_ratio']}  (CPU over the {w:.1f} s window: sending, then 1 s for the tail)")
    size = r["file_bytes"]
    print(
        f"file: {size / 2**20:.2f} MiB, {size / max(1, rec['written']):.1f} bytes per message; "
        f"{rec['in_file']} messages in the file, in order: {rec['in_order']}"
    )


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="role")
    pub = sub.add_parser("pub")
    pub.add_argument("--rate", type=float, default=1000.0)
    pub.add_argument("--seconds", type=float, default=60.0)
    pub.add_argument("--subscribers", type=int, default=2)
    sub.add_parser("count")
    p.add_argument("--rate", type=float, default=1000.0, help="messages per second (default 1000)")
    p.add_argument("--seconds", type=float, default=60.0, help="how long to send (default 60)")
    p.add_argument("--compression", choices=["zstd", "lz4", "none"], default="zstd")
    p.add_argument("--keep", metavar="FILE.mcap", help="keep the recording here")
    p.add_argument("--json", action="store_true", help="also print the result as one JSON line")
    args = p.parse_args(argv)
    if args.role == "pub":
        return publish(args.rate, args.seconds, args.subscribers)
    if args.role == "count":
        return count()
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 100)))
    result = run(args.rate, args.seconds, args.compression, args.keep)
    report(result)
    if args.json:
        print(json.dumps(result))
    recorder = result["recorder"]
    ok = recorder["written"] == recorder["received"] and recorder["missing_from_file"] == 0
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
