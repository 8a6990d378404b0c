"""Across the network: the robot on one host, the operator's monitor and camera viewer on another.

    python -m benchmarks.experiments.network [--seconds 14] [--cases clean,loss20,5mbit,partition,5mbit_raw]
    python -m benchmarks.experiments.network --bandwidth     # each topic's bandwidth at its default rate
    python -m benchmarks.experiments.network --encoders      # Pillow against simplejpeg on the camera's pictures

Two hosts (:class:`tutorial.tools.network.hosts.Network`, network namespaces joined by
a switch; root only).  On ``robot``: the simulation with the tank's joystick
controller, joint states (50 Hz), IMU (20 Hz) and camera (30 Hz), plus the
step clock probe.  On ``operator``: the Step 3 monitor (``rtt-run``
with the probed monitor, run by ``rtt-run``), the demo joystick (its Joy crosses the link to the
robot) and a camera viewer (``benchmarks.net_probe``, an ``rtt-image``'s
receiver, compressed by default).  One run per case, the faults on the
robot's link, both ways:

* ``clean``: nothing; the baseline every other case is set beside;
* ``loss20``: 20 % of packets dropped at random (nftables ``numgen``);
* ``5mbit``: 5 Mbit/s each way (``tc`` token bucket), the camera on, compressed;
* ``partition``: every packet dropped for 4 s, 3 s after the first state;
* ``5mbit_raw``: 5 Mbit/s with the camera viewer on the *raw* topic: the
  issue's "before", not a target;
* ``loss20_best_effort``: 20 % loss, the monitor's live subscription best
  effort instead of reliable, for comparison (exercise 8.1);
* ``loss20_dds_default``: 20 % loss, every program with Fast DDS's default
  timing instead of the project's profile (``tutorial/ros/fastdds_profiles.xml``:
  a 5 ms heartbeat, not 3 s), for comparison.

Figures of each case, beside the same run's clean link: joint states applied
per second at the remote monitor, their age p50/p99 (from the start of the
step that produced a state to the monitor's main thread applying it: every
namespace shares ``time.monotonic_ns()``), time to ``stale`` after the cut
and back to ``live`` after the heal, camera pictures per second at the viewer
and their age (to the end of decoding), whether the monitor ended on the
simulation's final state, and the simulation's real-time factor.

:func:`measure` returns the figures as a dict (``make bench`` keeps them as
``latest.json``'s ``network``); the targets are data in
:data:`benchmarks.targets.NETWORK_TARGETS`.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks.paths import ROOT
from benchmarks.procs import py
from benchmarks.stats import pct
from tutorial.tools.network.host_program import HostProgram

SIM_PROJECT = "benchmarks/projects/tank_net_sim.yaml"
VIEW_PROJECT = "benchmarks/projects/tank_view.yaml"
CASES = {  # in the order they run; the raw flood last, so nothing of it can linger into another case
    "clean": {},
    "loss20": {"loss": 20},
    "loss20_best_effort": {"loss": 20, "view": "benchmarks/projects/tank_view_best_effort.yaml"},
    "loss20_dds_default": {"loss": 20, "dds_default": True},
    "5mbit": {"rate_mbit": 5.0},
    "partition": {"partition_s": 4.0},
    "5mbit_raw": {"rate_mbit": 5.0, "transport": "raw"},
}
PARTITION_AFTER = 3.0  # s after the monitor's first state
STARTUP_TIMEOUT = 60.0  # s for the monitor's first state


def viewer_record(line: str) -> dict | None:
    """One JSON record printed by ``rtt-run --json``, or None."""
    if not line.startswith("{"):
        return None
    try:
        record = json.loads(line)
    except ValueError:
        return None
    return record if isinstance(record, dict) else None


def is_event(event: str):
    return lambda line: line.startswith("{") and f'"event": "{event}"' in line


def run_case(net, name: str, spec: dict, seconds: float, work: Path) -> dict:
    """One run of the robot and the operator with ``spec``'s faults on the robot's link; its figures."""
    robot, operator = net["robot"], net["operator"]
    robot.clear_faults()
    if spec.get("rate_mbit"):
        robot.limit_rate(spec["rate_mbit"])
    if spec.get("loss"):
        robot.set_loss(spec["loss"])
    transport = spec.get("transport", "compressed")
    sim_probe, view_probe = work / f"{name}.sim.json", work / f"{name}.view.json"
    dds = {}
    if spec.get("dds_default"):  # a profiles file with no profile: Fast DDS's own defaults
        empty = work / "no_profiles.xml"
        empty.write_text('<profiles xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles"/>\n')
        dds = {"FASTRTPS_DEFAULT_PROFILES_FILE": str(empty)}
    camera_out = work / f"{name}.camera.json"
    view = HostProgram(
        operator,
        py(
            "tutorial.tools.rtt_run",
            spec.get("view", VIEW_PROJECT),
            "--headless",
            "--json",
            "--ros-args",
            "-r",
            "__node:=rtt_viewer",
        ),
        {"RTT_PROBE_FILE": str(view_probe), **dds},
    )
    camera = HostProgram(
        operator,
        py(
            "benchmarks.net_probe",
            "camera",
            "--transport",
            transport,
            "--duration",
            str(seconds + 60),
            "--out",
            str(camera_out),
        ),
        dds,
    )
    joy = HostProgram(operator, py("tutorial.tools.rtt_joy", "--demo"), dds)
    sim = None
    try:
        if camera.first(lambda line: line.startswith("probe: subscribed"), 30) is None:
            raise RuntimeError(f"the camera probe did not start:\n{camera.text()}")
        sim = HostProgram(
            robot,
            py("tutorial.tools.rtt_run", SIM_PROJECT, "--headless", "--json", "--duration", str(seconds)),
            {"RTT_PROBE_FILE": str(sim_probe), **dds},
        )
        first = view.first(is_event("first_state"), STARTUP_TIMEOUT)
        if first is None:
            raise RuntimeError(f"{name}: no state reached the monitor:\n{view.text()}\n{sim.text()}")
        cut = healed = None
        if spec.get("partition_s"):
            time.sleep(max(0.0, first + PARTITION_AFTER - time.monotonic()))  # not synchronisation: the schedule
            cut = time.monotonic()
            robot.partition()
            time.sleep(spec["partition_s"])  # not synchronisation: the partition lasts this long
            healed = time.monotonic()
            robot.heal()
        if sim.p.wait(seconds + 60) != 0:
            raise RuntimeError(f"{name}: the simulation failed:\n{sim.text()}")
        sim.stop(20)
        # The monitor has its last state when it says stale (nothing more is coming), or 5 s on.
        stale_before = sum(1 for line in view.lines() if is_event("stale")(line))
        deadline = time.monotonic() + 5
        while time.monotonic() < deadline:
            if sum(1 for line in view.lines() if is_event("stale")(line)) > stale_before:
                break
            time.sleep(0.05)  # polling the monitor's output: a deadline loop
    finally:
        for program in (joy, camera, view, sim):
            if program is not None:
                program.stop(20)
        robot.clear_faults()
    summary = next(json.loads(line) for line in reversed(sim.lines()) if line.startswith('{"event": "summary"'))
    return figures(name, spec, summary, sim_probe, view_probe, camera_out, view, cut, healed)


def figures(name, spec, summary, sim_probe, view_probe, camera_out, view, cut, healed) -> dict:
    """The case's figures from the probes' files and the monitor's output."""
    clock = json.loads(Path(sim_probe).read_text())
    step_wall = dict(zip((round(ns / 1e6) for ns in clock["sim_ns"]), clock["wall_ns"]))
    shown = json.loads(Path(view_probe.with_name(view_probe.stem + ".Tank.json")).read_text())
    applied = shown["applied"]  # (stamp ns, callback ns, applied ns)
    ages = [a - step_wall[round(s / 1e6)] for s, _, a in applied if round(s / 1e6) in step_wall]
    stamps = [s for s, _, _ in applied]
    span = (max(stamps) - min(stamps)) / 1e9 if len(stamps) > 1 else 0.0
    final_time = summary["simulated_time"]
    final = summary["bodies"]["Tank"]["joint_positions"]
    records = [r for r in map(viewer_record, view.lines()) if r]
    shown_last = next((r for r in reversed(records) if r.get("event") == "summary"), None)
    last_positions = (shown_last or {}).get("controllers", {}).get("RttJointStateMonitor", {}).get("last_positions")
    ends_exact = bool(
        stamps
        and round(max(stamps) / 1e6) == round(final_time * 1000)
        and last_positions is not None
        and all(abs(last_positions[k] - v) <= 1e-9 for k, v in final.items())
    )
    camera = json.loads(Path(camera_out).read_text())
    pictures = camera["pictures"]  # (stamp ns, arrival ns, bytes)
    picture_ages = [a - step_wall[round(s / 1e6)] for s, a, _ in pictures if round(s / 1e6) in step_wall]
    camera_stamps = [s for s, _, _ in pictures]
    camera_span = (max(camera_stamps) - min(camera_stamps)) / 1e9 if len(camera_stamps) > 1 else 0.0
    out = {
        "case": name,
        "link": spec,
        "states_applied": len(applied),
        "states_per_s": round((len(applied) - 1) / span, 1) if span else 0.0,
        "age_ms": pct(ages, 1e-6),
        "age_p50_ms": pct(ages, 1e-6)["p50"],
        "age_p99_ms": pct(ages, 1e-6)["p99"],
        "ends_exact": ends_exact,
        "camera_transport": camera["topic"],
        "camera_pictures": len(pictures),
        "camera_per_s": round((len(pictures) - 1) / camera_span, 1) if camera_span else 0.0,
        "camera_age_ms": pct(picture_ages, 1e-6),
        "camera_kB": round(float(np.mean([b for _, _, b in pictures])) / 1000, 1) if pictures else None,
        "camera_rejected": camera["counts"]["rejected"],
        "real_time_factor": summary["real_time_factor"],
        "camera_published": summary["controllers"]["RttCameraImagePublisher"]["published"],
    }
    if cut is not None:
        times = [t for t, line in view.timed_lines() if t >= cut and is_event("stale")(line)]
        back = [t for t, line in view.timed_lines() if t >= healed and is_event("recovered")(line)]
        out["stale_after_s"] = round(times[0] - cut, 3) if times else None
        out["live_after_s"] = round(back[0] - healed, 3) if back else None
    return out


