"""Soak: the Step 3 pipeline at 1 kHz for minutes, watched for leaks, backlog and stale periods.

    python -m benchmarks.soak                 # 10 minutes, meshcat pages on, as `make demo`
    python -m benchmarks.soak --minutes 1 --headless

Not part of ``make test``.  It starts Step 3's three programs as ``make demo``
does - the simulation (``rtt-run project/step2.yaml``, real time, its joint
state publisher at 1 kHz: ``-p RttJointStatePublisher.rate:=1000.0``), the
demo joystick (``rtt-joy --demo``) and the viewer (``rtt-run
project/step3.yaml``, node ``rtt_viewer``) - and, in the same run, the
baseline: a bare rclpy publisher and subscriber of the same ``JointState`` at
the same rate (``benchmarks.bare_pair``), whose memory shows what rclpy and
Fast DDS do on their own.  After ``--warmup`` s it measures for ``--minutes``:

* every process's memory (RSS, psutil) at the start and the end of the
  window, its growth and its slope (least squares over samples every
  ``--sample`` s), and its CPU in cores; meshcat servers are rows of their own;
* the viewer's status lines: how many came (one a second is due), their
  rate of states received (msg/s), states applied and coalesced (received but
  replaced by a newer one before the main thread applied it: received -
  applied), and the age of the newest state shown;
* stale periods: ``stale`` records and status lines saying stale;
* the simulation's real-time factor and the states it published.

Targets, each reported PASS or FAIL: memory growth under 5 MB per process;
no backlog (the viewer's newest state no older in the window's last minute
than in its first, within 5 ms, and the simulation at real time); no stale
period.  Results go to ``benchmarks/results/soak.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import random
import signal
import statistics
import subprocess
import sys
import threading
import time
from pathlib import Path

import psutil

from tutorial.ros.launch import fast_dds_shm_files, remove_unused_fast_dds_shm

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results"
MEMORY_GROWTH_LIMIT_MB = 5.0
AGE_GROWTH_LIMIT_MS = 5.0
REAL_TIME_FACTOR_MIN = 0.99
MB = 1024.0 * 1024.0


class Program:
    """One child process, its output lines kept with their arrival times (a reader thread per stream)."""

    def __init__(self, name: str, cmd: list[str], env: dict):
        self.name = name
        self.proc = subprocess.Popen(
            cmd, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True
        )
        self.lines: list[tuple[float, str]] = []  # (time.monotonic(), line); appended by the reader only
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self) -> None:
        for line in self.proc.stdout:
            self.lines.append((time.monotonic(), line.rstrip("\n")))  # list.append is atomic

    def records(self, event: str | None = None, since: float = 0.0, until: float = float("inf")) -> list[dict]:
        """JSON records of ``event`` (any, if None) that arrived between ``since`` and ``until``, each with ``_at``."""
        found = []
        for at, line in list(self.lines):
            if since <= at <= until and line.startswith("{"):
                record = json.loads(line)
                if event is None or record.get("event") == event:
                    found.append({**record, "_at": at})
        return found

    def text(self) -> str:
        return "\n".join(line for _, line in list(self.lines))

    def stop(self, timeout: float = 20.0) -> int | None:
        """Ctrl-C (SIGINT), wait; SIGKILL after ``timeout`` s.  Its exit status."""
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
            try:
                self.proc.wait(timeout)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self.reader.join(5)
        return self.proc.returncode


def py(*args: str) -> list[str]:
    return [sys.executable, "-u", "-m", *args]


def process_tree(programs: list[Program]) -> dict[str, psutil.Process]:
    """Every process to measure by a row name: each program, and its children as ``name/child``."""
    rows = {}
    for program in programs:
        try:
            parent = psutil.Process(program.proc.pid)
            rows[program.name] = parent
            for child in parent.children(recursive=True):
                is_meshcat = "meshcat" in " ".join(child.cmdline())
                rows[f"{program.name}/{'meshcat' if is_meshcat else child.pid}"] = child
        except psutil.NoSuchProcess:
            pass
    return rows


def sample(rows: dict[str, psutil.Process]) -> dict[str, tuple[float, float, float]]:
    """``{row: (time.monotonic(), RSS in MB, CPU s user+system)}`` of the live processes."""
    out = {}
    for name, p in rows.items():
        try:
            with p.oneshot():
                out[name] = (time.monotonic(), p.memory_info().rss / MB, sum(p.cpu_times()[:2]))
        except psutil.NoSuchProcess:
            pass
    return out


def slope_per_10_min(points: list[tuple[float, float]]) -> float | None:
    """Least-squares slope of ``(t s, value)`` points, per 600 s."""
    if len(points) < 3:
        return None
    return statistics.linear_regression([t for t, _ in points], [v for _, v in points]).slope * 600.0


def median(values):
    return round(statistics.median(values), 3) if values else None


def soak(minutes: float, warmup: float, period: float, rate: float, headless: bool, baseline: bool) -> dict:
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    env.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 100)))
    window = minutes * 60.0
    meshcat = [] if not headless else ["--headless"]
    programs = [
        Program(
            "rtt_viewer",
            py(
                "tutorial.tools.rtt_run",
                "project/step3.yaml",
                "--json",
                *meshcat,
                "--ros-args",
                "-r",
                "__node:=rtt_viewer",
            ),
            env,
        ),
        Program(
            "rtt",
            py(
                "tutorial.tools.rtt_run",
                "project/step2.yaml",
                "--json",
                *meshcat,
                "--ros-args",
                "-p",
                f"RttJointStatePublisher.rate:={rate}",
            ),
            env,
        ),
        Program("rtt_joy", py("tutorial.tools.rtt_joy", "--demo"), env),
    ]
    if baseline:
        programs += [
            Program("bare_sub", py("benchmarks.soak", "--bare", "sub"), env),
            Program("bare_pub", py("benchmarks.soak", "--bare", "pub", "--rate", str(rate)), env),
        ]
    viewer, sim, joy = programs[:3]
    try:
        deadline = time.monotonic() + 60.0
        while not viewer.records("first_state"):
            if time.monotonic() > deadline or any(p.proc.poll() is not None for p in programs):
                raise RuntimeError(
                    "the viewer showed no state within 60 s:\n"
                    + "\n".join(f"--- {p.name}\n{p.text()}" for p in programs)
                )
            time.sleep(0.2)
        first_state_at = time.monotonic()
        print(f"pipeline up; warm-up {warmup:.0f} s, then {minutes:g} min measured", flush=True)
        time.sleep(warmup)
        rows = process_tree(programs)
        samples = [sample(rows)]
        start = time.monotonic()
        end = start + window
        next_print = start + 60.0
        while time.monotonic() < end:
            time.sleep(min(period, max(0.0, end - time.monotonic())))
            samples.append(sample(rows))
            dead = [p.name for p in programs if p.proc.poll() is not None]
            if dead:
                raise RuntimeError(
                    f"{', '.join(dead)} ended during the soak:\n"
                    + "\n".join(f"--- {p.name}\n{p.text()}" for p in programs)
                )
            if time.monotonic() >= next_print:
                next_print += 60.0
                status = viewer.records("status")[-1]
                print(
                    f"  {(time.monotonic() - start) / 60:4.1f} min: viewer {status['rate_hz']:.0f} msg/s, "
                    f"newest state {status['age_ms']} ms old",
                    flush=True,
                )
        stopped_at = time.monotonic()
    finally:
        shm_files = set()
        for program in programs:
            shm_files |= fast_dds_shm_files(program.proc.pid)
        codes = {p.name: p.stop() for p in reversed(programs)}  # the publishers first, the viewer last
        remove_unused_fast_dds_shm(shm_files)  # what a program killed after its 20 s left

    # -- processes: memory and CPU over the window
    processes = {}
    for name in rows:
        points = [s[name] for s in samples if name in s]
        if len(points) < 2:
            continue
        (t0, rss0, cpu0), (t1, rss1, cpu1) = points[0], points[-1]
        processes[name] = {
            "rss_start_mb": round(rss0, 2),
            "rss_end_mb": round(rss1, 2),
            "growth_mb": round(rss1 - rss0, 2),
            "slope_mb_per_10min": round(slope_per_10_min([(t, r) for t, r, _ in points]) or 0.0, 2),
            "cpu_cores": round((cpu1 - cpu0) / (t1 - t0), 3),
        }

    # -- the viewer's status lines in the window
    statuses = viewer.records("status", start, stopped_at)
    received = [s["received"] for s in statuses]
    applied = [s["applied"] for s in statuses]
    ages = [(s["_at"], s["age_ms"]) for s in statuses if s["age_ms"] is not None]
    first_min = [a for t, a in ages if t < start + 60.0]
    last_min = [a for t, a in ages if t >= stopped_at - 60.0]
    rates = [s["rate_hz"] for s in statuses]
    d_received = received[-1] - received[0] if statuses else 0
    d_applied = applied[-1] - applied[0] if statuses else 0
    stale_records = viewer.records("stale", first_state_at, stopped_at)
    stale_lines = [s for s in viewer.records("status", first_state_at, stopped_at) if s["stale"]]
    viewer_summary = (viewer.records("summary") or [{}])[-1]
    sim_summary = (sim.records("summary") or [{}])[-1]
    published = sim_summary.get("controllers", {}).get("RttJointStatePublisher", {}).get("published")
    span = statuses[-1]["_at"] - statuses[0]["_at"] if len(statuses) > 1 else 0.0
    viewer_figures = {
        "status_lines": len(statuses),
        "status_lines_per_s": round((len(statuses) - 1) / span, 3) if span else None,
        "rate_hz": {"min": min(rates, default=None), "p50": median(rates), "max": max(rates, default=None)},
        "received": d_received,
        "received_per_s": round(d_received / span, 1) if span else None,
        "applied": d_applied,
        "coalesced": d_received - d_applied,
        "coalesced_fraction": round((d_received - d_applied) / d_received, 4) if d_received else None,
        "age_ms": {
            "p50": median([a for _, a in ages]),
            "p99": round(sorted(a for _, a in ages)[int(0.99 * (len(ages) - 1))], 3) if ages else None,
            "max": max((a for _, a in ages), default=None),
            "first_minute_p50": median(first_min),
            "last_minute_p50": median(last_min),
            "p50_by_minute": [
                median([a for t, a in ages if start + 60 * m <= t < start + 60 * (m + 1)])
                for m in range(max(1, round((stopped_at - start) / 60.0)))
            ],
        },
        "stale_records": len(stale_records),
        "stale_status_lines": len(stale_lines),
        "rejected": statuses[-1]["rejected"] if statuses else None,
        "summary_received": viewer_summary.get("controllers", {}).get("RttJointStateMonitor", {}).get("received"),
    }
    simulation = {
        "real_time_factor": sim_summary.get("real_time_factor"),
        "simulated_time": sim_summary.get("simulated_time"),
        "published": published,
    }
    age_growth = (
        viewer_figures["age_ms"]["last_minute_p50"] - viewer_figures["age_ms"]["first_minute_p50"]
        if first_min and last_min
        else None
    )
    ours = [n for n in processes if not n.startswith("bare_")]
    targets = {
        "memory_growth_under_5_MB_per_process": {
            "pass": bool(ours) and all(processes[n]["growth_mb"] < MEMORY_GROWTH_LIMIT_MB for n in ours),
            "worst": max(((processes[n]["growth_mb"], n) for n in ours), default=None),
        },
        "no_backlog": {
            "pass": age_growth is not None
            and age_growth <= AGE_GROWTH_LIMIT_MS
            and (simulation["real_time_factor"] or 0) >= REAL_TIME_FACTOR_MIN,
            "age_growth_ms": None if age_growth is None else round(age_growth, 3),
            "real_time_factor": simulation["real_time_factor"],
        },
        "no_stale_period": {
            "pass": not stale_records and not stale_lines and len(statuses) > 0,
            "stale_records": len(stale_records),
            "stale_status_lines": len(stale_lines),
        },
    }
    return {
        "when": time.strftime("%Y-%m-%d %H:%M:%S"),
        "machine": {
            "cpus": os.cpu_count(),
            "python": platform.python_version(),
            "platform": platform.platform(),
            "load_avg_at_end": os.getloadavg(),
        },
        "settings": {
            "minutes": minutes,
            "warmup_s": warmup,
            "sample_s": period,
            "rate_hz": rate,
            "meshcat": not headless,
            "baseline": baseline,
            "executor": os.environ.get("RTT_EXECUTOR", "the default of tutorial.ros.env"),
            "ros_domain_id": env["ROS_DOMAIN_ID"],
        },
        "window_s": round(stopped_at - start, 1),
        "processes": processes,
        "viewer": viewer_figures,
        "simulation": simulation,
        "joy": {"last_line": joy.text().splitlines()[-1:]},
        "exit_codes": codes,
        "targets": targets,
    }


def report(r: dict) -> None:
    s = r["settings"]
    print(
        f"\n== soak: Step 3 at {s['rate_hz']:g} Hz, {r['window_s']:.0f} s measured after {s['warmup_s']:g} s "
        f"of warm-up, meshcat {'on' if s['meshcat'] else 'off'}, executor: {s['executor']}; "
        f"{r['machine']['cpus']} CPUs, load at the end "
        f"{', '.join(f'{x:.2f}' for x in r['machine']['load_avg_at_end'])}"
    )
    print(
        f"{'process':<22}{'RSS start MB':>13}{'RSS end MB':>12}{'growth MB':>11}{'slope MB/10min':>16}{'CPU cores':>11}"
    )
    for name, p in r["processes"].items():
        print(
            f"{name:<22}{p['rss_start_mb']:>13.1f}{p['rss_end_mb']:>12.1f}{p['growth_mb']:>11.2f}"
            f"{p['slope_mb_per_10min']:>16.2f}{p['cpu_cores']:>11.3f}"
        )
    base = [n for n in r["processes"] if n.startswith("bare_")]
    if base:
        print("  (bare_pub, bare_sub: the same-run baseline, a bare rclpy pair of the same message at the same rate)")
    v, a = r["viewer"], r["viewer"]["age_ms"]
    print(
        f"viewer: {v['status_lines']} status lines ({v['status_lines_per_s']} per s); "
        f"{v['rate_hz']['p50']} msg/s median (min {v['rate_hz']['min']}, max {v['rate_hz']['max']})"
    )
    print(
        f"  states received {v['received']} ({v['received_per_s']} per s of {s['rate_hz']:g} published), "
        f"applied {v['applied']}, coalesced {v['coalesced']} ({100 * (v['coalesced_fraction'] or 0):.2f} %); "
        f"rejected {v['rejected']}"
    )
    print(
        f"  newest state's age ms: p50 {a['p50']}, p99 {a['p99']}, max {a['max']}; "
        f"p50 minute by minute {a['p50_by_minute']}"
    )
    print(f"  stale records {v['stale_records']}, status lines saying stale {v['stale_status_lines']}")
    sim = r["simulation"]
    print(
        f"simulation: real-time factor {sim['real_time_factor']}, {sim['simulated_time']} s simulated, "
        f"{sim['published']} states published"
    )
    print(f"exit codes: {r['exit_codes']}")
    print("\n== targets")
    for name, t in r["targets"].items():
        details = ", ".join(f"{k} {v}" for k, v in t.items() if k != "pass")
        print(f"  {'PASS' if t['pass'] else 'FAIL'}  {name}  ({details})")


def bare(role: str, rate: float) -> int:
    """The baseline: a bare rclpy publisher or subscriber of the tutorial's ``JointState``, until Ctrl-C.

    Same message (2 joints), topic pattern and QoS as the tutorial's
    publisher; it keeps nothing of what it receives, so its memory is rclpy's
    and Fast DDS's own.
    """
    import rclpy
    from rclpy.executors import ExternalShutdownException
    from sensor_msgs.msg import JointState

    from tutorial.interfaces.joint_state import joint_state_qos

    rclpy.init()
    node = rclpy.create_node(f"soak_bare_{role}")
    topic, count = "/SoakBare/joint_state", [0]
    if role == "pub":
        pub = node.create_publisher(JointState, topic, joint_state_qos())

        def tick():
            msg = JointState()
            msg.header.stamp = node.get_clock().now().to_msg()
            msg.name, msg.position = ["A", "B"], [0.1 * (count[0] % 10), 0.2]
            msg.velocity, msg.effort = [0.0, 0.0], [0.0, 0.0]
            pub.publish(msg)
            count[0] += 1

        node.create_timer(1.0 / rate, tick)
    else:
        node.create_subscription(JointState, topic, lambda msg: count.__setitem__(0, count[0] + 1), joint_state_qos())
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    print(json.dumps({"event": "bare", "role": role, "messages": count[0]}), flush=True)
    return 0


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--bare", choices=["pub", "sub"], help=argparse.SUPPRESS)  # the baseline's own processes
    p.add_argument("--minutes", type=float, default=10.0, help="length of the measured window (default 10)")
    p.add_argument("--warmup", type=float, default=30.0, help="s between the first state shown and the window")
    p.add_argument("--sample", type=float, default=10.0, help="s between memory and CPU samples (default 10)")
    p.add_argument("--rate", type=float, default=1000.0, help="joint state rate, Hz (default 1000)")
    p.add_argument("--headless", action="store_true", help="no meshcat pages (make demo has them)")
    p.add_argument(
        "--no-baseline", dest="baseline", action="store_false", help="without the bare rclpy pair running alongside"
    )
    p.add_argument("--output", default=str(RESULTS / "soak.json"))
    args = p.parse_args(argv)
    if args.bare:
        return bare(args.bare, args.rate)
    if args.minutes <= 0 or args.warmup < 0 or args.sample <= 0:
        p.error("--minutes and --sample must be > 0, --warmup >= 0")
    r = soak(args.minutes, args.warmup, args.sample, args.rate, args.headless, args.baseline)
    report(r)
    out = Path(args.output)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(r, indent=1))
    print(f"\nresults: {out}")
    return 0 if all(t["pass"] for t in r["targets"].values()) else 1


if __name__ == "__main__":
    sys.exit(main())
