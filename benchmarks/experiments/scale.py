"""Scale curves: the Step 1-3 pipeline as the work grows, N tanks in one world and one arm of N joints."""

from __future__ import annotations

from pathlib import Path

from benchmarks.experiments.cross_process import pipeline_run, pool_pipeline
from benchmarks.experiments.speed import simulation_speed
from benchmarks.scale_projects import SCALE_JOINTS, SCALE_RATE, SCALE_TANKS, arm_projects, tanks_projects


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
