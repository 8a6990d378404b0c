"""The targets of ``make bench`` as data: each limit is written once, and makes both the target's words and its verdict.

A target holds one figure of a run (``latest.json``'s dict) against its
limit, and writes the table's row: target, measured, baseline (same run),
ratio, pass.  Adding one is an entry in :data:`TARGETS`.
"""

from __future__ import annotations

import operator
from collections.abc import Callable
from dataclasses import dataclass
from functools import reduce

from benchmarks.scale_projects import SCALE_RATE, SCALE_TANKS

FRAME_60HZ_MS = 1000.0 / 60.0  # ms: one frame of a 60 Hz display
AT_MOST, AT_LEAST = operator.le, operator.ge
# What a target's figure (its ratio, for "ratio") is held against, from its limit and its same-run baseline.
BOUNDS = {
    "limit": lambda limit, baseline: limit,
    "ratio": lambda limit, baseline: limit,
    "times": lambda limit, baseline: limit * baseline,
    "plus": lambda limit, baseline: limit + baseline,
}


def read(*keys: str) -> Callable[[dict], object]:
    """A reader of run results: ``read("a", "b")(r)`` is ``r["a"]["b"]``."""
    return lambda r: reduce(operator.getitem, keys, r)


def partial(r: dict) -> bool:
    """Whether run results ``r`` may lack figures: an experiment failed (``r["failed"]``), a class of
    learners failed (its entry in ``r["learners"]`` says so), or the run was ``--quick`` (fewer sizes: no
    class of 8 learners)."""
    classes = r.get("learners") or {}
    return bool(r.get("failed") or r.get("quick") or any("failed" in c for c in classes.values()))


@dataclass(frozen=True)
class Target:
    """One target: a figure of a run, its limit, and how the two are compared and written.

    ``text`` holds ``{limit}`` where the limit goes, written with
    ``limit_fmt``; the verdict uses the same ``limit``.  ``against`` says
    what the figure is held against: ``"limit"`` (the limit itself; a
    baseline, if given, is shown for reference), ``"times"`` (the limit
    times the baseline), ``"plus"`` (the limit plus the baseline), or
    ``"ratio"`` (not the figure: ``ratio(r)`` is held against the limit).
    With ``"times"``, ``offset`` is added to the bound (``{offset}`` in the
    text writes it).
    A figure, baseline or ratio that is None was not measured: "n/a", a fail.
    """

    text: str
    limit: float
    compare: Callable[[float, float], bool]  # AT_MOST or AT_LEAST: compare(figure, what it is held against)
    figure: Callable[[dict], float | None]  # run results -> the measured figure
    fmt: str | Callable[[object], str]  # the figure written: a format, e.g. "{:.3f} ms", or a function
    against: str = "limit"  # "limit", "times", "plus" or "ratio" (see above)
    baseline: Callable[[dict], float | None] | None = None  # run results -> the same-run baseline, same unit
    baseline_fmt: str | None = None  # the baseline written (None: as `fmt`)
    ratio: Callable[[dict], float | None] | None = None  # run results -> the ratio (None: figure / baseline)
    ratio_fmt: str = "{:.2f}x"
    limit_fmt: str = "{:g}"
    needs: str | None = None  # a key of the run results without which the target is left out ("scale")
    offset: float = 0.0  # with "times": the figure is held against limit x baseline + offset
    gpu_only: bool = False  # only a GPU can meet it: where the run's browser had none (r["gpu"]), n/a, not a miss

    @property
    def limit_text(self) -> str:
        """The limit as the target's words write it."""
        return self.limit_fmt.format(self.limit)

    @property
    def label(self) -> str:
        """The target's words, its limit written in."""
        return self.text.format(limit=self.limit_text, offset=f"{self.offset:g}")

    def written(self, value) -> str:
        """A figure as the row writes it."""
        return self.fmt(value) if callable(self.fmt) else self.fmt.format(value)

    def row(self, r: dict) -> dict:
        """The table's row for run results ``r``: target, measured, baseline, ratio (text) and pass (bool; None:
        not held in this run, a ``gpu_only`` target without a GPU).

        In a :func:`partial` run, a target whose figures it lacks reads
        "n/a": a fail, never left out.

        Raises:
            KeyError, TypeError: a figure is missing from a full run where no experiment failed.
        """
        if self.gpu_only and not r.get("gpu"):
            return {
                "target": self.label,
                "measured": "n/a: no GPU (Chromium draws with SwiftShader)",
                "baseline": "",
                "ratio": "",
                "pass": None,
            }
        try:
            value = self.figure(r)
            base = None if self.baseline is None else self.baseline(r)
            ratio = self.ratio(r) if self.ratio is not None else None
        except (KeyError, TypeError):
            if not partial(r):
                raise
            return {"target": self.label, "measured": "n/a", "baseline": "", "ratio": "", "pass": False}
        if self.ratio is None and value is not None and base is not None:
            # the figure to its baseline, or to its bound when that is the limit plus the baseline
            ratio = value / (self.limit + base if self.against == "plus" else base)
        held = ratio if self.against == "ratio" else value
        if base is None and self.against in ("times", "plus"):
            held = None
        if self.baseline is None:
            baseline = ""
        elif base is None:
            baseline = "n/a"
        else:
            baseline = self.baseline_fmt.format(base) if self.baseline_fmt else self.written(base)
            if self.against == "plus":
                baseline = f"{self.limit_text} + {baseline}"
        return {
            "target": self.label,
            "measured": "n/a" if value is None else self.written(value),
            "baseline": baseline,
            "ratio": "" if ratio is None else self.ratio_fmt.format(ratio),
            "pass": held is not None
            and bool(
                self.compare(
                    held, BOUNDS[self.against](self.limit, base) + (self.offset if self.against == "times" else 0.0)
                )
            ),
        }


