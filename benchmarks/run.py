"""The benchmark suite: ``make bench`` (or ``python -m benchmarks.run``).

Every figure comes with a baseline measured in the same run, and the ratio,
because absolute times on a shared machine vary:

* simulation speed: the tutorial's simulation with its controllers against
  a bare ``mj_step`` loop on the same model (the tank with Step 1's
  controller and Step 2's publisher, ``project/step2.yaml``);
* end-to-end latency across processes (simulation step -> state applied on
  the viewer's main thread) against a bare rclpy publisher/subscriber pair
  of the same ``sensor_msgs/JointState`` with the same QoS, in interleaved
  rounds whose samples are pooled; at 1 kHz the same rounds also run the
  bare pair's subscriber and the tutorial on rclpy's ``EventsExecutor``
  (``RTT_EXECUTOR=events``, an opt-in), for comparison;
* the viewer under a 1 kHz flood: age of the displayed state, backlog,
  meshcat cost per frame, frames per second, CPU per process;
* start-up: from the launch command to the first state shown;
* a real robot's description: the Panda's first frame from its
  description's arrival, cold, started again and a second monitor; and
  every robot of example-robot-data's, cold and cached, the median and
  the slowest (:mod:`benchmarks.experiments.any_robot`; figures, not targets);
* a service's and a parameter set's round trip: notebook 10's tank
  (``/Tank/reset``, ``max_track_speed``) against a bare rclpy node, p50
  and p99 (:mod:`benchmarks.experiments.round_trips`; figures, not targets);
* late join: a viewer's and a recorder's wait for the state a running
  publisher keeps, under the project's Fast DDS profile and Fast DDS's
  defaults, and what each profile costs an idle participant;
* a class on one server: 1 to 16 learners on ``make hub``'s JupyterHub,
  each running Step 3 in their kernel with its live views streaming to a
  client that does not draw: each learner's real-time factor, the viewer's
  state age, memory per learner, CPU by process (one learner is the baseline);
* scale curves: N tanks in one world (each with its Step 1 controller and
  Step 2 publisher, driven by one ``rtt-joy --demo``) and one viewer
  mirroring all N, for N = 1, 2, 4, 8; the same for one arm of 6, 12, 24
  and 48 joints (``model/arm<N>.xml``): simulation steps/s against bare
  ``mj_step`` and the real-time factor, the viewer's frames/s and
  scene-update cost, the displayed-state age, CPU per process.

It prints a table of the targets (target, measured, baseline, ratio,
pass/fail), writes ``benchmarks/results/latest.json`` and
``benchmarks/results/targets.md``, and draws its plots beside them
(``bench_scale.png``, ``bench_latency.png``, ``bench_browser.png``), each
titled with the run's time and commit.  The book's figures change only
through ``make bench-figures`` (:mod:`benchmarks.publish`), which copies a
run's plots into ``book/_static/``.  ROS traffic stays on this machine (localhost
discovery, a ROS_DOMAIN_ID of its own).

Here: the options, the order of the experiments, and where the results go.
The experiments are in :mod:`benchmarks.experiments`, the targets in
:mod:`benchmarks.targets`, the printed report and Markdown tables in
:mod:`benchmarks.report`, the plots in :mod:`benchmarks.plots`.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import random
import sys
import tempfile
import time
import traceback
from pathlib import Path

from benchmarks.experiments.any_robot import measure as description_first_frame
from benchmarks.experiments.any_robot import measure_all as every_robot_first_frame
from benchmarks.experiments.browser import CASES as BROWSER_CASES
from benchmarks.experiments.browser import pixel_latency
from benchmarks.experiments.cross_process import latency_rounds
from benchmarks.experiments.late_join import late_join
from benchmarks.experiments.learners import LEARNERS, learners_per_server
from benchmarks.experiments.network import measure as across_hosts
from benchmarks.experiments.round_trips import measure as round_trips
from benchmarks.experiments.scale import scale_curves
from benchmarks.experiments.scene_update import scene_update_cost
from benchmarks.experiments.speed import (
    SPEED_PAIRS,
    SPEED_PAIRS_OTHER,
    realtime_mode,
    simulation_speed,
)
from benchmarks.experiments.startup import startup
from benchmarks.experiments.widget import WIDGET_CASES, first_picture, widget_vs_page
from benchmarks.experiments.widget import remote as widget_remote
from benchmarks.machine import gpu
from benchmarks.machine import probe as machine_probe
from benchmarks.paths import BOOK_STATIC, RESULTS, ROOT
from benchmarks.plots import plot_browser, plot_latency, plot_learners, plot_scale
from benchmarks.report import print_report, print_targets, runs_table, targets_markdown
from benchmarks.targets import partial, targets


class Experiments:
    """Runs a run's experiments one after the other into its results; one that fails does not end the run.

    A full run is half an hour: an experiment that raises (a browser or a
    hub that did not start in time) is noted in ``r["failed"]`` (the
    traceback) and the run goes on, so the other figures are written; the
    failed experiment's targets read n/a, a fail
    (:func:`benchmarks.targets.targets`).  Ctrl-C still stops the run.
    """

    def __init__(self, r: dict):
        self.r = r

    def __call__(self, key: str, experiment, merge: bool = False) -> bool:
        """Run ``experiment()`` into ``r[key]`` (``merge``: its keys into ``r``); False when it failed."""
        try:
            result = experiment()
        except Exception:  # noqa: BLE001 - kept in the results and printed; the run goes on
            why = traceback.format_exc()
            self.r.setdefault("failed", {})[key] = why
            print(f"\n{key}: the experiment FAILED, the run goes on without it:\n{why}", file=sys.stderr, flush=True)
            return False
        if merge:
            self.r.update(result)
        else:
            self.r[key] = result
        return True


def _commit() -> str:
    """The checked-out commit, short, with ``+`` when the work tree has changes ("unknown" outside git)."""
    import subprocess

    try:
        head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True)
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=ROOT, capture_output=True)
    except OSError:
        return "unknown"
    return head.stdout.strip() + ("+" if dirty.stdout.strip() else "") if head.returncode == 0 else "unknown"


def main(argv=None) -> int:
    """Run the suite (or, with ``--table``, only print saved runs' targets); 0 if every target passed, else 1."""
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
        help=f"directory for the plots (default {RESULTS.relative_to(ROOT)}, beside the results; "
        f"make bench-figures copies them into {BOOK_STATIC.relative_to(ROOT)})",
    )
    args = p.parse_args(argv)
    if args.table:
        print(runs_table(args.table), end="")
        return 0
    from tutorial.ros.shm import new_leftovers_removed

    with new_leftovers_removed():  # the Fast DDS files of the nodes the experiments kill (about 80 a run)
        return _suite(args)


