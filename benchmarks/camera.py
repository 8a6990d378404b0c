"""Step 6's camera: does rendering hold the 1 ms physics back?  ``python -m benchmarks.camera``

The Step 6 project (Step 2 plus the camera publisher at 30 Hz) against the
Step 2 project as the baseline, in interleaved rounds (step2, step6, step2,
...), each run as ``rtt-run`` runs it (an :class:`tutorial.app.app.App`, headless,
in this process, which records every step's lateness):

* real time (``--seconds``, 20 by default): real-time factor, step lateness
  (how far a step ran behind wall-clock time; 0 when on time) p99 and max,
  CPU cores the process used (all its threads), and for Step 6 the pictures
  published per simulated and per wall-clock second, skipped, and the mean
  render time;
* as fast as possible (``--fast-seconds`` of simulated time, 5 by default):
  steps per second, the worst case, where the render thread renders flat out
  next to the simulation.

A third project in each real-time round, ``naive``, is Step 6 with the
rendering done the naive way, inside ``control()`` on the simulation thread
(:class:`RenderInControl`): what the render thread saves the physics from.

An ``rtt-image`` process subscribes the camera the whole time and says how
many pictures it received, against the number published.  Each figure is
printed with the same-run baseline and the ratio; the machine is shared, so
repeat it and look at the spread across rounds.
"""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")  # before anything imports mujoco: render without a display

import argparse  # noqa: E402
import random  # noqa: E402
import re  # noqa: E402
import signal  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import mujoco  # noqa: E402

from benchmarks.stats import pct  # noqa: E402
from tutorial.controllers.camera_image_publisher import RttCameraImagePublisher, render_snapshot  # noqa: E402
from tutorial.core.simulator import Snapshot  # noqa: E402
from tutorial.interfaces.image import fill_image  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
BASELINE, CAMERA, NAIVE = "project/step2.yaml", "project/step6.yaml", "naive"


class RenderInControl(RttCameraImagePublisher):
    """For comparison only, the naive way: render and publish inside ``control()``, on the simulation thread."""

    def initialize(self, io) -> bool:
        self.sim_renderer = mujoco.Renderer(self.model, self.height, self.width)  # the simulation thread's context
        self.sim_data = mujoco.MjData(self.model)
        warm_up = Snapshot(0.0, self.model.qpos0.copy(), 0)  # the first picture's one-time cost, before the clock runs
        render_snapshot(self.sim_renderer, self.sim_data, warm_up, self.camera_id)
        return super().initialize(io)

    def hand_over(self) -> None:
        data = self.io.data
        snapshot = Snapshot(float(data.time), data.qpos.copy(), 0)
        started = time.perf_counter()
        pixels = render_snapshot(self.sim_renderer, self.sim_data, snapshot, self.camera_id)
        self.render_seconds += time.perf_counter() - started
        self.rendered += 1
        fill_image(self.msg, pixels, snapshot.time)
        self.publisher.publish(self.msg)
        self.published += 1
        self.last_handed = snapshot.time

    def stop(self) -> None:
        super().stop()
        self.sim_renderer.close()


def load(project: str):
    """A project by path, or ``naive``: Step 6 with :class:`RenderInControl` in place of the publisher."""
    import dataclasses

    from tutorial.core.project import load_project

    if project != NAIVE:
        return load_project(ROOT / project)
    proj = load_project(ROOT / CAMERA)
    for model in proj.models:
        model.controllers = [
            dataclasses.replace(c, cls=RenderInControl) if c.cls is RttCameraImagePublisher else c
            for c in model.controllers
        ]
    return proj


def run_project(project: str, seconds: float, realtime: bool) -> dict:
    """One headless run of a project in this process; its figures."""
    from tutorial.app.app import App

    app = App(
        load(project),
        node_name=f"bench_camera_{random.randrange(10**6)}",
        headless=True,
        realtime_sync=realtime,
        duration=seconds,
        output=lambda record: None,
        record_timing=realtime,
    )
    cpu0, wall0 = time.process_time(), time.monotonic()
    try:
        app.open()
        app.run()
    finally:
        app.close()
    cores = (time.process_time() - cpu0) / (time.monotonic() - wall0)
    summary = app.summary()
    if summary.get("error"):
        raise RuntimeError(f"{project}: {summary['error']}")
    out = {
        "real_time_factor": app.sim.real_time_factor,
        "steps_per_s": app.sim.steps / app.sim.wall_time,
        "cores": cores,
        "camera": summary.get("controllers", {}).get("RttCameraImagePublisher"),
    }
    if realtime:
        out["late_ms"] = pct(app.sim.lateness, 1000.0)
    return out


def median(values) -> float:
    return float(statistics.median(values))