_TANK_1KHZ, _BARE_1KHZ = ("pipeline", "tank_1kHz"), ("bare", "tank_1kHz")
_SPEED = ("simulation_speed", "tank")
_MOST_TANKS = ("scale", "tanks", str(max(SCALE_TANKS)))

# The scale targets, by name: the scale plot draws their limits.
SCALE_REAL_TIME = Target(
    "8 tanks simulate in real time (real-time factor >= {limit}, the lowest run)",
    0.99,
    AT_LEAST,
    read(*_MOST_TANKS, "real_time_factor"),
    "{:.3f}",
    baseline=lambda r: 1.0,
    baseline_fmt="{:.3f} (wall clock)",
    ratio_fmt="{:.3f}x",
    needs="scale",
)
SCALE_FRAMES = Target(
    "the viewer mirrors all 8 at >= {limit} frames/s",
    50.0,
    AT_LEAST,
    read(*_MOST_TANKS, "frames_per_s"),
    "{:.1f} frames/s",
    baseline=lambda r: SCALE_RATE,
    baseline_fmt="{:.0f} states/s per tank (cap 60)",
    needs="scale",
)
SCALE_AGE = Target(
    "8 tanks: displayed-state age p99 <= {limit} ms + the bare pair's p99 (50 Hz)",
    FRAME_60HZ_MS,
    AT_MOST,
    read(*_MOST_TANKS, "first_shown_age_ms", "p99"),
    "{:.2f} ms",
    against="plus",
    baseline=read("bare", "tank_50Hz", "latency_ms", "p99"),
    limit_fmt="{:.1f}",
    needs="scale",
)
SCALE_CPU = Target(
    "8 tanks: the whole pipeline <= {limit} CPU cores",
    1.5,
    AT_MOST,
    read(*_MOST_TANKS, "cpu_cores", "total"),
    "{:.2f} cores",
    needs="scale",
)

