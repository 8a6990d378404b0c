"""Joining a running robot: how soon a new viewer, or a new recorder, gets the state a publisher keeps.

    python -m benchmarks.experiments.late_join [--starts 20] [--idle-seconds 20]

A publisher of ``sensor_msgs/JointState`` with the joint state's QoS
(transient local, keep last 1) runs at 0.1 Hz, so what a newcomer gets in
its first seconds is the kept state, not a new one.  Then, ``--starts``
times, a fresh process starts a node (a new DDS participant) and waits:

* ``viewer``: the subscription the Step 3 monitor makes for late joiners
  (transient local, :func:`tutorial.interfaces.joint_state.joint_state_qos`);
  the figure is from its creation to the kept state's arrival;
* ``recorder``: ``rtt-bag record``'s :class:`tutorial.tools.bag.record.BagRecorder`
  on the topic; from its start to the first message written.

Both run under the project's Fast DDS profile (``tutorial/ros/fastdds_profiles.xml``)
and under Fast DDS's defaults (an empty profile), alternating start by
start, so both see the same machine.  A newcomer finds a running
publisher only when that publisher's participant next announces itself:
Fast DDS's default announcement period is 3 s.

The price of announcing more often: ``--idle`` participants (nodes doing
nothing) run ``--idle-seconds`` under each profile, and the experiment
reads their CPU time and the UDP datagrams this machine sent meanwhile
(``/proc/net/snmp``: every process's, so other work on the machine adds
to it; the two profiles alternate for that reason).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks.paths import ROOT

TOPIC = "/LateJoin/joint_state"
WAIT_S = 10.0  # the longest a newcomer waits for the kept state

# One process of each kind; each prints one JSON line.
PUBLISHER = """
import sys, time
import tutorial  # localhost discovery and the project's profile unless the environment names another
import rclpy
from sensor_msgs.msg import JointState
from tutorial.interfaces.joint_state import joint_state_qos
rclpy.init()
node = rclpy.create_node("late_join_publisher")
pub = node.create_publisher(JointState, sys.argv[1], joint_state_qos())
msg = JointState(); msg.name = ["TURRET_Y", "TURRET_P"]; msg.position = [0.25, -0.1]
print('{"ready": true}', flush=True)
next_due = time.monotonic()
while True:  # 0.1 Hz until killed
    if time.monotonic() >= next_due:
        pub.publish(msg); next_due += 10.0
    rclpy.spin_once(node, timeout_sec=0.5)
"""

VIEWER = """
import json, sys, time
import tutorial
import rclpy
from sensor_msgs.msg import JointState
from tutorial.interfaces.joint_state import joint_state_qos
rclpy.init()
node = rclpy.create_node("late_join_viewer")
got = []
t0 = time.monotonic()
node.create_subscription(JointState, sys.argv[1], lambda m: got.append(time.monotonic()), joint_state_qos())
while not got and time.monotonic() - t0 < float(sys.argv[2]):
    rclpy.spin_once(node, timeout_sec=0.02)
print(json.dumps({"s": got[0] - t0 if got else None}), flush=True)
"""

RECORDER = """
import json, sys, time
import tutorial
import rclpy
from tutorial.tools.bag.record import BagRecorder
rclpy.init()
t0 = time.monotonic()
rec = BagRecorder(sys.argv[3], [sys.argv[1]], output=lambda text: None).start()
first = None
while first is None and time.monotonic() - t0 < float(sys.argv[2]):
    if rec.stats().messages:
        first = time.monotonic() - t0
    time.sleep(0.005)  # polling the recorder's count: a newcomer's wait is what is measured, +-5 ms
rec.close()
print(json.dumps({"s": first}), flush=True)
"""

IDLE = """
import time, rclpy
import tutorial
rclpy.init()
node = rclpy.create_node("late_join_idle")
print('{"ready": true}', flush=True)
while True:
    time.sleep(1.0)
