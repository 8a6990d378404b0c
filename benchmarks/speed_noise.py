"""How precise is ``make bench``'s simulation-speed figure on this machine?

    python -m benchmarks.speed_noise [--repeats 3] [--seconds 10]

The figure (``benchmarks.experiments.speed.simulation_speed``) is the median ratio of
interleaved pairs: a run of the tank's simulation with its controllers,
divided by the mean of the bare ``mj_step`` runs on either side.  This
prints what limits it:

1. the noise floor: bare runs timed against bare runs in the same way, where
   every ratio would be 1.000 on a steady machine, for runs of about 50 ms
   (``MIN_RUN_S``) and four times longer, each for ``--seconds``;
2. the figure itself, taken ``--repeats`` times back to back with 60 pairs
   and with ``SPEED_PAIRS`` (240), with the bootstrap 95 % interval of each.

About 2.5 minutes.  Not part of ``make bench``.  ROS traffic stays on this
machine (localhost discovery, a ROS_DOMAIN_ID of its own).
"""

from __future__ import annotations

import argparse
import os
import random
import time

import numpy as np

from benchmarks.experiments.speed import (
    SPEED_PAIRS,
    bare_steps_per_s,
    run_steps,
    simulation_speed,
)
from benchmarks.paths import ROOT
from benchmarks.procs import in_thread
from benchmarks.stats import interleaved_ratios

PROJECT = "project/step2.yaml"


def bare_against_bare(model, steps: int, seconds: float) -> list[float]:
    """Ratios of bare runs to the mean of the bare runs on either side, for ``seconds`` s (any thread).

    Paired exactly as the figure pairs its runs (:func:`benchmarks.stats.interleaved_ratios`).
    """

    def bare() -> float:
        return bare_steps_per_s(model, steps)

    deadline = time.monotonic() + seconds
    ratios, _, _ = interleaved_ratios(lambda: in_thread(bare), bare, lambda done: time.monotonic() < deadline)
    return ratios


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeats", type=int, default=3, help="figures per pair count (default 3)")
    p.add_argument("--seconds", type=float, default=10.0, help="time per noise-floor run length (default 10)")
    args = p.parse_args(argv)
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 100)))

    import rclpy
    from rclpy.signals import SignalHandlerOptions

    from tutorial.core.project import load_project
    from tutorial.core.world import build_world

    proj = load_project(ROOT / PROJECT)
    model = build_world(proj.models, time_step=proj.simulator.time_step)
    steps = run_steps(model, 1000)
    print(f"== noise floor: bare against bare, {PROJECT}, {args.seconds:g} s per run length")
    for n in (steps, 4 * steps):
        r = bare_against_bare(model, n, args.seconds)
        q1, med, q3 = np.percentile(r, [25, 50, 75])
        print(
            f"  runs of {n} steps: {len(r)} ratios, median {med:.3f}, quartiles {q1:.3f}-{q3:.3f} "
            f"(width {q3 - q1:.3f})",
            flush=True,
        )

    print(f"== the figure (50 Hz publisher), {args.repeats} times back to back per pair count")
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    try:
        for pairs in (60, SPEED_PAIRS):
            figures = []
            for _ in range(args.repeats):
                s = simulation_speed(PROJECT, {"publisher_50Hz": 50.0}, pairs, 1000)
                lo, hi = s["publisher_50Hz_ratio_ci95"]
                figures.append(s["publisher_50Hz_ratio"])
                print(f"  {pairs} pairs: {s['publisher_50Hz_ratio']:.3f}x (95% CI {lo:.3f}-{hi:.3f})", flush=True)
            print(f"  {pairs} pairs: spread of the {args.repeats} figures {max(figures) - min(figures):.3f}")
    finally:
        rclpy.try_shutdown()
    print("(each CI resamples single pairs: the machine's drift between two figures is not in it)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