def measure(seconds: float = 14.0, cases=tuple(CASES)) -> dict:
    """Run every case once, in order, on one pair of hosts; ``{case: figures}``.

    Raises:
        RuntimeError: hosts cannot be made here (the reason), or a run failed.
    """
    from tutorial.tools.network.hosts import Network, why_unavailable

    problem = why_unavailable()
    if problem:
        raise RuntimeError(f"cannot make the hosts: {problem}")
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"  # this process; the hosts' programs get SUBNET
    os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 100)))
    results = {}
    with tempfile.TemporaryDirectory(prefix="rtt-net-bench-") as tmp, Network(("robot", "operator")) as net:
        for name in cases:
            results[name] = run_case(net, name, CASES[name], seconds, Path(tmp))
            print(f"{name}: done", flush=True)
    return results


def print_table(results: dict) -> None:
    clean = results.get("clean")
    print("\nAcross hosts (robot -> operator), each beside the same run's clean link:")
    header = (
        f"{'case':<18} {'states/s':>9} {'age p50':>8} {'age p99':>8} {'stale':>6} {'live':>6} "
        f"{'img/s':>6} {'img p50':>8} {'img p99':>8} {'kB':>5} {'exact':>6} {'RTF':>6}"
    )
    print(header)

    def row(r: dict) -> str:
        ca = r["camera_age_ms"]
        return (
            f"{r['case']:<18} {r['states_per_s']:>9} {r['age_p50_ms']!s:>8} {r['age_p99_ms']!s:>8} "
            f"{r.get('stale_after_s', '')!s:>6} {r.get('live_after_s', '')!s:>6} {r['camera_per_s']:>6} "
            f"{ca['p50']!s:>8} {ca['p99']!s:>8} {r['camera_kB']!s:>5} {r['ends_exact']!s:>6} "
            f"{r['real_time_factor']:>6.3f}"
        )

    for name, r in results.items():
        print(row(r))
        if clean is not None and name != "clean":
            print(row(clean).replace("clean             ", "  (clean)         ", 1))


