"""Across processes: the tutorial's simulation and viewer as two processes, and the bare rclpy pair as the baseline.

A run returns raw samples; the pooling functions turn the interleaved runs
of one figure into its percentiles, counts and CPU.
"""

from __future__ import annotations

import json
import signal
import statistics
import tempfile
import time
from pathlib import Path

from benchmarks.procs import finish, py, start, steady_cpu_cores
from benchmarks.stats import pct

# The cross-process figures: (key, simulation project, viewer project, publish rate in Hz, joints per message).
LATENCY_RUNS = (
    ("tank_50Hz", "benchmarks/projects/tank_sim.yaml", "benchmarks/projects/tank_view.yaml", 50.0, 2),
    ("tank_1kHz", "benchmarks/projects/tank_sim.yaml", "benchmarks/projects/tank_view.yaml", 1000.0, 2),
)
EVENTS_KEY = "tank_1kHz"  # the figure whose rounds also run both sides on the EventsExecutor (not targets)


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
        "round_p50_ms": _round_p50s(runs),
    }


def _round_p50s(runs: list[dict]) -> list[float | None]:
    """Each run's own latency p50, ms, in the order run (the spread from round to round)."""
    return [round(statistics.median(r["latency"]) * 1e-6, 4) if r["latency"] else None for r in runs]


def bare_pair_run(
    rate: float, seconds: float, warmup: float, joints: int, executor: str = "single", hand_off: bool = False
) -> dict:
    """One run of the bare rclpy pair at the same rate, same message and QoS: raw samples.

    ``executor`` is the subscriber's: ``single`` (rclpy's default, the
    baseline) or ``events`` (the EventsExecutor, for comparison).
    ``hand_off``: the subscriber notes each arrival on its main thread after
    the tutorial's hand-off (``benchmarks.bare_pair --hand-off``), not a baseline.
    """
    with tempfile.TemporaryDirectory() as d:
        probe = Path(d) / "bare.json"
        sub_cmd = py("benchmarks.bare_pair", "sub", "--duration", str(seconds + 8.0), "--executor", executor)
        if hand_off:
            sub_cmd.append("--hand-off")
        sub = start(sub_cmd, probe)
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
    """The bare pair's figures over interleaved runs: latency samples pooled (ms), CPU cores averaged."""
    latency = [x for r in runs for x in r["latency"]]
    return {
        "rate_hz": rate,
        "runs": len(runs),
        "latency_ms": pct(latency, 1e-6),
        "received": sum(r["received"] for r in runs),
        "cpu_cores": round(statistics.mean(r["cpu_cores"] for r in runs), 3),
        "latency_samples_ms": sorted(round(x * 1e-6, 4) for x in latency),
        "round_p50_ms": _round_p50s(runs),
    }


def latency_rounds(rounds: int, seconds: float, warmup: float) -> dict:
    """Each of :data:`LATENCY_RUNS` in ``rounds`` interleaved rounds of ``seconds`` s, bare pair and pipeline.

    Interleaved rounds (bare, pipeline, bare, ...), samples pooled: the
    machine's speed drifts, and this way both sides see the same mix of fast
    and slow moments.  At :data:`EVENTS_KEY` each round also runs the bare
    pair and the tutorial on the EventsExecutor (opt-in; not targets).

    Returns:
        ``{"pipeline": ..., "bare": ..., "bare_events_executor": ..., "pipeline_events_executor": ...}``, each
        keyed by the run's key (:func:`pool_pipeline`, :func:`pool_bare`).
    """
    out: dict = {"pipeline": {}, "bare": {}, "bare_events_executor": {}, "pipeline_events_executor": {}}
    for key, sim_p, view_p, rate, joints in LATENCY_RUNS:
        bare_runs, pipe_runs, events_runs, pipe_events_runs = [], [], [], []
        for _ in range(rounds):
            bare_runs.append(bare_pair_run(rate, seconds, warmup, joints))
            pipe_runs.append(pipeline_run(sim_p, view_p, rate, seconds, warmup))
            if key == EVENTS_KEY:
                events_runs.append(bare_pair_run(rate, seconds, warmup, joints, executor="events"))
                pipe_events_runs.append(pipeline_run(sim_p, view_p, rate, seconds, warmup, executor="events"))
        out["bare"][key] = pool_bare(bare_runs, rate)
        out["pipeline"][key] = pool_pipeline(pipe_runs, rate)
        if events_runs:
            out["bare_events_executor"][key] = pool_bare(events_runs, rate)
            out["pipeline_events_executor"][key] = pool_pipeline(pipe_events_runs, rate)
    return out


VARIANTS = ("bare", "bare_hand_off", "pipeline", "pipeline_headless")


def main(argv=None) -> int:
    """An A/B at 1 kHz, not part of ``make bench``: the variants alternate, round after round.

    ``bare`` is the targets' baseline, ``bare_hand_off`` the same pair with
    the tutorial's hop to the main thread, ``pipeline`` the simulation and
    the Step 3 viewer (``pipeline_headless``: its view not drawn).  Prints
    each round's latency p50 and p99 and, at the end, the pooled figures.
    Run it alone on the machine.
    """
    import argparse
    import os

    from tutorial.ros import env as ros_env

    p = argparse.ArgumentParser(description=main.__doc__.splitlines()[0])
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--seconds", type=float, default=8.0)
    p.add_argument("--variants", default="bare,bare_hand_off,pipeline", help=f"comma-separated: {', '.join(VARIANTS)}")
    args = p.parse_args(argv)
    variants = args.variants.split(",")
    unknown = sorted(set(variants) - set(VARIANTS))
    if unknown:
        p.error(f"unknown variants {unknown}: use {', '.join(VARIANTS)}")
    ros_env.use_localhost_by_default()
    if "ROS_DOMAIN_ID" not in os.environ:
        p.error("set ROS_DOMAIN_ID to a domain of your own (this A/B publishes at 1 kHz)")
    _, sim_project, view_project, rate, joints = next(r for r in LATENCY_RUNS if r[0] == "tank_1kHz")
    runs: dict[str, list[dict]] = {v: [] for v in variants}
    for i in range(args.rounds):
        for v in variants:
            if v.startswith("bare"):
                run = bare_pair_run(rate, args.seconds, 1.0, joints, hand_off=v == "bare_hand_off")
                more = ""
            else:
                headless = v.endswith("headless")
                run = pipeline_run(sim_project, view_project, rate, args.seconds, 1.0, headless_view=headless)
                s2c, c2a = pct(run["step_to_callback"], 1e-6), pct(run["callback_to_applied"], 1e-6)
                more = f"  step -> callback p50 {s2c['p50']:.3f}, callback -> applied p50 {c2a['p50']:.3f}"
            runs[v].append(run)
            lat = pct(run["latency"], 1e-6)
            figures = f"p50 {lat['p50']:.3f} ms  p99 {lat['p99']:.3f} ms  n {lat['n']}"
            print(f"round {i + 1} {v:18s} {figures}{more}", flush=True)
    for v in variants:
        lat = pct([x for r in runs[v] for x in r["latency"]], 1e-6)
        rounds = ", ".join(f"{p50:.3f}" for p50 in _round_p50s(runs[v]))
        print(f"pooled  {v:18s} p50 {lat['p50']:.3f} ms  p99 {lat['p99']:.3f} ms  (rounds' p50: {rounds})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