def _suite(args) -> int:
    """Every experiment, its report, plots and results (``main``'s arguments); 0 if every target passed, else 1."""
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 100)))
    seconds, warmup = (5.0, 1.0) if args.quick else (args.seconds, 2.0)
    rounds = 1 if args.quick else args.rounds
    plots = Path(args.plots) if args.plots else RESULTS

    import rclpy
    from rclpy.signals import SignalHandlerOptions

    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    machine = {"cpus": os.cpu_count(), "python": platform.python_version(), "platform": platform.platform()}
    r: dict = {
        "machine": machine,
        "when": time.strftime("%Y-%m-%d %H:%M"),
        "commit": _commit(),
        "seconds_per_run": seconds,
        "rounds": rounds,
        "quick": args.quick,  # a smoke test: its targets of sizes it did not run read n/a
        "load_average_at_start": [round(x, 2) for x in os.getloadavg()],
        "machine_at_start": machine_probe(),
        "gpu": gpu(),  # None: the browser draws in software, and the GPU-only targets read n/a
    }
    pairs, other_pairs = (8, 8) if args.quick else (SPEED_PAIRS, SPEED_PAIRS_OTHER)
    rates = {"publisher_50Hz": 50.0, "publisher_every_step": 0.0}
    measure = Experiments(r)
    measure(
        "simulation_speed",
        lambda: {
            "tank": simulation_speed("project/step2.yaml", rates, pairs, 1000),
            "arm24": simulation_speed("benchmarks/projects/arm_sim.yaml", rates, other_pairs, 1000),
        },
    )
    measure("realtime", lambda: realtime_mode("project/step2.yaml", 2.0 if args.quick else 5.0))
    rclpy.try_shutdown()
    measure("pipeline", lambda: latency_rounds(rounds, seconds, warmup), merge=True)  # pipeline, bare, ...
    measure(
        "scene_update",
        lambda: {
            "tank": scene_update_cost("model/tank.xml", 30 if args.quick else 200),
            "arm24": scene_update_cost("model/arm24.xml", 30 if args.quick else 200),
        },
    )
    measure("startup", lambda: startup(1 if args.quick else 3))
    if measure("any_robot", lambda: description_first_frame(1 if args.quick else 3)):  # not a target
        a = r["any_robot"]
        print(
            f"the Panda from its description, first frame after its arrival: cold {a['cold_median_s']} s, "
            f"started again (cached) {a['restart_median_s']} s, second monitor {a['warm_median_s']} s",
            flush=True,
        )
    if not args.quick and measure("every_robot", every_robot_first_frame):  # not a target: about 3 min
        e = r["every_robot"]
        print(
            f"every robot of example-robot-data ({e['robots']}), first frame after its description's arrival: "
            f"cold median {e['cold_median_s']} s, slowest {e['cold_slowest']['s']} s ({e['cold_slowest']['file']}); "
            f"cached median {e['cached_median_s']} s, slowest {e['cached_slowest']['s']} s "
            f"({e['cached_slowest']['file']})",
            flush=True,
        )
    if measure("round_trips", lambda: round_trips(50 if args.quick else 300, 1 if args.quick else 3)):  # not a target
        t = r["round_trips"]
        for kind, what in (("service", "/Tank/reset"), ("parameter_set", "a parameter set")):
            f, ours, bare = t[kind], t[kind]["tutorial_ms"], t[kind]["bare_ms"]
            print(
                f"{what}'s round trip: p50 {ours['p50']} ms, p99 {ours['p99']} ms; a bare rclpy node's "
                f"{bare['p50']} ms, {bare['p99']} ms (ratios {f['p50_ratio']}, {f['p99_ratio']})",
                flush=True,
            )
    late = (4, 4, 5.0) if args.quick else (20, 8, 20.0)  # starts, idle participants, idle seconds
    measure("late_join", lambda: late_join(*late))
    with tempfile.TemporaryDirectory() as d:
        scale_rounds = 1 if args.quick else args.scale_rounds
        measure("scale", lambda: scale_curves(seconds, warmup, scale_rounds, 8 if args.quick else 20, Path(d)))
    measure("browser", lambda: pixel_latency(list(BROWSER_CASES), seconds, warmup))
    measure("widget", lambda: widget_vs_page(list(WIDGET_CASES), seconds, warmup))
    measure("first_picture", lambda: first_picture(4 if args.quick else 10))
    from tutorial.tools.network.hosts import why_unavailable

    hosts_problem = why_unavailable()
    if hosts_problem:  # its targets are left out of the table, and this says why
        r["network_skipped"] = hosts_problem
        print(f"across hosts: skipped ({hosts_problem})", flush=True)
    else:
        measure("network", lambda: across_hosts(6.0 if args.quick else 14.0))
        measure("widget_remote", lambda: widget_remote(5.0))
    learners = (1, 2) if args.quick else LEARNERS
    measure("learners", lambda: learners_per_server(learners, 8.0 if args.quick else 20.0, warmup + 1.0))
    if not args.quick:  # one learner before the cuts of 2026-11-27 and 28: the cores per learner's baseline
        measure("learners_before", lambda: learners_per_server([1], 20.0, warmup + 1.0, before=True))
    r["load_average_at_end"] = [round(x, 2) for x in os.getloadavg()]
    r["machine_at_end"] = machine_probe()
    r["targets"] = targets(r)
    try:
        print_report(r)
    except Exception:  # noqa: BLE001 - re-raised unless this run lacks figures on purpose or after a failure
        if not partial(r):
            raise
        print("\n(the figures stop at the first one this run lacks; all that were measured are in the results)")
        print_targets(r)
    r["plots"] = []
    for plot, name in (
        (plot_scale, "bench_scale.png"),
        (plot_latency, "bench_latency.png"),
        (plot_browser, "bench_browser.png"),
        (plot_learners, "bench_learners.png"),
    ):
        try:
            r["plots"].append(str(plot(r, plots / name)))
        except Exception:  # noqa: BLE001 - as above
            if not partial(r):
                raise
            print(f"{name}: not drawn, this run lacks figures it shows", flush=True)
    out = Path(args.output)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(r, indent=1))
    (out.parent / "targets.md").write_text(targets_markdown(r))
    print(f"\nwritten to {out}, {out.parent / 'targets.md'}; plots: {', '.join(r['plots']) or 'none'}")
    return 0 if all(t["pass"] is not False for t in r["targets"]) else 1


if __name__ == "__main__":
    sys.exit(main())