_BROWSER_CASES = {
    "tank_50Hz": "1 tank at 50 Hz",
    "tank_1kHz": "1 tank at 1 kHz",
    "tanks_8": "8 tanks",
    "arm_48": "the 48-joint arm",
}
# The cases whose bare meshcat page itself misses two 60 Hz frames when Chromium draws in software: the
# absolute target is a GPU's; their ratio to the bare page, same run, is held everywhere.
GPU_ONLY = ("tanks_8", "arm_48")
BROWSER_TARGETS = tuple(
    target
    for case, words in _BROWSER_CASES.items()
    for target in (
        Target(
            f"browser, {words}: publish -> drawn p99 <= {{limit}} ms (two 60 Hz frames)",
            2 * FRAME_60HZ_MS,
            AT_MOST,
            read("browser", case, "tutorial", "publish_to_drawn", "p99"),
            "{:.1f} ms",
            baseline=read("browser", case, "bare", "sent_to_drawn", "p99"),
            baseline_fmt="bare page {:.1f} ms",
            limit_fmt="{:.1f}",
            needs="browser",
            gpu_only=case in GPU_ONLY,
        ),
        Target(
            f"browser, {words}: publish -> drawn p99 <= {{limit}}x the bare page's send -> drawn p99",
            1.2,
            AT_MOST,
            read("browser", case, "tutorial", "publish_to_drawn", "p99"),
            "{:.1f} ms",
            against="times",
            baseline=read("browser", case, "bare", "sent_to_drawn", "p99"),
            needs="browser",
        ),
    )
) + (
    Target(
        "browser, 8 tanks: the page keeps >= {limit} frames/s",
        55.0,
        AT_LEAST,
        read("browser", "tanks_8", "tutorial", "frames_per_s"),
        "{:.1f} frames/s",
        baseline=read("browser", "tanks_8", "bare", "frames_per_s"),
        baseline_fmt="bare page {:.1f} frames/s",
        needs="browser",
    ),
)

# The live view in the notebook (a widget over Jupyter's connection) beside the meshcat page over its own
# WebSocket, the same taped frames, the same run (benchmarks/experiments/widget.py).
WIDGET_TARGETS = tuple(
    Target(
        f"notebook view, {words}: handed -> drawn p99 <= {{limit}}x the meshcat page's",
        1.2,
        AT_MOST,
        read("widget", case, "widget", "handed_to_drawn", "p99"),
        "{:.1f} ms",
        against="times",
        baseline=read("widget", case, "page", "sent_to_drawn", "p99"),
        needs="widget",
    )
    for case, words in (("tank_50Hz", "1 tank at 50 Hz"), ("tanks_8", "8 tanks"))
) + (
    Target(
        "notebook view, 8 tanks: the view's page keeps >= {limit} frames/s",
        55.0,
        AT_LEAST,
        read("widget", "tanks_8", "widget", "frames_per_s"),
        "{:.1f} frames/s",
        baseline=read("widget", "tanks_8", "page", "frames_per_s"),
        baseline_fmt="meshcat page {:.1f} frames/s",
        needs="widget",
    ),
    Target(
        "notebook view without the nodelay extension (as in Colab), 8 tanks: the view's page keeps >= {limit} "
        "frames/s (its handed -> drawn p99, about 3x the page's, is in latest.json: the README's Front ends)",
        20.0,
        AT_LEAST,
        read("widget", "tanks_8", "widget_plain", "frames_per_s"),
        "{:.1f} frames/s",
        baseline=read("widget", "tanks_8", "widget", "frames_per_s"),
        baseline_fmt="with the extension {:.1f} frames/s",
        needs="widget",
    ),
    Target(
        "notebook view: a new view's first picture while a cell runs (Run All), from its output appearing, "
        "p99 of 10 <= {limit} ms",
        2000.0,
        AT_MOST,
        read("first_picture", "busy", "p99"),
        "{:.0f} ms",
        baseline=read("first_picture", "idle", "p99"),
        baseline_fmt="kernel idle {:.0f} ms",
        needs="first_picture",
    ),
    Target(
        "notebook view, browser on another host over 5 Mbit/s: the view draws >= {limit} frames/s from the kernel",
        20.0,
        AT_LEAST,
        read("widget_remote", "fps"),
        "{:.1f} frames/s",
        needs="widget_remote",
    ),
    Target(
        "notebook view, browser on another host over 5 Mbit/s: a trivial cell answers within {limit} ms (worst of 5)",
        500.0,
        AT_MOST,
        read("widget_remote", "cell_ms_max"),
        "{:.0f} ms",
        needs="widget_remote",
    ),
)

