"""Simulation speed: the tutorial's simulation with its controllers against bare ``mj_step``, and in real time."""

from __future__ import annotations

import random
import time
from pathlib import Path

import numpy as np

from benchmarks.paths import ROOT
from benchmarks.procs import in_thread
from benchmarks.stats import interleaved_ratios, median_ci95, pct

MIN_RUN_S = 0.05  # s: the shortest bare run of a simulation-speed pair
# Interleaved pairs behind the targeted simulation-speed figure (the tank).  Here a
# bare run of ~50 ms timed against other bare runs spreads 0.8-0.9x to 1.1-1.17x
# (quartiles), so the median of 60 pairs moved by up to 0.1 from one figure to the
# next, as much as the target's margin; with 240 pairs (about 30 s per rate) three
# figures in a row spread by 0.02 (python -m benchmarks.speed_noise).
SPEED_PAIRS = 240
SPEED_PAIRS_OTHER = 60  # the 24-joint arm's figure: reported, not targeted


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


def simulation_speed(project: str | Path, rates: dict[str, float], pairs: int, steps: int) -> dict:
    """Steps/s of the project's simulation with its controllers (``StepClock`` never) as fast as possible vs
    bare mj_step.

    This machine's CPU speed drifts by tens of percent within seconds, so
    single runs cannot be compared.  The two are measured in short
    interleaved runs of ``steps`` steps (bare, pipeline, bare, ...) on the
    same kind of thread; each pipeline run is divided by the mean of the bare runs on
    either side, and the median of those ratios is reported with its
    quartiles and a bootstrap 95 % confidence interval of the median (the
    scatter among this run's pairs only, see :func:`benchmarks.stats.median_ci95`).  A run
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

            def pipeline() -> float:
                data = mujoco.MjData(model)
                sim = Simulator(
                    model,
                    data,
                    attachments,  # noqa: B023 - pipeline() runs within this iteration
                    node=node,
                    realtime_sync=False,
                    duration=steps * model.opt.timestep,
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
    out["controllers"] = [a.name for a in attachments]
    out["pairs"] = pairs
    out["steps_per_run"] = steps
    return out


def realtime_mode(project: str, seconds: float) -> dict:
    """Real-time factor and step overrun percentiles with every controller on, in real-time mode."""
    from tutorial.app.app import App
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
