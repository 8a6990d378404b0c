"""The benchmark suite: ``make bench`` (or ``python -m benchmarks.run``).

Every figure comes with a baseline measured in the same run, and the ratio,
because absolute times on a shared machine vary:

* simulation speed: the tutorial's simulation with its controllers against
  a bare ``mj_step`` loop on the same model;
* end-to-end latency across processes (simulation step -> state applied on
  the viewer's main thread) against a bare rclpy publisher/subscriber pair
  of the same ``sensor_msgs/JointState`` with the same QoS, in interleaved
  rounds whose samples are pooled; at 1 kHz the same rounds also run the
  tutorial and the bare pair on rclpy's EventsExecutor (``RTT_EXECUTOR=events``,
  an opt-in), for comparison;
* the viewer under a 1 kHz flood: age of the displayed state, backlog,
  meshcat cost per frame, frames per second, CPU per process;
* start-up: from the launch command to the first state shown;
* scale: the same for a 24-joint arm.

It prints a table, reports pass or fail on each target, and writes
``benchmarks/results/latest.json``.  ROS traffic stays on this machine
(localhost discovery, a ROS_DOMAIN_ID of its own).
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
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results"
FRAME_60HZ_MS = 1000.0 / 60.0


# ---------------------------------------------------------------- helpers
def pct(values, scale=1.0) -> dict:
    """p50/p90/p99/max of ``values`` times ``scale``, rounded (empty: None)."""
    if len(values) == 0:
        return {"n": 0, "p50": None, "p90": None, "p99": None, "max": None}
    a = np.asarray(values, dtype=float) * scale
    return {"n": int(a.size), "p50": round(float(np.percentile(a, 50)), 3), "p90": round(float(np.percentile(a, 90)), 3),
            "p99": round(float(np.percentile(a, 99)), 3), "max": round(float(a.max()), 3)}


def cpu_seconds(pid: int) -> float:
    """User + system CPU time of a process and its children, s."""
    import psutil

    try:
        proc = psutil.Process(pid)
        total = sum(proc.cpu_times()[:2])
        for child in proc.children(recursive=True):
            try:
                total += sum(child.cpu_times()[:2])
            except psutil.NoSuchProcess:
                pass
        return total
    except psutil.NoSuchProcess:
        return float("nan")


def start(cmd: list[str], probe: Path | None = None, extra_env: dict | None = None) -> subprocess.Popen:
    env = {**os.environ, **(extra_env or {})}
    if probe is not None:
        env["RTT_PROBE_FILE"] = str(probe)
    return subprocess.Popen(cmd, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def finish(proc: subprocess.Popen, timeout: float) -> str:
    try:
        out, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        proc.kill()
        out, err = proc.communicate()
        raise RuntimeError(f"{proc.args} did not finish:\n{out}\n{err}")
    if proc.returncode != 0:
        raise RuntimeError(f"{proc.args} exited {proc.returncode}:\n{out}\n{err}")
    return out


def py(*args: str) -> list[str]:
    return [sys.executable, "-u", "-m", *args]


# ---------------------------------------------------------------- 1. simulation speed
def simulation_speed(project: str, rates: dict[str, float], pairs: int, steps: int) -> dict:
    """Steps/s of the project's simulation with its controllers (as fast as possible) vs bare mj_step.

    This machine's CPU speed drifts by tens of percent within seconds, so
    single runs cannot be compared.  The two are measured in short
    interleaved runs of ``steps`` steps (bare, pipeline, bare, ...) on the
    same kind of thread; each pipeline run is divided by the mean of the bare runs on
    either side, and the median of those ratios is reported with its
    quartiles.
    """
    import threading

    import mujoco
    import rclpy

    from tutorial.body import Body
    from tutorial.controller import ControllerConfig
    from tutorial.project import load_project
    from tutorial.simulator import Attachment, Simulator
    from tutorial.world import build_world

    proj = load_project(ROOT / project)
    model = build_world(proj.models, time_step=proj.simulator.time_step)
    node = rclpy.create_node(f"bench_speed_{random.randrange(10**6)}")

    def in_thread(fn):
        out = []
        t = threading.Thread(target=lambda: out.append(fn()))
        t.start()
        t.join()
        return out[0]

    def bare() -> float:
        data = mujoco.MjData(model)
        t0 = time.perf_counter()
        for _ in range(steps):
            mujoco.mj_step(model, data)
        return steps / (time.perf_counter() - t0)

    out: dict = {}
    bare_all = []
    try:
        for label, rate in rates.items():
            attachments = []
            for m in proj.models:
                for c in m.controllers:
                    if c.name == "StepClock":
                        continue
                    params = dict(c.parameters)
                    if "rate" in params:
                        params["rate"] = rate
                    controller = c.cls()
                    config = ControllerConfig(name=c.name, body=Body(model, mujoco.MjData(model), m.name), node=node,
                                              parameters=params)
                    assert controller.configure(config)
                    attachments.append(Attachment(c.name, controller, m.name))

            def pipeline() -> float:
                data = mujoco.MjData(model)
                sim = Simulator(model, data, attachments, node=node, realtime_sync=False,
                                duration=steps * model.opt.timestep).start()
                sim.join()
                if sim.error:
                    raise RuntimeError(sim.error)
                return sim.steps / sim.wall_time

            ratios, speeds = [], []
            before = in_thread(bare)
            for _ in range(pairs):
                p = pipeline()
                after = in_thread(bare)
                ratios.append(p / ((before + after) / 2))
                speeds.append(p)
                bare_all += [before, after]
                before = after
            q1, med, q3 = np.percentile(ratios, [25, 50, 75])
            out[f"{label}_steps_per_s"] = round(float(np.median(speeds)))
            out[f"{label}_ratio"] = round(float(med), 3)
            out[f"{label}_ratio_quartiles"] = [round(float(q1), 3), round(float(q3), 3)]
            for a in attachments:
                a.controller.unconfigure()
    finally:
        node.destroy_node()
    out["bare_steps_per_s"] = round(float(np.median(bare_all)))
    out["pairs"] = pairs
    out["steps_per_run"] = steps
    return out


def realtime_mode(project: str, seconds: float) -> dict:
    """Real-time factor and step overrun percentiles with every controller on, in real-time mode."""
    from tutorial.app import App
    from tutorial.project import load_project

    proj = load_project(ROOT / project)
    for m in proj.models:
        m.controllers = [c for c in m.controllers if c.name != "StepClock"]
    app = App(proj, node_name=f"bench_rt_{random.randrange(10**6)}", headless=True, realtime_sync=True,
              duration=seconds, output=lambda r: None, record_timing=True)
    try:
        app.open()
        app.run()
    finally:
        app.close()
    late = pct(app.sim.lateness, 1000.0)
    return {"real_time_factor": round(app.sim.real_time_factor, 4), "overrun_ms": late}


# ---------------------------------------------------------------- 2-3. across processes
def steady_cpu_cores(procs: dict[str, subprocess.Popen], seconds: float, warmup: float) -> dict[str, float]:
    """CPU cores each running process (with its children) uses over the steady part of a run.

    Waits out discovery and the warm-up first (not synchronisation: the
    sample simply starts later), then samples for the rest of the run.
    """
    time.sleep(warmup + 2.0)
    cpu0 = {k: cpu_seconds(p.pid) for k, p in procs.items()}
    t0 = time.monotonic()
    time.sleep(max(1.0, seconds - warmup - 3.0))
    cpu1 = {k: cpu_seconds(p.pid) for k, p in procs.items()}
    span = time.monotonic() - t0
    return {k: (cpu1[k] - cpu0[k]) / span for k in procs}


def pipeline_run(sim_project: str, view_project: str, rate: float, seconds: float, warmup: float,
                 headless_view: bool = False, executor: str = "single") -> dict:
    """One run of simulation and viewer as two processes: raw samples, joined on the state's stamp.

    ``executor`` is the spin threads' (``RTT_EXECUTOR``): ``single``, the
    tutorial's default, or ``events``, the opt-in, for comparison.
    """
    env = {"RTT_EXECUTOR": executor}
    with tempfile.TemporaryDirectory() as d:
        sim_probe, view_probe = Path(d) / "sim.json", Path(d) / "view.json"
        view_cmd = py("benchmarks.viewer_proc", view_project)
        if headless_view:
            view_cmd.append("--headless")
        viewer = start(view_cmd + ["--duration", str(seconds + 8.0)], view_probe, env)
        time.sleep(1.0)  # not synchronisation: the viewer starts first so it misses nothing
        sim = start(py("tutorial.runner", sim_project, "--headless", "--duration", str(seconds), "--json",
                       "--ros-args", "-p", f"RttJointStatePublisher.rate:={rate}"), sim_probe, env)
        cpu = steady_cpu_cores({"simulation": sim, "viewer": viewer}, seconds, warmup)
        finish(sim, seconds + 30)
        finish(viewer, seconds + 30)
        s = json.loads(sim_probe.read_text())
        v = json.loads(view_probe.read_text())
    step_wall = {round(t / 1000): w for t, w in zip(s["sim_ns"], s["wall_ns"])}
    # The measured window: from the first state the viewer applied (discovery can take a few
    # seconds) plus the warm-up, to the simulation's last step (after it, frames show an old state).
    if not v["applied"]:
        raise RuntimeError(f"the viewer applied no state in the {sim_project} run")
    start_ns = v["applied"][0][2] + int(warmup * 1e9)
    end_ns = s["wall_ns"][-1]
    window = [(step_wall[round(stamp / 1000)], arrived, applied) for stamp, arrived, applied in v["applied"]
              if round(stamp / 1000) in step_wall and start_ns <= applied <= end_ns]
    frames = [(t, stamp, cost) for t, stamp, cost in v["frames"]
              if start_ns <= t <= end_ns and round(stamp / 1000) in step_wall]
    ages = [t - step_wall[round(stamp / 1000)] for t, stamp, _ in frames]
    return {
        "latency": [applied - step for step, _, applied in window],
        "step_to_callback": [arrived - step for step, arrived, _ in window],
        "callback_to_applied": [applied - arrived for _, arrived, applied in window],
        "ages": ages,
        "frames": len(frames),
        "frame_span_s": (frames[-1][0] - frames[0][0]) * 1e-9 if len(frames) > 1 else 0.0,
        "scene_update_s": [c for _, _, c in frames],
        "messages": {"applied": len(v["applied"]), "posted": v["posted"], "coalesced": v["coalesced"],
                     "max_pending": v["max_pending"]},
        "cpu_cores": cpu,
    }


def pool_pipeline(runs: list[dict], rate: float) -> dict:
    """The pipeline's figures over interleaved runs: samples pooled, CPU averaged, counts summed."""
    ages_first = [a for r in runs for a in r["ages"][: len(r["ages"]) // 2]]
    ages_second = [a for r in runs for a in r["ages"][len(r["ages"]) // 2:]]
    span = sum(r["frame_span_s"] for r in runs)
    cpu = {k: round(statistics.mean(r["cpu_cores"][k] for r in runs), 3) for k in runs[0]["cpu_cores"]}
    return {
        "rate_hz": rate,
        "runs": len(runs),
        "latency_ms": pct([x for r in runs for x in r["latency"]], 1e-6),
        "step_to_callback_ms": pct([x for r in runs for x in r["step_to_callback"]], 1e-6),
        "callback_to_applied_ms": pct([x for r in runs for x in r["callback_to_applied"]], 1e-6),
        "displayed_age_ms": pct(ages_first + ages_second, 1e-6),
        "displayed_age_p99_ms_first_half": pct(ages_first, 1e-6)["p99"],
        "displayed_age_p99_ms_second_half": pct(ages_second, 1e-6)["p99"],
        "frames_per_s": round(sum(r["frames"] for r in runs) / span, 1) if span > 0 else 0.0,
        "scene_update_ms": pct([c for r in runs for c in r["scene_update_s"]], 1000.0),
        "messages": {"applied": sum(r["messages"]["applied"] for r in runs),
                     "posted": sum(r["messages"]["posted"] for r in runs),
                     "coalesced": sum(r["messages"]["coalesced"] for r in runs),
                     "max_pending": max(r["messages"]["max_pending"] for r in runs)},
        "cpu_cores": {**cpu, "total": round(sum(cpu.values()), 3)},
    }


def bare_pair_run(rate: float, seconds: float, warmup: float, joints: int, executor: str = "single") -> dict:
    """One run of the bare rclpy pair at the same rate, same message and QoS: raw samples.

    ``executor`` is the subscriber's: ``single`` (rclpy's default, the
    baseline) or ``events`` (the EventsExecutor, for comparison).
    """
    with tempfile.TemporaryDirectory() as d:
        probe = Path(d) / "bare.json"
        sub = start(py("benchmarks.bare_pair", "sub", "--duration", str(seconds + 8.0), "--executor", executor), probe)
        time.sleep(1.0)  # not synchronisation: the subscriber starts first so it misses nothing
        pub = start(py("benchmarks.bare_pair", "pub", "--rate", str(rate), "--duration", str(seconds),
                       "--joints", str(joints)))
        cpu = sum(steady_cpu_cores({"pub": pub, "sub": sub}, seconds, warmup).values())
        finish(pub, seconds + 30)
        finish(sub, seconds + 30)
        received = json.loads(probe.read_text())["received"]
    first = received[0][1] if received else 0
    return {"latency": [r - s for s, r in received if r >= first + int(warmup * 1e9)], "received": len(received),
            "cpu_cores": cpu}


def pool_bare(runs: list[dict], rate: float) -> dict:
    return {"rate_hz": rate, "runs": len(runs), "latency_ms": pct([x for r in runs for x in r["latency"]], 1e-6),
            "received": sum(r["received"] for r in runs),
            "cpu_cores": round(statistics.mean(r["cpu_cores"] for r in runs), 3)}


# ---------------------------------------------------------------- 3b. meshcat cost per frame
def scene_update_cost(model_file: str, frames: int) -> dict:
    """ms per frame to move every body of a model in meshcat: pipelined (the library) vs a round trip per body.

    The baseline is meshcat-python's own ``set_transform``, which waits for
    the server's reply after each command; both run against one server, interleaved.
    """
    import mujoco

    from tutorial.meshcat_server import start_server
    from tutorial.scene import Scene
    from tutorial.world import ModelEntry, build_world

    model = build_world([ModelEntry("M", ROOT / model_file)])
    data = mujoco.MjData(model)
    server = start_server()
    try:
        scene = Scene(server.visualizer(), model)
        scene.build(data)
        pipe = scene._pipe
        times = {"pipelined": [], "round_trip_per_body": []}
        for i in range(frames):
            for label, p in (("pipelined", pipe), ("round_trip_per_body", None)):
                scene._pipe = p
                data.qpos[:] = 0.001 * (2 * i + (p is None))
                mujoco.mj_kinematics(model, data)
                t0 = time.perf_counter()
                scene.update(data)
                times[label].append(time.perf_counter() - t0)
        scene._pipe = pipe
        scene.close()
    finally:
        server.close()
    out = {k: pct(v, 1000.0) for k, v in times.items()}
    out["bodies"] = len(scene.moving_bodies)
    out["speedup_p50"] = round(out["round_trip_per_body"]["p50"] / out["pipelined"]["p50"], 2)
    return out


# ---------------------------------------------------------------- 4. start-up
def startup(repeats: int) -> dict:
    """Seconds from starting ``launch_py/step3_launch.py --demo`` to the viewer's first applied state."""
    times = []
    for _ in range(repeats):
        t0 = time.monotonic()
        proc = subprocess.Popen([sys.executable, "-u", str(ROOT / "launch_py" / "step3_launch.py"), "--demo"],
                                cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        first = None
        deadline = t0 + 60
        for line in proc.stdout:
            if line.startswith("[rtt_viewer]") and "first joint state" in line:
                first = time.monotonic() - t0
                break
            if time.monotonic() > deadline:
                break
        proc.send_signal(signal.SIGINT)
        try:
            proc.communicate(timeout=20)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.communicate()
        if first is None:
            raise RuntimeError("the viewer showed no state within 60 s of the launch")
        times.append(first)
    return {"first_state_s": [round(t, 3) for t in times], "median_s": round(statistics.median(times), 3)}


# ---------------------------------------------------------------- report
def targets(r: dict) -> list[tuple[str, bool, str]]:
    tank1k, bare1k = r["pipeline"]["tank_1kHz"], r["bare"]["tank_1kHz"]
    sim = r["simulation_speed"]["tank"]
    out = [
        ("simulation with 50 Hz publisher >= 0.8x bare mj_step", sim["publisher_50Hz_ratio"] >= 0.8,
         f"{sim['publisher_50Hz_ratio']:.3f}x"),
        ("end-to-end p50 <= 1.5x bare rclpy pair at 1 kHz",
         tank1k["latency_ms"]["p50"] <= 1.5 * bare1k["latency_ms"]["p50"],
         f"{tank1k['latency_ms']['p50']:.3f} ms vs {bare1k['latency_ms']['p50']:.3f} ms "
         f"({tank1k['latency_ms']['p50'] / bare1k['latency_ms']['p50']:.2f}x)"),
        ("end-to-end p99 <= 3x bare rclpy pair at 1 kHz",
         tank1k["latency_ms"]["p99"] <= 3 * bare1k["latency_ms"]["p99"],
         f"{tank1k['latency_ms']['p99']:.3f} ms vs {bare1k['latency_ms']['p99']:.3f} ms "
         f"({tank1k['latency_ms']['p99'] / bare1k['latency_ms']['p99']:.2f}x)"),
        ("displayed-state age p99 <= 16.7 ms + bare p99",
         tank1k["displayed_age_ms"]["p99"] <= FRAME_60HZ_MS + bare1k["latency_ms"]["p99"],
         f"{tank1k['displayed_age_ms']['p99']:.2f} ms vs {FRAME_60HZ_MS + bare1k['latency_ms']['p99']:.2f} ms"),
        ("Step 3 pipeline at 1 kHz <= 1 CPU core", tank1k["cpu_cores"]["total"] <= 1.0,
         f"{tank1k['cpu_cores']['total']:.2f} cores"),
        ("first state shown <= 3 s after launch", r["startup"]["median_s"] <= 3.0, f"{r['startup']['median_s']:.2f} s"),
    ]
    return out


def print_report(r: dict) -> None:
    sim = r["simulation_speed"]
    print("\n== simulation speed (steps/s, as fast as possible; ratio to bare mj_step on the same model, same run)")
    for name, s in sim.items():
        parts = [f"bare {s['bare_steps_per_s']}"]
        for k in s:
            if k.endswith("_steps_per_s") and k != "bare_steps_per_s":
                label = k[: -len("_steps_per_s")]
                q1, q3 = s[label + "_ratio_quartiles"]
                parts.append(f"{label} {s[k]} ({s[label + '_ratio']:.2f}x, quartiles {q1:.2f}-{q3:.2f})")
        print(f"  {name:5s} " + ", ".join(parts) + f"  [{s['pairs']} interleaved pairs of {s['steps_per_run']} steps]")
    rt = r["realtime"]
    print(f"  real-time mode (tank, all controllers): real-time factor {rt['real_time_factor']}, "
          f"step overrun p50 {rt['overrun_ms']['p50']} ms, p99 {rt['overrun_ms']['p99']} ms, max {rt['overrun_ms']['max']} ms")
    print(f"\n== end-to-end latency across processes (ms): step -> applied on the viewer's main thread; bare pair: "
          f"publish -> callback ({r['rounds']} interleaved rounds of {r['seconds_per_run']:g} s each, samples pooled)")
    print(f"  {'run':14s} {'p50':>7s} {'p90':>7s} {'p99':>7s} {'max':>8s}   {'bare p50':>8s} {'bare p99':>8s}  ratio p50/p99")
    for key, run in r["pipeline"].items():
        bare = r["bare"][key]["latency_ms"]
        lat = run["latency_ms"]
        print(f"  {key:14s} {lat['p50']:7.3f} {lat['p90']:7.3f} {lat['p99']:7.3f} {lat['max']:8.3f}   {bare['p50']:8.3f} "
              f"{bare['p99']:8.3f}  {lat['p50'] / bare['p50']:.2f} / {lat['p99'] / bare['p99']:.2f}")
    for key, bare in r.get("bare_events_executor", {}).items():
        lat = bare["latency_ms"]
        print(f"  (not a target: {key} bare pair with its subscriber on the EventsExecutor: p50 {lat['p50']:.3f}, "
              f"p99 {lat['p99']:.3f})")
    for key, run in r.get("pipeline_events_executor", {}).items():
        lat, cpu = run["latency_ms"], run["cpu_cores"]
        print(f"  (not a target: {key} pipeline with RTT_EXECUTOR=events: p50 {lat['p50']:.3f}, "
              f"p99 {lat['p99']:.3f} ({lat['p50'] / r['bare'][key]['latency_ms']['p50']:.2f}x / "
              f"{lat['p99'] / r['bare'][key]['latency_ms']['p99']:.2f}x the bare pair); callback -> applied p50 "
              f"{run['callback_to_applied_ms']['p50']:.3f}; CPU cores sim {cpu['simulation']}, viewer "
              f"{cpu['viewer']}, total {cpu['total']})")
    print("  where it goes (p50 / p99 ms): step -> viewer's callback | callback -> applied on the main thread")
    for key, run in r["pipeline"].items():
        a, b = run["step_to_callback_ms"], run["callback_to_applied_ms"]
        print(f"  {key:14s} {a['p50']:.3f} / {a['p99']:.3f} | {b['p50']:.3f} / {b['p99']:.3f}")
    print("\n== the viewer (meshcat on), per run")
    for key, run in r["pipeline"].items():
        m = run["messages"]
        print(f"  {key:14s} displayed age p50 {run['displayed_age_ms']['p50']:.2f} ms, p99 {run['displayed_age_ms']['p99']:.2f} ms "
              f"(first half {run['displayed_age_p99_ms_first_half']}, second half {run['displayed_age_p99_ms_second_half']}); "
              f"{run['frames_per_s']} frames/s; scene update p50 {run['scene_update_ms']['p50']:.3f} ms, "
              f"p99 {run['scene_update_ms']['p99']:.3f} ms; messages applied {m['applied']}, coalesced {m['coalesced']}, "
              f"max pending {m['max_pending']}; CPU cores sim {run['cpu_cores']['simulation']}, viewer "
              f"{run['cpu_cores']['viewer']}, total {run['cpu_cores']['total']} (bare pair {r['bare'][key]['cpu_cores']})")
    print("\n== meshcat cost per frame (ms): pipelined transforms vs meshcat's round trip per body, same server, interleaved")
    for name, u in r["scene_update"].items():
        print(f"  {name:6s} {u['bodies']} bodies: pipelined p50 {u['pipelined']['p50']:.3f} p99 {u['pipelined']['p99']:.3f}; "
              f"round trip per body p50 {u['round_trip_per_body']['p50']:.3f} p99 {u['round_trip_per_body']['p99']:.3f} "
              f"({u['speedup_p50']}x)")
    print(f"\n== start-up: launch to first state shown: {r['startup']['first_state_s']} s, median {r['startup']['median_s']} s")
    print("\n== targets")
    for name, ok, figure in r["targets"]:
        print(f"  [{'PASS' if ok else 'FAIL'}] {name}: {figure}")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seconds", type=float, default=8.0, help="length of each cross-process run (default 8)")
    p.add_argument("--rounds", type=int, default=3,
                   help="interleaved rounds of bare pair and pipeline per cross-process figure (default 3)")
    p.add_argument("--quick", action="store_true", help="shorter runs, fewer repeats (a smoke test of the suite)")
    p.add_argument("--output", default=str(RESULTS / "latest.json"))
    args = p.parse_args(argv)
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 100)))
    seconds, warmup = (5.0, 1.0) if args.quick else (args.seconds, 2.0)
    rounds = 1 if args.quick else args.rounds

    import rclpy
    from rclpy.signals import SignalHandlerOptions

    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    r: dict = {"machine": {"cpus": os.cpu_count(), "python": platform.python_version(), "platform": platform.platform()},
               "when": time.strftime("%Y-%m-%d %H:%M:%S"), "seconds_per_run": seconds, "rounds": rounds}
    pairs = 8 if args.quick else 60
    rates = {"publisher_50Hz": 50.0, "publisher_every_step": 0.0}
    r["simulation_speed"] = {
        "tank": simulation_speed("project/step2.yaml", rates, pairs, 1000),
        "arm24": simulation_speed("benchmarks/projects/arm_sim.yaml", rates, pairs, 1000),
    }
    r["realtime"] = realtime_mode("project/step2.yaml", 2.0 if args.quick else 5.0)
    rclpy.try_shutdown()
    r["pipeline"], r["bare"] = {}, {}
    for key, sim_p, view_p, rate, joints in (
        ("tank_50Hz", "benchmarks/projects/tank_sim.yaml", "benchmarks/projects/tank_view.yaml", 50.0, 2),
        ("tank_1kHz", "benchmarks/projects/tank_sim.yaml", "benchmarks/projects/tank_view.yaml", 1000.0, 2),
        ("arm24_1kHz", "benchmarks/projects/arm_sim.yaml", "benchmarks/projects/arm_view.yaml", 1000.0, 24),
    ):
        # Interleaved rounds (bare, pipeline, bare, ...), samples pooled: the machine's speed
        # drifts, and this way both sides see the same mix of fast and slow moments.
        bare_runs, pipe_runs, events_runs, pipe_events_runs = [], [], [], []
        for _ in range(rounds):
            bare_runs.append(bare_pair_run(rate, seconds, warmup, joints))
            pipe_runs.append(pipeline_run(sim_p, view_p, rate, seconds, warmup))
            if key == "tank_1kHz":
                # Not targets: the bare pair and the tutorial on the opt-in EventsExecutor.
                events_runs.append(bare_pair_run(rate, seconds, warmup, joints, executor="events"))
                pipe_events_runs.append(pipeline_run(sim_p, view_p, rate, seconds, warmup, executor="events"))
        r["bare"][key] = pool_bare(bare_runs, rate)
        r["pipeline"][key] = pool_pipeline(pipe_runs, rate)
        if events_runs:
            r["bare_events_executor"] = {key: pool_bare(events_runs, rate)}
            r["pipeline_events_executor"] = {key: pool_pipeline(pipe_events_runs, rate)}
    r["scene_update"] = {"tank": scene_update_cost("model/tank.xml", 30 if args.quick else 200),
                         "arm24": scene_update_cost("model/arm24.xml", 30 if args.quick else 200)}
    r["startup"] = startup(1 if args.quick else 3)
    r["targets"] = targets(r)
    print_report(r)
    out = Path(args.output)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(r, indent=1))
    print(f"\nwritten to {out}")
    return 0 if all(ok for _, ok, _ in r["targets"]) else 1


if __name__ == "__main__":
    sys.exit(main())