# A class on one server: N learners on make hub's JupyterHub, each running Step 3 with its live views at the
# hub's frame rate (benchmarks/experiments/learners.py); the baseline is one learner alone, same run.
LEARNERS_AT = "8"
LEARNERS_TARGETS = (
    Target(
        f"a class on one server, {LEARNERS_AT} learners (Step 3, live views): every learner's real-time factor "
        ">= {limit}",
        0.99,
        AT_LEAST,
        read("learners", LEARNERS_AT, "real_time_factor_min"),
        "{:.3f}",
        baseline=read("learners", "1", "real_time_factor_min"),
        baseline_fmt="one learner {:.3f}",
        needs="learners",
    ),
    Target(
        # A saturated machine cannot keep "<= 2x one learner's" (about 4 ms): two frames at 60 Hz is what a
        # learner would see as late.
        f"a class on one server, {LEARNERS_AT} learners: the viewer's state age p99 (worst learner) <= {{limit}} ms",
        33.0,
        AT_MOST,
        read("learners", LEARNERS_AT, "age_ms_p99_max"),
        "{:.1f} ms",
        baseline=read("learners", "1", "age_ms_p99_max"),
        baseline_fmt="one learner {:.1f} ms",
        needs="learners",
    ),
    Target(
        f"a class on one server, {LEARNERS_AT} learners: memory per learner (PSS of their server and all it "
        "started) <= {limit} MB",
        1024.0,
        AT_MOST,
        read("learners", LEARNERS_AT, "memory_mb_per_learner_mean"),
        "{:.0f} MB",
        baseline=read("learners", "1", "memory_mb_per_learner_mean"),
        baseline_fmt="one learner {:.0f} MB",
        needs="learners",
    ),
    Target(
        "a class on one server, one learner: cores per learner (their kernel, Jupyter server and joystick) <= {limit}",
        0.20,
        AT_MOST,
        read("learners", "1", "cores_per_learner"),
        "{:.3f} cores",
        # for reference only (held against the limit): a before-run that failed reads n/a, never a crash
        baseline=lambda r: ((r.get("learners_before") or {}).get("1") or {}).get("cores_per_learner"),
        baseline_fmt="before the cuts of 2026-11-27 and 28 {:.3f} cores",
        needs="learners",
    ),
)

_NET = "network"
NETWORK_TARGETS = (
    Target(
        "across hosts, 5 Mbit/s, camera on: remote camera >= {limit} pictures/s",
        10.0,
        AT_LEAST,
        read(_NET, "5mbit", "camera_per_s"),
        "{:.1f} pictures/s",
        needs=_NET,
    ),
    Target(
        "across hosts, 5 Mbit/s, camera on: joint-state age p99 at the remote monitor <= {limit}x the clean link's "
        "p99 + {offset} ms",
        2.0,
        AT_MOST,
        read(_NET, "5mbit", "age_p99_ms"),
        "{:.2f} ms",
        against="times",
        offset=5.0,
        baseline=read(_NET, "clean", "age_p99_ms"),
        baseline_fmt="clean link {:.2f} ms",
        needs=_NET,
    ),
    Target(
        "across hosts, 20 % loss: the monitor applies >= {limit} states/s",
        40.0,
        AT_LEAST,
        read(_NET, "loss20", "states_per_s"),
        "{:.1f} states/s",
        baseline=read(_NET, "clean", "states_per_s"),
        baseline_fmt="clean link {:.1f} states/s",
        needs=_NET,
    ),
    Target(
        "across hosts, 20 % loss: the monitor ends on the simulation's final state",
        1.0,
        AT_LEAST,
        lambda r: float(r[_NET]["loss20"]["ends_exact"]),
        lambda exact: "yes" if exact else "no",
        needs=_NET,
    ),
    Target(
        "across hosts, 4 s partition: stale within {limit} s of the cut",
        1.25,
        AT_MOST,
        read(_NET, "partition", "stale_after_s"),
        "{:.2f} s",
        needs=_NET,
    ),
    Target(
        "across hosts, 4 s partition: live within {limit} s of the heal",
        2.0,
        AT_MOST,
        read(_NET, "partition", "live_after_s"),
        "{:.2f} s",
        needs=_NET,
    ),
) + tuple(
    Target(
        f"across hosts, {words}: the simulation keeps real time (real-time factor >= {{limit}})",
        0.98,
        AT_LEAST,
        read(_NET, case, "real_time_factor"),
        "{:.3f}",
        needs=_NET,
    )
    for case, words in (
        ("clean", "clean link"),
        ("loss20", "20 % loss"),
        ("5mbit", "5 Mbit/s"),
        ("partition", "partition"),
    )
)

