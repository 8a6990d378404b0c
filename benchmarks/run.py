"""The benchmark suite: ``make bench`` (or ``python -m benchmarks.run``).

Every figure comes with a baseline measured in the same run, and the ratio,
because absolute times on a shared machine vary:

* simulation speed: the tutorial's simulation with its controllers against
  a bare ``mj_step`` loop on the same model;
* end-to-end latency across processes (simulation step -> state applied on
  the viewer's main thread) against a bare rclpy publisher/subscriber pair
  of the same ``sensor_msgs/JointState`` with the same QoS, in interleaved
  rounds whose samples are pooled; at 1 kHz the same rounds also run the
  bare pair's subscriber and the tutorial on rclpy's ``EventsExecutor``
  (``RTT_EXECUTOR=events``, an opt-in), for comparison;
* the viewer under a 1 kHz flood: age of the displayed state, backlog,
  meshcat cost per frame, frames per second, CPU per process;
* start-up: from the launch command to the first state shown;
* scale curves: N tanks in one world (each with its Step 1 controller and
  Step 2 publisher, driven by one ``rtt-joy --demo``) and one viewer
  mirroring all N, for N = 1, 2, 4, 8; the same for one arm of 6, 12, 24
  and 48 joints (``model/arm<N>.xml``): simulation steps/s against bare
  ``mj_step`` and the real-time factor, the viewer's frames/s and
  scene-update cost, the displayed-state age, CPU per process.

It prints a table of the targets (target, measured, baseline, ratio,
pass/fail), writes ``benchmarks/results/latest.json`` and
``benchmarks/results/targets.md``, and draws the plots
``book/_static/bench_scale.png`` and ``book/_static/bench_latency.png``
(``--quick`` draws them in ``benchmarks/results/`` instead, so a smoke run
never replaces the book's).  ROS traffic stays on this machine (localhost
discovery, a ROS_DOMAIN_ID of its own).
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

from benchmarks.arm_model import JOINT_COUNTS

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "benchmarks" / "results"
BOOK_STATIC = ROOT / "book" / "_static"
FRAME_60HZ_MS = 1000.0 / 60.0
SCALE_TANKS = (1, 2, 4, 8)
SCALE_JOINTS = JOINT_COUNTS  # model/arm<N>.xml
MIN_RUN_S = 0.05  # s: the shortest bare run of a simulation-speed pair
# Interleaved pairs behind the targeted simulation-speed figure (the tank).  Here a
# bare run of ~50 ms timed against other bare runs spreads 0.8-0.9x to 1.1-1.17x
# (quartiles), so the median of 60 pairs moved by up to 0.1 from one figure to the
# next, as much as the target's margin; with 240 pairs (about 30 s per rate) three
# figures in a row spread by 0.02 (python -m benchmarks.speed_noise).
SPEED_PAIRS = 240
SPEED_PAIRS_OTHER = 60  # the 24-joint arm's figures: reported, not targeted
SCALE_RATE = 50.0  # Hz: the Step 2 publisher's default, every body of the scale runs
# Where the tanks of an N-tank world start (x, y in m): in two rows across the 6 m room,
# clear of its crates and pillar and of each other.
TANK_POSITIONS = (
    (-2.1, -0.6),
    (-0.7, 0.6),
    (0.7, -0.6),
    (2.1, 0.6),
    (-2.1, 0.6),
    (-0.7, -0.6),
    (0.7, 0.6),
    (2.1, -0.6),
)


# ---------------------------------------------------------------- helpers
def pct(values, scale=1.0) -> dict:
    """p50/p90/p99/max of ``values`` times ``scale``, rounded (empty: None)."""
    if len(values) == 0:
        return {"n": 0, "p50": None, "p90": None, "p99": None, "max": None}
    a = np.asarray(values, dtype=float) * scale
    return {
        "n": int(a.size),
        "p50": round(float(np.percentile(a, 50)), 3),
        "p90": round(float(np.percentile(a, 90)), 3),
        "p99": round(float(np.percentile(a, 99)), 3),
        "max": round(float(a.max()), 3),
    }


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
        raise RuntimeError(f"{proc.args} did not finish:\n{out}\n{err}") from None
    if proc.returncode != 0:
        raise RuntimeError(f"{proc.args} exited {proc.returncode}:\n{out}\n{err}")
    return out


def py(*args: str) -> list[str]:
    return [sys.executable, "-u", "-m", *args]


def write_yaml(path: Path, project: dict) -> Path:
    import yaml

    path.write_text(yaml.safe_dump(project, sort_keys=False))
    return path


# ---------------------------------------------------------------- the scale runs' project files
STEP_CLOCK = ("StepClock", "benchmarks.probes:StepClock")
STEP1 = ("RttTankController", "tutorial.controllers.tank_controller:RttTankController")
STEP2 = ("RttJointStatePublisher", "tutorial.controllers.joint_state_publisher:RttJointStatePublisher")
SWING = ("SwingController", "tests.fixtures.swing_controller:SwingController")
MONITOR = ("RttJointStateMonitor", "benchmarks.probes:ProbedJointStateSubscriber")
SIMULATOR = {"time_step": 0.001, "realtime_sync": True}


def _controllers(*entries: tuple[str, str]) -> list[dict]:
    return [{"name": name, "class": cls} for name, cls in entries]


def tanks_projects(n: int, directory: Path) -> tuple[Path, Path]:
    """Project files of an N-tank world (the room, tanks ``Tank1``...) and of a viewer of all N.

    Each tank has its Step 1 controller and Step 2 publisher; the first also
    has the step clock, which runs first in every step.
    """
    tank = str(ROOT / "model" / "tank.xml")
    sim_models = [{"name": "Room", "file": str(ROOT / "model" / "room.xml")}]
    view_models = []
    for i, (x, y) in enumerate(TANK_POSITIONS[:n]):
        place = {"name": f"Tank{i + 1}", "file": tank, "position": [x, y, 0.0]}
        sim_models.append({**place, "controllers": _controllers(*([STEP_CLOCK] if i == 0 else []), STEP1, STEP2)})
        view_models.append({**place, "position": list(place["position"]), "controllers": _controllers(MONITOR)})
    sim = write_yaml(
        directory / f"tanks{n}_sim.yaml",
        {"name": f"bench_tanks{n}_sim", "models": sim_models, "simulator": dict(SIMULATOR)},
    )
    view = write_yaml(directory / f"tanks{n}_view.yaml", {"name": f"bench_tanks{n}_view", "models": view_models})
    return sim, view


def arm_projects(joints: int, directory: Path) -> tuple[Path, Path]:
    """Project files of one ``model/arm<joints>.xml`` arm swinging (step clock, sine PD, publisher) and its viewer."""
    arm = {"name": f"Arm{joints}", "file": str(ROOT / "model" / f"arm{joints}.xml")}
    sim = write_yaml(
        directory / f"arm{joints}_sim.yaml",
        {
            "name": f"bench_arm{joints}_sim",
            "models": [{**arm, "controllers": _controllers(STEP_CLOCK, SWING, STEP2)}],
            "simulator": dict(SIMULATOR),
        },
    )
    view = write_yaml(
        directory / f"arm{joints}_view.yaml",
        {"name": f"bench_arm{joints}_view", "models": [{**arm, "controllers": _controllers(MONITOR)}]},
    )
    return sim, view


# ---------------------------------------------------------------- 1. simulation speed
def in_thread(fn):
    """``fn()`` run on a new thread, as the simulation runs on its own; returns its result."""
    import threading

    out = []
    t = threading.Thread(target=lambda: out.append(fn()))
    t.start()
    t.join()
    return out[0]


def bare_steps_per_s(model, steps: int) -> float:
    """Steps/s of a bare ``mj_step`` loop of ``steps`` steps on a fresh ``MjData`` of ``model`` (this thread)."""
    import mujoco

    data = mujoco.MjData(model)
    t0 = time.perf_counter()
    for _ in range(steps):
        mujoco.mj_step(model, data)
    return steps / (time.perf_counter() - t0)


def run_steps(model, steps: int) -> int:
    """``steps``, raised so that a bare run takes at least ``MIN_RUN_S``."""
    fastest = max(in_thread(lambda: bare_steps_per_s(model, steps)) for _ in range(3))
    return max(steps, int(np.ceil(MIN_RUN_S * fastest)))


def interleaved_ratios(run, bare, more) -> tuple[list[float], list[float], list[float]]:
    """Time ``run()`` between bare runs (``bare()`` on a thread of its own) while ``more(pairs so far)``.

    Each ``run()`` (steps/s) is divided by the mean of the bare runs on
    either side; a bare run is shared by the pairs before and after it, so
    a drift of the machine's speed over seconds cancels out.

    Returns:
        (ratios, the run() speeds, the bare speeds: two per pair).
    """
    ratios, speeds, bares = [], [], []
    before = in_thread(bare)
    while more(len(ratios)):
        speed = run()
        after = in_thread(bare)
        ratios.append(speed / ((before + after) / 2))
        speeds.append(speed)
        bares += [before, after]
        before = after
    return ratios, speeds, bares


def median_ci95(values, resamples: int = 2000) -> tuple[float, float]:
    """Bootstrap 95 % confidence interval of the median of ``values`` (a fixed seed: the same data, the same answer).

    It resamples single values, so it covers the scatter among them and
    nothing that moves them all together: the simulation-speed pairs of one
    run share the machine's state of that half minute, and two runs'
    intervals need not overlap (set F's first and third did not).
    """
    x = np.asarray(values, dtype=float)
    rng = np.random.default_rng(0)
    medians = np.median(x[rng.integers(0, x.size, size=(resamples, x.size))], axis=1)
    lo, hi = np.percentile(medians, [2.5, 97.5])
    return float(lo), float(hi)


def simulation_speed(project: str | Path, rates: dict[str, float], pairs: int, steps: int) -> dict:
    """Steps/s of the project's simulation with its controllers (as fast as possible) vs bare mj_step.

    This machine's CPU speed drifts by tens of percent within seconds, so
    single runs cannot be compared.  The two are measured in short
    interleaved runs of ``steps`` steps (bare, pipeline, bare, ...) on the
    same kind of thread; each pipeline run is divided by the mean of the bare runs on
    either side, and the median of those ratios is reported with its
    quartiles and a bootstrap 95 % confidence interval of the median (the
    scatter among this run's pairs only, see :func:`median_ci95`).  A run
    takes at least ``MIN_RUN_S`` of bare stepping (``steps`` grows for a
    small model: a run of a few ms measures the scheduler, not the code).
    No joystick drives the tanks here.  ``python -m benchmarks.speed_noise``
    shows how precise the figure is on the machine at hand.
    """
    import mujoco
    import rclpy

    from tutorial.core.body import Body
    from tutorial.core.controller import ControllerConfig
    from tutorial.core.project import load_project
    from tutorial.core.simulator import Attachment, Simulator
    from tutorial.core.world import build_world

    proj = load_project(ROOT / project)
    model = build_world(proj.models, time_step=proj.simulator.time_step)
    node = rclpy.create_node(f"bench_speed_{random.randrange(10**6)}")

    def bare() -> float:
        return bare_steps_per_s(model, steps)

    steps = run_steps(model, steps)
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
                    config = ControllerConfig(
                        name=c.name, body=Body(model, mujoco.MjData(model), m.name), node=node, parameters=params
                    )
                    assert controller.configure(config)
                    attachments.append(Attachment(c.name, controller, m.name))

            def pipeline(attachments=attachments) -> float:
                data = mujoco.MjData(model)
                sim = Simulator(
                    model, data, attachments, node=node, realtime_sync=False, duration=steps * model.opt.timestep
                ).start()
                sim.join()
                if sim.error:
                    raise RuntimeError(sim.error)
                return sim.steps / sim.wall_time

            ratios, speeds, bares = interleaved_ratios(pipeline, bare, lambda done: done < pairs)
            bare_all += bares
            q1, med, q3 = np.percentile(ratios, [25, 50, 75])
            out[f"{label}_steps_per_s"] = round(float(np.median(speeds)))
            out[f"{label}_ratio"] = round(float(med), 3)
            out[f"{label}_ratio_quartiles"] = [round(float(q1), 3), round(float(q3), 3)]
            out[f"{label}_ratio_ci95"] = [round(float(x), 3) for x in median_ci95(ratios)]
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
    from tutorial.core.app import App
    from tutorial.core.project import load_project

    proj = load_project(ROOT / project)
    for m in proj.models:
        m.controllers = [c for c in m.controllers if c.name != "StepClock"]
    app = App(
        proj,
        node_name=f"bench_rt_{random.randrange(10**6)}",
        headless=True,
        realtime_sync=True,
        duration=seconds,
        output=lambda r: None,
        record_timing=True,
    )
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


def _summary(stdout: str) -> dict:
    """The ``summary`` record of an ``rtt-run --json`` run's output."""
    for line in reversed(stdout.splitlines()):
        if line.startswith("{") and '"summary"' in line:
            record = json.loads(line)
            if record.get("event") == "summary":
                return record
    raise RuntimeError(f"no summary in the simulation's output:\n{stdout[-2000:]}")


def pipeline_run(
    sim_project: str | Path,
    view_project: str | Path,
    rate: float,
    seconds: float,
    warmup: float,
    headless_view: bool = False,
    executor: str | None = None,
    joystick: bool = False,
) -> dict:
    """One run of simulation and viewer as two processes: raw samples, joined on the states' stamps.

    ``executor`` is the spin threads' (``RTT_EXECUTOR``; None: the
    tutorial's default).  ``joystick``: ``rtt-joy --demo`` drives the tanks
    (its CPU is counted as the pipeline's).  The viewer may mirror several
    bodies: their samples are pooled.

    Returns the samples (ns) and the counts, among them ``ages``: at every
    frame, how old each body's shown state was (frame time minus the wall
    time of the step that produced it), and ``first_shown_ages``: the same
    only at the frames that show a body a state newer than the frame before
    (so a state shown in several frames counts once, at its first: at
    50 Hz the publisher's own 20 ms between states is not counted).
    """
    env = {} if executor is None else {"RTT_EXECUTOR": executor}
    with tempfile.TemporaryDirectory() as d:
        sim_probe, view_probe = Path(d) / "sim.json", Path(d) / "view.json"
        view_cmd = py("benchmarks.viewer_proc", str(view_project))
        if headless_view:
            view_cmd.append("--headless")
        procs = {}
        try:
            procs["viewer"] = start(view_cmd + ["--duration", str(seconds + 8.0)], view_probe, env)
            time.sleep(1.0)  # not synchronisation: the viewer starts first so it misses nothing
            sim_cmd = py(
                "tutorial.tools.rtt_run",
                str(sim_project),
                "--headless",
                "--duration",
                str(seconds),
                "--json",
                "--ros-args",
                "-p",
                f"RttJointStatePublisher.rate:={rate}",
            )
            procs["simulation"] = start(sim_cmd, sim_probe, env)
            if joystick:
                procs["joystick"] = start(py("tutorial.tools.rtt_joy", "--demo", "--duration", str(seconds + 6.0)))
            cpu = steady_cpu_cores(procs, seconds, warmup)
            summary = _summary(finish(procs["simulation"], seconds + 30))
            finish(procs["viewer"], seconds + 30)
            if joystick:
                procs["joystick"].send_signal(signal.SIGINT)
                finish(procs["joystick"], 20)
        finally:  # a failed run leaves no process behind
            for proc in procs.values():
                if proc.poll() is None:
                    proc.kill()
                    proc.wait(10)
        s = json.loads(sim_probe.read_text())
        views = [json.loads(f.read_text()) for f in sorted(Path(d).glob("view.*.json"))]
    if not views:
        raise RuntimeError(f"the viewer of {view_project} wrote no probe file")
    step_wall = {round(t / 1000): w for t, w in zip(s["sim_ns"], s["wall_ns"])}
    end_ns = s["wall_ns"][-1]  # the simulation's last step: frames after it show an old state
    out = {
        "latency": [],
        "step_to_callback": [],
        "callback_to_applied": [],
        "ages": [],
        "first_shown_ages": [],
        "frames": 0,
        "frame_span_s": 0.0,
        "scene_update_s": [],
        "messages": {"applied": 0, "posted": 0, "coalesced": 0, "max_pending": 0, "yields": 0, "yield_timeouts": 0},
        "cpu_cores": cpu,
        "real_time_factor": summary.get("real_time_factor"),
        "bodies": len(views),
    }
    starts = []  # each body's measured window starts here (ns)
    for v in views:
        # The measured window: from the first state this body's viewer applied (discovery can
        # take a few seconds) plus the warm-up, to the simulation's last step.
        if not v["applied"]:
            raise RuntimeError(f"the viewer applied no state in the {sim_project} run")
        start_ns = v["applied"][0][2] + int(warmup * 1e9)
        starts.append(start_ns)
        window = [
            (step_wall[round(stamp / 1000)], arrived, applied)
            for stamp, arrived, applied in v["applied"]
            if round(stamp / 1000) in step_wall and start_ns <= applied <= end_ns
        ]
        out["latency"] += [applied - step for step, _, applied in window]
        out["step_to_callback"] += [arrived - step for step, arrived, _ in window]
        out["callback_to_applied"] += [applied - arrived for _, arrived, applied in window]
        frames = [
            (t, stamp, cost)
            for t, stamp, cost in v["frames"]
            if start_ns <= t <= end_ns and round(stamp / 1000) in step_wall
        ]
        out["ages"] += [t - step_wall[round(stamp / 1000)] for t, stamp, _ in frames]
        shown = None
        for t, stamp, _ in frames:
            if stamp != shown:
                out["first_shown_ages"].append(t - step_wall[round(stamp / 1000)])
                shown = stamp
        out["messages"]["applied"] += len(v["applied"])
    # The hand-off queue (MainLoop) and the frames are the viewer's, shared by its bodies:
    # every probe wrote the same counters; the frames are counted from the first body's probe.
    for k in ("posted", "coalesced", "max_pending", "yields", "yield_timeouts"):
        out["messages"][k] = views[0][k]
    frames0 = [(t, c) for t, _, c in views[0]["frames"] if starts[0] <= t <= end_ns]
    out["frames"] = len(frames0)
    out["frame_span_s"] = (frames0[-1][0] - frames0[0][0]) * 1e-9 if len(frames0) > 1 else 0.0
    out["scene_update_s"] = [c for _, c in frames0]
    return out


def pool_pipeline(runs: list[dict], rate: float) -> dict:
    """The pipeline's figures over interleaved runs: samples pooled, CPU averaged, counts summed."""
    ages_first = [a for r in runs for a in r["ages"][: len(r["ages"]) // 2]]
    ages_second = [a for r in runs for a in r["ages"][len(r["ages"]) // 2 :]]
    span = sum(r["frame_span_s"] for r in runs)
    cpu = {k: round(statistics.mean(r["cpu_cores"][k] for r in runs), 3) for k in runs[0]["cpu_cores"]}
    rtf = [r["real_time_factor"] for r in runs if r.get("real_time_factor") is not None]
    return {
        "rate_hz": rate,
        "runs": len(runs),
        "bodies": runs[0].get("bodies", 1),
        "latency_ms": pct([x for r in runs for x in r["latency"]], 1e-6),
        "step_to_callback_ms": pct([x for r in runs for x in r["step_to_callback"]], 1e-6),
        "callback_to_applied_ms": pct([x for r in runs for x in r["callback_to_applied"]], 1e-6),
        "displayed_age_ms": pct(ages_first + ages_second, 1e-6),
        "displayed_age_p99_ms_first_half": pct(ages_first, 1e-6)["p99"],
        "displayed_age_p99_ms_second_half": pct(ages_second, 1e-6)["p99"],
        "first_shown_age_ms": pct([a for r in runs for a in r["first_shown_ages"]], 1e-6),
        "frames_per_s": round(sum(r["frames"] for r in runs) / span, 1) if span > 0 else 0.0,
        "scene_update_ms": pct([c for r in runs for c in r["scene_update_s"]], 1000.0),
        "messages": {
            "applied": sum(r["messages"]["applied"] for r in runs),
            "posted": sum(r["messages"]["posted"] for r in runs),
            "coalesced": sum(r["messages"]["coalesced"] for r in runs),
            "max_pending": max(r["messages"]["max_pending"] for r in runs),
            "yields": sum(r["messages"]["yields"] for r in runs),
            "yield_timeouts": sum(r["messages"]["yield_timeouts"] for r in runs),
        },
        "cpu_cores": {**cpu, "total": round(sum(cpu.values()), 3)},
        "real_time_factor": round(min(rtf), 4) if rtf else None,
        "real_time_factors": [round(x, 4) for x in rtf],
        "latency_samples_ms": sorted(round(x * 1e-6, 4) for r in runs for x in r["latency"]),
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
        pub = start(
            py("benchmarks.bare_pair", "pub", "--rate", str(rate), "--duration", str(seconds), "--joints", str(joints))
        )
        cpu = sum(steady_cpu_cores({"pub": pub, "sub": sub}, seconds, warmup).values())
        finish(pub, seconds + 30)
        finish(sub, seconds + 30)
        received = json.loads(probe.read_text())["received"]
    first = received[0][1] if received else 0
    return {
        "latency": [r - s for s, r in received if r >= first + int(warmup * 1e9)],
        "received": len(received),
        "cpu_cores": cpu,
    }


def pool_bare(runs: list[dict], rate: float) -> dict:
    latency = [x for r in runs for x in r["latency"]]
    return {
        "rate_hz": rate,
        "runs": len(runs),
        "latency_ms": pct(latency, 1e-6),
        "received": sum(r["received"] for r in runs),
        "cpu_cores": round(statistics.mean(r["cpu_cores"] for r in runs), 3),
        "latency_samples_ms": sorted(round(x * 1e-6, 4) for x in latency),
    }


# ---------------------------------------------------------------- 3b. meshcat cost per frame
def scene_update_cost(model_file: str, frames: int) -> dict:
    """ms per frame to move every body of a model in meshcat: pipelined (the library) vs a round trip per body.

    The baseline is meshcat-python's own ``set_transform``, which waits for
    the server's reply after each command; both run against one server, interleaved.
    """
    import mujoco

    from tutorial.core.world import ModelEntry, build_world
    from tutorial.view.meshcat_server import start_server
    from tutorial.view.scene import Scene

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
    out["transforms"] = len(scene.moving_bodies)  # per frame, all moving (a tank: chassis, turret, barrel)
    out["speedup_p50"] = round(out["round_trip_per_body"]["p50"] / out["pipelined"]["p50"], 2)
    return out


# ---------------------------------------------------------------- 4. start-up
def startup(repeats: int) -> dict:
    """Seconds from starting ``launch_py/step3_launch.py --demo`` to the viewer's first applied state."""
    times = []
    for _ in range(repeats):
        t0 = time.monotonic()
        proc = subprocess.Popen(
            [sys.executable, "-u", str(ROOT / "launch_py" / "step3_launch.py"), "--demo"],
            cwd=ROOT,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
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


# ---------------------------------------------------------------- 5. scale curves
def scale_curves(seconds: float, warmup: float, rounds: int, pairs: int, directory: Path) -> dict:
    """The Step 1-3 pipeline as the work grows: N tanks, and one arm of N joints.

    For each size: simulation speed against bare ``mj_step`` (as fast as
    possible, interleaved pairs), then ``rounds`` cross-process runs in
    real time (the sizes in turn, so a slow minute of the machine spreads
    over all of them), pooled.
    """
    import rclpy
    from rclpy.signals import SignalHandlerOptions

    configs = {}
    for n in SCALE_TANKS:
        configs[("tanks", n)] = (*tanks_projects(n, directory), True)
    for n in SCALE_JOINTS:
        configs[("joints", n)] = (*arm_projects(n, directory), False)
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    try:
        speeds = {
            key: simulation_speed(sim, {"publisher_50Hz": SCALE_RATE}, pairs, 1000)
            for key, (sim, _, _) in configs.items()
        }
    finally:
        rclpy.try_shutdown()
    runs: dict = {key: [] for key in configs}
    for i in range(rounds):
        order = list(configs) if i % 2 == 0 else list(reversed(configs))
        for key in order:
            sim, view, joystick = configs[key]
            runs[key].append(pipeline_run(sim, view, SCALE_RATE, seconds, warmup, joystick=joystick))
    out: dict = {"tanks": {}, "joints": {}, "rate_hz": SCALE_RATE, "rounds": rounds, "seconds_per_run": seconds}
    for (kind, n), rs in runs.items():
        pooled = pool_pipeline(rs, SCALE_RATE)
        pooled.pop("latency_samples_ms")
        out[kind][str(n)] = {"simulation_speed": speeds[(kind, n)], **pooled}
    return out


# ---------------------------------------------------------------- report
def targets(r: dict) -> list[dict]:
    """Each target: its text, the measured figure, the same-run baseline, their ratio and pass/fail."""
    tank1k, bare1k = r["pipeline"]["tank_1kHz"], r["bare"]["tank_1kHz"]
    sim = r["simulation_speed"]["tank"]
    lat, blat = tank1k["latency_ms"], bare1k["latency_ms"]
    out = [
        {
            "target": "simulation with the 50 Hz publisher >= 0.8x bare mj_step (steps/s)",
            "measured": f"{sim['publisher_50Hz_steps_per_s']:,} steps/s",
            "baseline": f"{sim['bare_steps_per_s']:,} steps/s",
            "ratio": f"{sim['publisher_50Hz_ratio']:.3f}x",
            "pass": sim["publisher_50Hz_ratio"] >= 0.8,
        },
        {
            "target": "end-to-end p50 <= 1.5x the bare rclpy pair at 1 kHz",
            "measured": f"{lat['p50']:.3f} ms",
            "baseline": f"{blat['p50']:.3f} ms",
            "ratio": f"{lat['p50'] / blat['p50']:.2f}x",
            "pass": lat["p50"] <= 1.5 * blat["p50"],
        },
        {
            "target": "end-to-end p99 <= 2x the bare rclpy pair at 1 kHz",
            "measured": f"{lat['p99']:.3f} ms",
            "baseline": f"{blat['p99']:.3f} ms",
            "ratio": f"{lat['p99'] / blat['p99']:.2f}x",
            "pass": lat["p99"] <= 2 * blat["p99"],
        },
        {
            "target": "displayed-state age p99 at 1 kHz <= 16.7 ms + the bare pair's p99",
            "measured": f"{tank1k['displayed_age_ms']['p99']:.2f} ms",
            "baseline": f"{FRAME_60HZ_MS:.1f} + {blat['p99']:.2f} ms",
            "ratio": f"{tank1k['displayed_age_ms']['p99'] / (FRAME_60HZ_MS + blat['p99']):.2f}x",
            "pass": tank1k["displayed_age_ms"]["p99"] <= FRAME_60HZ_MS + blat["p99"],
        },
        {
            "target": "Step 3 pipeline at 1 kHz <= 1 CPU core",
            "measured": f"{tank1k['cpu_cores']['total']:.2f} cores",
            "baseline": f"bare pair {bare1k['cpu_cores']:.2f} cores",
            "ratio": f"{tank1k['cpu_cores']['total'] / bare1k['cpu_cores']:.2f}x",
            "pass": tank1k["cpu_cores"]["total"] <= 1.0,
        },
        {
            "target": "first state shown <= 3 s after launch",
            "measured": f"{r['startup']['median_s']:.2f} s",
            "baseline": "",
            "ratio": "",
            "pass": r["startup"]["median_s"] <= 3.0,
        },
    ]
    scale = r.get("scale")
    if scale:
        eight = scale["tanks"][str(max(SCALE_TANKS))]
        bare50 = r["bare"]["tank_50Hz"]["latency_ms"]
        age = eight["first_shown_age_ms"]["p99"]
        rtf = eight["real_time_factor"]
        out += [
            {
                "target": "8 tanks simulate in real time (real-time factor >= 0.99, the lowest run)",
                "measured": "n/a" if rtf is None else f"{rtf:.3f}",
                "baseline": "1.000 (wall clock)",
                "ratio": "" if rtf is None else f"{rtf:.3f}x",
                "pass": rtf is not None and rtf >= 0.99,
            },
            {
                "target": "the viewer mirrors all 8 at >= 50 frames/s",
                "measured": f"{eight['frames_per_s']:.1f} frames/s",
                "baseline": f"{SCALE_RATE:.0f} states/s per tank (cap 60)",
                "ratio": f"{eight['frames_per_s'] / SCALE_RATE:.2f}x",
                "pass": eight["frames_per_s"] >= 50.0,
            },
            {
                "target": "8 tanks: displayed-state age p99 <= 16.7 ms + the bare pair's p99 (50 Hz)",
                "measured": f"{age:.2f} ms",
                "baseline": f"{FRAME_60HZ_MS:.1f} + {bare50['p99']:.2f} ms",
                "ratio": f"{age / (FRAME_60HZ_MS + bare50['p99']):.2f}x",
                "pass": age <= FRAME_60HZ_MS + bare50["p99"],
            },
            {
                "target": "8 tanks: the whole pipeline <= 1.5 CPU cores",
                "measured": f"{eight['cpu_cores']['total']:.2f} cores",
                "baseline": "",
                "ratio": "",
                "pass": eight["cpu_cores"]["total"] <= 1.5,
            },
        ]
    return out


def targets_markdown(r: dict) -> str:
    """The targets as a Markdown table (the book's first table)."""
    lines = ["| target | measured | baseline, same run | ratio | |", "|---|---|---|---|---|"]
    for t in r["targets"]:
        lines.append(
            f"| {t['target']} | {t['measured']} | {t['baseline']} | {t['ratio']} | "
            f"{'pass' if t['pass'] else '**FAIL**'} |"
        )
    return "\n".join(lines) + "\n"


def runs_table(paths: list[str]) -> str:
    """The targets of several saved runs (``latest.json`` files) as one Markdown table.

    The measured figure, baseline and ratio are the last run's; the last
    column gives every run's ratio (or figure) and verdict, in order.
    """
    runs = [json.loads(Path(p).read_text()) for p in paths]
    last = runs[-1]
    lines = [
        f"| target | measured | baseline, same run | ratio | runs {', '.join(str(i + 1) for i in range(len(runs)))} |",
        "|---|---|---|---|---|",
    ]
    for i, t in enumerate(last["targets"]):
        each = []
        for r in runs:
            u = r["targets"][i]
            each.append(f"{u['ratio'] or u['measured']} {'pass' if u['pass'] else '**FAIL**'}")
        lines.append(f"| {t['target']} | {t['measured']} | {t['baseline']} | {t['ratio']} | {'; '.join(each)} |")
    return "\n".join(lines) + "\n"


def print_report(r: dict) -> None:
    sim = r["simulation_speed"]
    print("\n== simulation speed (steps/s, as fast as possible; ratio to bare mj_step on the same model, same run)")
    for name, s in sim.items():
        parts = [f"bare {s['bare_steps_per_s']}"]
        for k in s:
            if k.endswith("_steps_per_s") and k != "bare_steps_per_s":
                label = k[: -len("_steps_per_s")]
                q1, q3 = s[label + "_ratio_quartiles"]
                lo, hi = s.get(label + "_ratio_ci95", (float("nan"),) * 2)
                parts.append(
                    f"{label} {s[k]} ({s[label + '_ratio']:.3f}x, 95% CI {lo:.3f}-{hi:.3f}, "
                    f"quartiles {q1:.2f}-{q3:.2f})"
                )
        print(f"  {name:5s} " + ", ".join(parts) + f"  [{s['pairs']} interleaved pairs of {s['steps_per_run']} steps]")
    rt = r["realtime"]
    print(
        f"  real-time mode (tank, all controllers): real-time factor {rt['real_time_factor']}, "
        f"step overrun p50 {rt['overrun_ms']['p50']} ms, p99 {rt['overrun_ms']['p99']} ms, "
        f"max {rt['overrun_ms']['max']} ms"
    )
    print(
        f"\n== end-to-end latency across processes (ms): step -> applied on the viewer's main thread; bare pair: "
        f"publish -> callback ({r['rounds']} interleaved rounds of {r['seconds_per_run']:g} s each, samples pooled)"
    )
    print(
        f"  {'run':14s} {'p50':>7s} {'p90':>7s} {'p99':>7s} {'max':>8s}   "
        f"{'bare p50':>8s} {'bare p99':>8s}  ratio p50/p99"
    )
    for key, run in r["pipeline"].items():
        bare = r["bare"][key]["latency_ms"]
        lat = run["latency_ms"]
        print(
            f"  {key:14s} {lat['p50']:7.3f} {lat['p90']:7.3f} {lat['p99']:7.3f} {lat['max']:8.3f}   {bare['p50']:8.3f} "
            f"{bare['p99']:8.3f}  {lat['p50'] / bare['p50']:.2f} / {lat['p99'] / bare['p99']:.2f}"
        )
    for key, bare in r.get("bare_events_executor", {}).items():
        lat = bare["latency_ms"]
        print(
            f"  (not a target: {key} bare pair with its subscriber on the EventsExecutor: p50 {lat['p50']:.3f}, "
            f"p99 {lat['p99']:.3f}; the tutorial's p50/p99 are "
            f"{r['pipeline'][key]['latency_ms']['p50'] / lat['p50']:.2f}x"
            f" / {r['pipeline'][key]['latency_ms']['p99'] / lat['p99']:.2f}x these)"
        )
    for key, run in r.get("pipeline_events_executor", {}).items():
        lat, cpu = run["latency_ms"], run["cpu_cores"]
        print(
            f"  (not a target: {key} pipeline with RTT_EXECUTOR=events: p50 {lat['p50']:.3f}, "
            f"p99 {lat['p99']:.3f} ({lat['p50'] / r['bare'][key]['latency_ms']['p50']:.2f}x / "
            f"{lat['p99'] / r['bare'][key]['latency_ms']['p99']:.2f}x the bare pair); callback -> applied p50 "
            f"{run['callback_to_applied_ms']['p50']:.3f}; CPU cores sim {cpu['simulation']}, viewer "
            f"{cpu['viewer']}, total {cpu['total']})"
        )
    print("  where it goes (p50 / p99 ms): step -> viewer's callback | callback -> applied on the main thread")
    for key, run in r["pipeline"].items():
        a, b = run["step_to_callback_ms"], run["callback_to_applied_ms"]
        print(f"  {key:14s} {a['p50']:.3f} / {a['p99']:.3f} | {b['p50']:.3f} / {b['p99']:.3f}")
    print("\n== the viewer (meshcat on), per run")
    for key, run in r["pipeline"].items():
        m = run["messages"]
        print(
            f"  {key:14s} displayed age p50 {run['displayed_age_ms']['p50']:.2f} ms, "
            f"p99 {run['displayed_age_ms']['p99']:.2f} ms "
            f"(first half {run['displayed_age_p99_ms_first_half']}, "
            f"second half {run['displayed_age_p99_ms_second_half']}); "
            f"{run['frames_per_s']} frames/s; scene update p50 {run['scene_update_ms']['p50']:.3f} ms, "
            f"p99 {run['scene_update_ms']['p99']:.3f} ms; messages applied {m['applied']}, coalesced {m['coalesced']}, "
            f"max pending {m['max_pending']}, spin thread stepped aside {m['yields']} times "
            f"({m['yield_timeouts']} gave up); CPU cores sim {run['cpu_cores']['simulation']}, viewer "
            f"{run['cpu_cores']['viewer']}, total {run['cpu_cores']['total']} (bare pair {r['bare'][key]['cpu_cores']})"
        )
    print(
        "\n== meshcat cost per frame (ms): pipelined transforms vs meshcat's round trip per body, "
        "same server, interleaved"
    )
    for name, u in r["scene_update"].items():
        print(
            f"  {name:6s} {u['transforms']} transforms: pipelined p50 {u['pipelined']['p50']:.3f} "
            f"p99 {u['pipelined']['p99']:.3f}; "
            f"round trip per body p50 {u['round_trip_per_body']['p50']:.3f} p99 {u['round_trip_per_body']['p99']:.3f} "
            f"({u['speedup_p50']}x)"
        )
    print(
        f"\n== start-up: launch to first state shown: {r['startup']['first_state_s']} s, "
        f"median {r['startup']['median_s']} s"
    )
    scale = r.get("scale")
    if scale:
        print(
            f"\n== scale ({scale['rate_hz']:g} Hz publishers, {scale['rounds']} rounds of "
            f"{scale['seconds_per_run']:g} s, "
            "pooled): simulation speed vs bare mj_step (as fast as possible) and real-time factor (lowest run); "
            "the viewer; displayed-state age at first display p99; CPU cores"
        )
        for kind, label in (("tanks", "tanks"), ("joints", "joints")):
            for n, s in scale[kind].items():
                sp, cpu = s["simulation_speed"], s["cpu_cores"]
                parts = ", ".join(f"{k} {v:.2f}" for k, v in cpu.items())
                print(
                    f"  {n:>2s} {label:6s}: {sp['publisher_50Hz_ratio']:.3f}x bare "
                    f"({sp['publisher_50Hz_steps_per_s']:,}"
                    f" vs {sp['bare_steps_per_s']:,} steps/s), RTF {s['real_time_factor']}; "
                    f"{s['frames_per_s']} frames/s,"
                    f" scene update p50 {s['scene_update_ms']['p50']:.2f} p99 {s['scene_update_ms']['p99']:.2f} ms; "
                    f"age p99 {s['first_shown_age_ms']['p99']:.2f} ms "
                    f"(every frame: {s['displayed_age_ms']['p99']:.2f});"
                    f" CPU {parts}"
                )
    print("\n== targets")
    for t in r["targets"]:
        figure = (
            t["measured"]
            + (f" vs {t['baseline']}" if t["baseline"] else "")
            + (f" ({t['ratio']})" if t["ratio"] else "")
        )
        print(f"  [{'PASS' if t['pass'] else 'FAIL'}] {t['target']}: {figure}")


# ---------------------------------------------------------------- plots
def plot_scale(r: dict, path: Path) -> Path:
    """The scale curves, one column per kind of growth (tanks, joints), a row per figure, as a PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scale = r["scale"]
    bare50 = r["bare"]["tank_50Hz"]["latency_ms"]["p99"]
    fig, axes = plt.subplots(5, 2, figsize=(10, 15), constrained_layout=True)  # legible at book width
    columns = (
        ("tanks", "tanks in one world (each: Step 1 controller, Step 2 publisher)", SCALE_TANKS),
        ("joints", "joints of one arm", SCALE_JOINTS),
    )
    for col, (kind, xlabel, sizes) in enumerate(columns):
        data = [scale[kind][str(n)] for n in sizes]
        ax = axes[0, col]
        ax.plot(
            sizes,
            [d["simulation_speed"]["publisher_50Hz_ratio"] for d in data],
            "o-",
            label="steps/s / bare mj_step's (as fast as possible)",
        )
        ax.plot(sizes, [d["real_time_factor"] for d in data], "s-", label="real-time factor (lowest run)")
        ax.axhline(0.99 if kind == "tanks" else 1.0, color="grey", ls=":", lw=1)
        ax.set_ylim(0, 1.1)
        ax.set_title("simulation")
        ax.legend(fontsize=7, loc="lower left")
        ax = axes[1, col]
        ax.plot(sizes, [d["frames_per_s"] for d in data], "o-")
        ax.axhline(50, color="grey", ls=":", lw=1)
        ax.set_ylim(0, 65)
        ax.set_title("viewer: frames/s")
        ax = axes[2, col]
        ax.plot(sizes, [d["scene_update_ms"]["p50"] for d in data], "o-", label="p50")
        ax.plot(sizes, [d["scene_update_ms"]["p99"] for d in data], "s--", label="p99")
        ax.set_ylim(bottom=0)
        ax.set_title("viewer: scene update, ms per frame")
        ax.legend(fontsize=7)
        ax = axes[3, col]
        ax.plot(sizes, [d["first_shown_age_ms"]["p50"] for d in data], "o-", label="p50")
        ax.plot(sizes, [d["first_shown_age_ms"]["p99"] for d in data], "s--", label="p99")
        ax.axhline(FRAME_60HZ_MS + bare50, color="grey", ls=":", lw=1, label="16.7 ms + bare pair p99")
        ax.set_ylim(bottom=0)
        ax.set_title("displayed-state age, ms")
        ax.legend(fontsize=7)
        ax = axes[4, col]
        for proc in data[0]["cpu_cores"]:
            ax.plot(sizes, [d["cpu_cores"][proc] for d in data], "o-" if proc == "total" else ".--", label=proc)
        if kind == "tanks":
            ax.axhline(1.5, color="grey", ls=":", lw=1)
        ax.set_ylim(bottom=0)
        ax.set_title("CPU cores per process")
        ax.legend(fontsize=7)
        for ax in axes[:, col]:
            ax.set_title(f"{kind}: {ax.get_title()}")
            ax.set_xscale("log", base=2)
            ax.set_xticks(sizes, [str(n) for n in sizes])
            ax.set_xlabel(xlabel)
            ax.grid(alpha=0.3)
    fig.suptitle(
        f"Scale: {SCALE_RATE:g} Hz publishers, one viewer mirroring every body "
        f"(make bench, {r['when']}; dotted lines: targets)",
        fontsize=11,
    )
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return path


def plot_latency(r: dict, path: Path) -> Path:
    """End-to-end latency at 1 kHz as distributions: the tutorial (both executors) and the bare pair."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    series = [
        ("bare rclpy pair (baseline)", r["bare"]["tank_1kHz"]),
        ("bare pair, subscriber on the EventsExecutor", r.get("bare_events_executor", {}).get("tank_1kHz")),
        ("tutorial (default: SingleThreadedExecutor)", r["pipeline"]["tank_1kHz"]),
        ("tutorial, RTT_EXECUTOR=events", r.get("pipeline_events_executor", {}).get("tank_1kHz")),
    ]
    fig, ax = plt.subplots(figsize=(8, 4.2), constrained_layout=True)
    for label, s in series:
        if not s:
            continue
        x = np.asarray(s["latency_samples_ms"])
        y = 1.0 - np.arange(x.size) / x.size
        ax.plot(x, y, label=f"{label}: p50 {s['latency_ms']['p50']:.3f}, p99 {s['latency_ms']['p99']:.2f} ms")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_ylim(1e-4, 1.05)
    ax.set_xlabel("end-to-end latency at 1 kHz, ms (tutorial: step -> applied on the viewer's main thread)")
    ax.set_ylabel("fraction of states slower")
    ax.axhline(0.5, color="grey", ls=":", lw=1)
    ax.axhline(0.01, color="grey", ls=":", lw=1)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    ax.set_title(f"1 kHz hand-off, {r['rounds']} interleaved rounds pooled (make bench, {r['when']})", fontsize=10)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return path


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seconds", type=float, default=8.0, help="length of each cross-process run (default 8)")
    p.add_argument(
        "--rounds",
        type=int,
        default=3,
        help="interleaved rounds of bare pair and pipeline per cross-process figure (default 3)",
    )
    p.add_argument("--scale-rounds", type=int, default=2, help="cross-process runs per scale point (default 2)")
    p.add_argument("--quick", action="store_true", help="shorter runs, fewer repeats (a smoke test of the suite)")
    p.add_argument("--output", default=str(RESULTS / "latest.json"))
    p.add_argument(
        "--table",
        nargs="+",
        metavar="RUN_JSON",
        help="print the targets of these saved runs as one Markdown table, and exit",
    )
    p.add_argument(
        "--plots",
        default=None,
        help=f"directory for the plots (default {BOOK_STATIC.relative_to(ROOT)}; "
        f"with --quick {RESULTS.relative_to(ROOT)})",
    )
    args = p.parse_args(argv)
    if args.table:
        print(runs_table(args.table), end="")
        return 0
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 100)))
    seconds, warmup = (5.0, 1.0) if args.quick else (args.seconds, 2.0)
    rounds = 1 if args.quick else args.rounds
    plots = Path(args.plots) if args.plots else (RESULTS if args.quick else BOOK_STATIC)

    import rclpy
    from rclpy.signals import SignalHandlerOptions

    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    r: dict = {
        "machine": {"cpus": os.cpu_count(), "python": platform.python_version(), "platform": platform.platform()},
        "when": time.strftime("%Y-%m-%d %H:%M"),
        "seconds_per_run": seconds,
        "rounds": rounds,
        "load_average_at_start": [round(x, 2) for x in os.getloadavg()],
    }
    pairs, other_pairs = (8, 8) if args.quick else (SPEED_PAIRS, SPEED_PAIRS_OTHER)
    rates = {"publisher_50Hz": 50.0, "publisher_every_step": 0.0}
    r["simulation_speed"] = {
        "tank": simulation_speed("project/step2.yaml", rates, pairs, 1000),
        "arm24": simulation_speed("benchmarks/projects/arm_sim.yaml", rates, other_pairs, 1000),
    }
    r["realtime"] = realtime_mode("project/step2.yaml", 2.0 if args.quick else 5.0)
    rclpy.try_shutdown()
    r["pipeline"], r["bare"] = {}, {}
    r["bare_events_executor"], r["pipeline_events_executor"] = {}, {}
    for key, sim_p, view_p, rate, joints in (
        ("tank_50Hz", "benchmarks/projects/tank_sim.yaml", "benchmarks/projects/tank_view.yaml", 50.0, 2),
        ("tank_1kHz", "benchmarks/projects/tank_sim.yaml", "benchmarks/projects/tank_view.yaml", 1000.0, 2),
    ):
        # Interleaved rounds (bare, pipeline, bare, ...), samples pooled: the machine's speed
        # drifts, and this way both sides see the same mix of fast and slow moments.
        bare_runs, pipe_runs, events_runs, pipe_events_runs = [], [], [], []
        for _ in range(rounds):
            bare_runs.append(bare_pair_run(rate, seconds, warmup, joints))
            pipe_runs.append(pipeline_run(sim_p, view_p, rate, seconds, warmup))
            if key == "tank_1kHz":
                # Not targets: the bare pair and the tutorial, on the EventsExecutor (opt-in).
                events_runs.append(bare_pair_run(rate, seconds, warmup, joints, executor="events"))
                pipe_events_runs.append(pipeline_run(sim_p, view_p, rate, seconds, warmup, executor="events"))
        r["bare"][key] = pool_bare(bare_runs, rate)
        r["pipeline"][key] = pool_pipeline(pipe_runs, rate)
        if events_runs:
            r["bare_events_executor"][key] = pool_bare(events_runs, rate)
            r["pipeline_events_executor"][key] = pool_pipeline(pipe_events_runs, rate)
    r["scene_update"] = {
        "tank": scene_update_cost("model/tank.xml", 30 if args.quick else 200),
        "arm24": scene_update_cost("model/arm24.xml", 30 if args.quick else 200),
    }
    r["startup"] = startup(1 if args.quick else 3)
    with tempfile.TemporaryDirectory() as d:
        r["scale"] = scale_curves(
            seconds, warmup, 1 if args.quick else args.scale_rounds, 8 if args.quick else 20, Path(d)
        )
    r["load_average_at_end"] = [round(x, 2) for x in os.getloadavg()]
    r["targets"] = targets(r)
    print_report(r)
    r["plots"] = [str(plot_scale(r, plots / "bench_scale.png")), str(plot_latency(r, plots / "bench_latency.png"))]
    out = Path(args.output)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(r, indent=1))
    (out.parent / "targets.md").write_text(targets_markdown(r))
    print(f"\nwritten to {out}, {out.parent / 'targets.md'}; plots: {', '.join(r['plots'])}")
    return 0 if all(t["pass"] for t in r["targets"]) else 1


if __name__ == "__main__":
    sys.exit(main())