# ---------------------------------------------------------------- bandwidth of each topic
TOPICS = [  # (topic, type, default rate in Hz)
    ("/joy", "sensor_msgs/msg/Joy", 20.0),  # rtt-joy repeats the sticks at 20 Hz (more while they move)
    ("/Tank/joint_state", "sensor_msgs/msg/JointState", 50.0),
    ("/Tank/imu", "sensor_msgs/msg/Imu", 20.0),
    ("/Tank/camera/image", "sensor_msgs/msg/Image", 30.0),
    ("/Tank/camera/image/compressed", "sensor_msgs/msg/CompressedImage", 30.0),
]


def bandwidth(seconds: float = 8.0) -> dict:
    """Each topic's messages per second and serialized bytes per second at its default rate.

    The simulation (every publisher at its default rate, JPEG quality 80)
    and the demo joystick on ``robot``; a probe on ``operator`` subscribes
    every topic serialized (nothing decoded).  Bytes are the CDR payload;
    on the wire each message adds about 80 bytes of RTPS, UDP and IP headers
    (a 230 kB raw picture: 4 UDP datagrams of up to 64 kB, about 160 IP
    fragments).  ``{topic: {"per_s", "bytes", "kbit_per_s", "default_hz",
    "kbit_per_s_at_default_rate"}}``: a subscriber in Python may receive fewer
    raw pictures than are sent (best effort), so the bandwidth at the
    default rate is the measured size times that rate.
    """
    from tutorial.tools.network.hosts import Network, why_unavailable

    problem = why_unavailable()
    if problem:
        raise RuntimeError(f"cannot make the hosts: {problem}")
    os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 100)))
    with tempfile.TemporaryDirectory(prefix="rtt-net-bw-") as tmp, Network(("robot", "operator")) as net:
        out = Path(tmp) / "bytes.json"
        robot, operator = net["robot"], net["operator"]
        probe = HostProgram(
            operator,
            py(
                "benchmarks.net_probe",
                "bytes",
                "--duration",
                str(seconds + 6),
                "--out",
                str(out),
                *[f"{t}:{k}" for t, k, _ in TOPICS],
            ),
        )
        probe.first(lambda line: line.startswith("probe: subscribed"), 30)
        joy = HostProgram(robot, py("tutorial.tools.rtt_joy", "--demo"))
        sim = HostProgram(
            robot,
            py("tutorial.tools.rtt_run", SIM_PROJECT, "--headless", "--json", "--duration", str(seconds + 4)),
            {"RTT_PROBE_FILE": str(Path(tmp) / "sim.json")},
        )
        sim.p.wait(seconds + 60)
        probe.p.wait(60)
        for program in (joy, sim, probe):
            program.stop(20)
        if not out.exists():
            raise RuntimeError(f"the probe wrote nothing:\n{probe.text()}")
        sizes = json.loads(out.read_text())["sizes"]
    table = {}
    for topic, _, default_hz in TOPICS:
        got = sizes.get(topic, [])
        if len(got) < 2:
            table[topic] = {"per_s": 0.0, "bytes": None, "kbit_per_s": 0.0, "default_hz": default_hz}
            continue
        # The steady part: from 2 s after the first message to the last.
        start = got[0][0] + 2e9
        steady = [(t, b) for t, b in got if t >= start]
        span = (steady[-1][0] - steady[0][0]) / 1e9
        per_s = (len(steady) - 1) / span if span > 0 else 0.0
        mean = float(np.mean([b for _, b in steady]))
        table[topic] = {
            "per_s": round(per_s, 1),  # as received by the probe
            "bytes": round(mean),
            "kbit_per_s": round(per_s * mean * 8 / 1000, 1),  # as received
            "default_hz": default_hz,
            "kbit_per_s_at_default_rate": round(default_hz * mean * 8 / 1000, 1),
        }
    return table