LATE_JOIN_TARGETS = tuple(
    Target(
        f"late join: {words} started next to a running 0.1 Hz publisher has its kept state within {{limit}} s "
        "(p95 of the starts)",
        1.0,
        AT_MOST,
        read("late_join", kind, "project", "p95"),
        "{:.2f} s",
        baseline=read("late_join", kind, "fast_dds_default", "p95"),
        baseline_fmt="Fast DDS's defaults {:.2f} s",
        needs="late_join",
    )
    for kind, words in (("viewer", "a viewer"), ("recorder", "rtt-bag record"))
)

TARGETS = (
    Target(
        "simulation with the 50 Hz publisher >= {limit}x bare mj_step (steps/s)",
        0.8,
        AT_LEAST,
        read(*_SPEED, "publisher_50Hz_steps_per_s"),
        "{:,} steps/s",
        against="ratio",
        baseline=read(*_SPEED, "bare_steps_per_s"),
        ratio=read(*_SPEED, "publisher_50Hz_ratio"),
        ratio_fmt="{:.3f}x",
    ),
    Target(
        "end-to-end p50 <= {limit}x the bare rclpy pair at 1 kHz",
        1.5,
        AT_MOST,
        read(*_TANK_1KHZ, "latency_ms", "p50"),
        "{:.3f} ms",
        against="times",
        baseline=read(*_BARE_1KHZ, "latency_ms", "p50"),
    ),
    Target(
        "end-to-end p99 <= {limit}x the bare rclpy pair at 1 kHz",
        2.0,
        AT_MOST,
        read(*_TANK_1KHZ, "latency_ms", "p99"),
        "{:.3f} ms",
        against="times",
        baseline=read(*_BARE_1KHZ, "latency_ms", "p99"),
    ),
    Target(
        "displayed-state age p99 at 1 kHz <= {limit} ms + the bare pair's p99",
        FRAME_60HZ_MS,
        AT_MOST,
        read(*_TANK_1KHZ, "displayed_age_ms", "p99"),
        "{:.2f} ms",
        against="plus",
        baseline=read(*_BARE_1KHZ, "latency_ms", "p99"),
        limit_fmt="{:.1f}",
    ),
    Target(
        "Step 3 pipeline at 1 kHz <= {limit} CPU core",
        1.0,
        AT_MOST,
        read(*_TANK_1KHZ, "cpu_cores", "total"),
        "{:.2f} cores",
        baseline=read(*_BARE_1KHZ, "cpu_cores"),
        baseline_fmt="bare pair {:.2f} cores",
    ),
    Target("first state shown <= {limit} s after launch", 3.0, AT_MOST, read("startup", "median_s"), "{:.2f} s"),
    SCALE_REAL_TIME,
    SCALE_FRAMES,
    SCALE_AGE,
    SCALE_CPU,
    *LATE_JOIN_TARGETS,
    *NETWORK_TARGETS,
    *BROWSER_TARGETS,
    *WIDGET_TARGETS,
    *LEARNERS_TARGETS,
)


def targets(r: dict) -> list[dict]:
    """Each target's row for run results ``r``: its text, the measured figure, the same-run baseline, ratio, pass.

    A target whose experiment did not run (``needs``: across hosts without
    root) is left out; one whose experiment failed (``r["failed"]``) is a fail.
    """
    failed = r.get("failed", {})
    return [t.row(r) for t in TARGETS if t.needs is None or r.get(t.needs) or t.needs in failed]