def spread(values) -> str:
    return f"{min(values):.3f}..{max(values):.3f}"


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--rounds", type=int, default=3, help="interleaved rounds (default 3)")
    p.add_argument("--seconds", type=float, default=20.0, help="simulated time of each real-time run (default 20)")
    p.add_argument(
        "--fast-seconds", type=float, default=5.0, help="simulated time of each as-fast-as-possible run (default 5)"
    )
    args = p.parse_args(argv)
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 100)))

    import rclpy
    from rclpy.signals import SignalHandlerOptions

    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    viewer_dir = tempfile.TemporaryDirectory()
    viewer = subprocess.Popen(
        [
            sys.executable,
            "-u",
            "-m",
            "tutorial.tools.rtt_image",
            "--no-window",
            "--output",
            str(Path(viewer_dir.name) / "image.png"),
        ],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    rows: list[tuple[int, str, str, dict]] = []
    try:
        time.sleep(2.0)  # not synchronisation: rtt-image starts and joins the graph before the first run
        for r in range(1, args.rounds + 1):
            for project in (BASELINE, CAMERA, NAIVE) if r % 2 else (NAIVE, CAMERA, BASELINE):
                rows.append((r, "real time", project, run_project(project, args.seconds, realtime=True)))
                print(f"round {r}: {project} real time done", flush=True)
            for project in (BASELINE, CAMERA) if r % 2 else (CAMERA, BASELINE):
                rows.append((r, "fast", project, run_project(project, args.fast_seconds, realtime=False)))
    finally:
        time.sleep(1.0)  # not synchronisation: lets the last pictures reach rtt-image before it stops
        viewer.send_signal(signal.SIGINT)
        viewer_out, _ = viewer.communicate(timeout=30)
        viewer_dir.cleanup()
        rclpy.try_shutdown()

    print(
        f"\nStep 6 camera benchmark: {args.rounds} interleaved rounds; real time {args.seconds:g} s, "
        f"fast {args.fast_seconds:g} s of simulated time each; {os.cpu_count()} CPUs"
    )
    print(
        f"{'round':>5} {'mode':<9} {'project':<8} {'RTF':>6} {'steps/s':>8} {'late p99':>8} {'late max':>8} "
        f"{'cores':>5} {'img/sim s':>9} {'img/wall s':>10} {'skipped':>7} {'render ms':>9}"
    )
    for r, mode, project, f in rows:
        cam = f["camera"] or {}
        late = f.get("late_ms") or {}
        print(
            f"{r:>5} {mode:<9} {Path(project).stem:<8} {f['real_time_factor']:>6.3f} {f['steps_per_s']:>8.0f} "
            f"{late.get('p99', ''):>8} {late.get('max', ''):>8} {f['cores']:>5.2f} "
            f"{cam.get('published_per_sim_s', ''):>9} {cam.get('published_per_wall_s', ''):>10} "
            f"{cam.get('skipped', ''):>7} {cam.get('render_ms', ''):>9}"
        )

    def pick(mode, project, key):
        return [f[key] for _, m, p, f in rows if m == mode and p == project]

    print("\nmedians (spread across rounds), Step 6 against the same run's Step 2:")
    for mode, key, label in (
        ("real time", "real_time_factor", "real-time factor"),
        ("fast", "steps_per_s", "steps/s as fast as possible"),
        ("real time", "cores", "CPU cores, real time"),
    ):
        base, cam = pick(mode, BASELINE, key), pick(mode, CAMERA, key)
        print(
            f"  {label:<30} step2 {median(base):10.3f} ({spread(base)})   step6 {median(cam):10.3f} "
            f"({spread(cam)})   ratio {median(cam) / median(base):.3f}"
        )
    for q in ("p99", "max"):
        base, cam, naive = (
            [late[q] for late in pick("real time", project, "late_ms")] for project in (BASELINE, CAMERA, NAIVE)
        )
        print(
            f"  {'step lateness ' + q + ', ms':<30} step2 {median(base):10.3f} ({spread(base)})   "
            f"step6 {median(cam):10.3f} ({spread(cam)})   naive {median(naive):10.3f} ({spread(naive)})"
        )
    naive = pick("real time", NAIVE, "real_time_factor")
    print(
        f"  {'real-time factor, naive':<30} {median(naive):.3f} ({spread(naive)}): "
        "rendering inside control() on the simulation thread"
    )
    cams = [f["camera"] for _, m, p, f in rows if m == "real time" and p == CAMERA]
    print(
        f"  {'pictures per simulated s':<30} {median([c['published_per_sim_s'] for c in cams]):.2f} "
        f"({spread([c['published_per_sim_s'] for c in cams])}) of 30 asked; per wall s "
        f"{median([c['published_per_wall_s'] for c in cams]):.2f}; skipped "
        f"{sum(c['skipped'] for c in cams)} of {sum(c['handed_over'] for c in cams)} handed over; "
        f"render {median([c['render_ms'] for c in cams]):.1f} ms"
    )
    published = sum(f["camera"]["published"] for _, m, p, f in rows if p != BASELINE)
    done = re.search(r"done: (\d+) pictures accepted, (\d+) rejected", viewer_out)
    if done:
        print(
            f"  rtt-image received {done.group(1)} of {published} pictures published "
            f"(every run; best effort, keep last 1), rejected {done.group(2)}"
        )
    else:
        print("  rtt-image did not report:\n" + viewer_out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