# ---------------------------------------------------------------- the encoders
def encoders(repeat: int = 500) -> dict:
    """JPEG encode and decode times of Pillow and simplejpeg (if installed) on one camera picture, ms."""
    os.environ.setdefault("MUJOCO_GL", "egl")  # before mujoco is imported: render without a display
    import io

    import mujoco
    from PIL import Image as PilImage

    from tutorial.core.project import load_project
    from tutorial.core.world import build_world

    model = build_world(load_project(ROOT / "project/step6.yaml").models, time_step=0.001)
    renderer, data = mujoco.Renderer(model, 240, 320), mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    renderer.update_scene(data, camera=0)
    pixels = renderer.render()
    renderer.close()

    def best_ms(fn) -> float:
        fn()
        runs = []
        for _ in range(5):
            t0 = time.perf_counter()
            for _ in range(repeat // 5):
                fn()
            runs.append((time.perf_counter() - t0) / (repeat // 5) * 1000)
        return round(float(np.median(runs)), 3)

    def pil_jpeg() -> bytes:
        out = io.BytesIO()
        PilImage.fromarray(pixels).save(out, format="JPEG", quality=80)
        return out.getvalue()

    def pil_png() -> bytes:
        out = io.BytesIO()
        PilImage.fromarray(pixels).save(out, format="PNG", compress_level=1)
        return out.getvalue()

    jpeg = pil_jpeg()
    result = {
        "picture": "320x240 rgb8, the tank's camera at its start pose",
        "pillow": {
            "encode_ms": best_ms(pil_jpeg),
            "decode_ms": best_ms(lambda: np.asarray(PilImage.open(io.BytesIO(jpeg)).convert("RGB"))),
            "bytes": len(jpeg),
            "png_encode_ms": best_ms(pil_png),
            "png_bytes": len(pil_png()),
        },
    }
    try:
        import simplejpeg
    except ImportError:
        result["simplejpeg"] = "not installed (pip install simplejpeg)"
    else:
        result["simplejpeg"] = {
            "encode_ms": best_ms(
                lambda: simplejpeg.encode_jpeg(pixels, quality=80, colorspace="RGB", colorsubsampling="420")
            ),
            "decode_ms": best_ms(lambda: simplejpeg.decode_jpeg(jpeg, colorspace="RGB")),
            "bytes": len(simplejpeg.encode_jpeg(pixels, quality=80, colorspace="RGB", colorsubsampling="420")),
        }
    return result


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seconds", type=float, default=14.0, help="simulated seconds of each case (default 14)")
    p.add_argument("--cases", default=",".join(CASES), help=f"comma-separated, of {', '.join(CASES)}")
    p.add_argument("--bandwidth", action="store_true", help="each topic's bandwidth at its default rate")
    p.add_argument("--encoders", action="store_true", help="Pillow against simplejpeg")
    p.add_argument("--json", metavar="FILE", help="also write the figures to FILE")
    args = p.parse_args(argv)
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    if args.encoders:
        result = encoders()
        print(json.dumps(result, indent=2))
    elif args.bandwidth:
        result = bandwidth()
        print(f"{'topic':<32} {'received/s':>10} {'bytes':>7} {'default Hz':>10} {'kbit/s at default':>17}")
        for topic, r in result.items():
            print(
                f"{topic:<32} {r['per_s']:>10} {r['bytes']!s:>7} {r['default_hz']:>10} "
                f"{r.get('kbit_per_s_at_default_rate', 0.0):>17}"
            )
    else:
        cases = [c for c in args.cases.split(",") if c]
        unknown = set(cases) - set(CASES)
        if unknown:
            p.error(f"unknown cases {sorted(unknown)}")
        result = measure(args.seconds, cases)
        print_table(result)
        from benchmarks.targets import NETWORK_TARGETS

        print("\ntargets (of the cases run):")
        for target in NETWORK_TARGETS:
            try:
                row = target.row({"network": result})
            except KeyError:  # a case it reads was not in --cases
                continue
            print(
                f"  [{'PASS' if row['pass'] else 'FAIL'}] {row['target']}: {row['measured']}"
                + (f" vs {row['baseline']}" if row["baseline"] else "")
            )
        result = {"cases": result}
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