"""


def summary(seconds: list[float]) -> dict:
    """n, p50, p95 and max of ``seconds``, s (None when empty)."""
    if not seconds:
        return {"n": 0, "p50": None, "p95": None, "max": None}
    a = np.asarray(seconds, dtype=float)
    return {
        "n": int(a.size),
        "p50": round(float(np.percentile(a, 50)), 3),
        "p95": round(float(np.percentile(a, 95)), 3),
        "max": round(float(a.max()), 3),
    }


def _env(profile: str) -> dict:
    env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST", PYTHONUNBUFFERED="1")
    env["FASTRTPS_DEFAULT_PROFILES_FILE"] = profile
    return env


def _udp_datagrams_sent() -> int:
    lines = [line.split() for line in Path("/proc/net/snmp").read_text().splitlines() if line.startswith("Udp:")]
    header, values = lines[0], lines[1]
    return int(values[header.index("OutDatagrams")])


def _start(code: str, env: dict, *args: str) -> subprocess.Popen:
    proc = subprocess.Popen([sys.executable, "-c", code, *args], cwd=ROOT, env=env, stdout=subprocess.PIPE, text=True)
    seen = []  # Fast DDS may print first (an empty profile: "Could not extract any profile")
    for line in proc.stdout:
        if '"ready"' in line:
            return proc
        seen.append(line)
        if len(seen) > 20:
            break
    proc.kill()
    raise RuntimeError(f"a helper process did not start: {''.join(seen)[-500:]!r}")


def _stop(procs) -> None:
    for p in procs:
        p.kill()
    for p in procs:
        p.wait(10)


def _one(code: str, env: dict, *args: str) -> float | None:
    out = subprocess.run(
        [sys.executable, "-c", code, *args], cwd=ROOT, env=env, capture_output=True, text=True, timeout=60
    )
    if out.returncode != 0:
        raise RuntimeError(f"a newcomer failed: {out.stderr.strip().splitlines()[-1:]}")
    return json.loads([line for line in out.stdout.splitlines() if line.startswith("{")][-1])["s"]


def late_join(starts: int = 20, idle: int = 8, idle_seconds: float = 20.0, settle_s: float = 4.0) -> dict:
    """Late-join times (s) of a viewer and a recorder under both profiles, and the cost of each profile.

    Returns ``{"viewer": {profile: pct}, "recorder": {...}, "missed": {...}, "idle": {...}, "profiles": {...}}``;
    each time is :func:`summary` of the seconds (p50, p95, max), a newcomer that got nothing in
    ``WAIT_S`` counted in ``missed``.
    """
    from tutorial.ros.env import PROJECT_PROFILES

    with tempfile.TemporaryDirectory() as d:
        empty = Path(d) / "fast_dds_defaults.xml"
        empty.write_text('<profiles xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles"/>\n')
        profiles = {"project": str(PROJECT_PROFILES), "fast_dds_default": str(empty)}
        times: dict = {kind: {name: [] for name in profiles} for kind in ("viewer", "recorder")}
        missed: dict = {kind: {name: 0 for name in profiles} for kind in times}
        for name, profile in profiles.items():
            env = _env(profile)
            publisher = _start(PUBLISHER, env, TOPIC)
            try:
                time.sleep(settle_s)  # the publisher is "running": past its own first announcements
                for i in range(starts):
                    for kind, code in (("viewer", VIEWER), ("recorder", RECORDER)):
                        s = _one(code, env, TOPIC, str(WAIT_S), str(Path(d) / f"{name}_{i}.mcap"))
                        if s is None:
                            missed[kind][name] += 1
                        else:
                            times[kind][name].append(s)
            finally:
                _stop([publisher])
        idle_cost: dict = {name: {"cpu_cores": [], "udp_datagrams_per_s": []} for name in profiles}
        import psutil

        for _ in range(2):  # alternate, so a busy moment of the machine falls on both
            for name, profile in profiles.items():
                env = _env(profile)
                procs = [_start(IDLE, env) for _ in range(idle)]
                try:
                    time.sleep(settle_s)  # past the initial announcements
                    ps = [psutil.Process(p.pid) for p in procs]
                    cpu0 = sum(sum(p.cpu_times()[:2]) for p in ps)
                    udp0, t0 = _udp_datagrams_sent(), time.monotonic()
                    time.sleep(idle_seconds)
                    dt = time.monotonic() - t0
                    cpu = sum(sum(p.cpu_times()[:2]) for p in ps) - cpu0
                    idle_cost[name]["cpu_cores"].append(round(cpu / dt / idle, 5))
                    idle_cost[name]["udp_datagrams_per_s"].append(round((_udp_datagrams_sent() - udp0) / dt / idle, 1))
                finally:
                    _stop(procs)
    return {
        "starts": starts,
        "viewer": {name: summary(v) for name, v in times["viewer"].items()},
        "recorder": {name: summary(v) for name, v in times["recorder"].items()},
        "missed": missed,
        "idle_participants": idle,
        "idle_seconds": idle_seconds,
        "idle_per_participant": idle_cost,
        "profiles": profiles,
    }


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--starts", type=int, default=20)
    p.add_argument("--idle", type=int, default=8, help="idle participants for the cost (default 8)")
    p.add_argument("--idle-seconds", type=float, default=20.0)
    args = p.parse_args(argv)
    os.environ.setdefault("ROS_DOMAIN_ID", str(60 + os.getpid() % 40))
    r = late_join(args.starts, args.idle, args.idle_seconds)
    print(json.dumps(r, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
