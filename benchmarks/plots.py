"""The plots of a run: scale curves, 1 kHz latency distributions, publish -> pixel; PNG files for the book."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from benchmarks.experiments.browser import STAGES as BROWSER_STAGES
from benchmarks.scale_projects import SCALE_JOINTS, SCALE_RATE, SCALE_TANKS
from benchmarks.targets import SCALE_AGE, SCALE_CPU, SCALE_FRAMES, SCALE_REAL_TIME


def plot_scale(r: dict, path: Path) -> Path:
    """The scale curves, one column per kind of growth (tanks, joints), a row per figure, as a PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scale = r["scale"]
    age_limit = SCALE_AGE.limit + SCALE_AGE.baseline(r)  # ms: the limit plus the bare pair's p99 at 50 Hz
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
        ax.axhline(SCALE_REAL_TIME.limit if kind == "tanks" else 1.0, color="grey", ls=":", lw=1)  # joints: real time
        ax.set_ylim(0, 1.1)
        ax.set_title("simulation")
        ax.legend(fontsize=7, loc="lower left")
        ax = axes[1, col]
        ax.plot(sizes, [d["frames_per_s"] for d in data], "o-")
        ax.axhline(SCALE_FRAMES.limit, color="grey", ls=":", lw=1)
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
        ax.axhline(age_limit, color="grey", ls=":", lw=1, label=f"{SCALE_AGE.limit_text} ms + bare pair p99")
        ax.set_ylim(bottom=0)
        ax.set_title("displayed-state age, ms")
        ax.legend(fontsize=7)
        ax = axes[4, col]
        for proc in data[0]["cpu_cores"]:
            ax.plot(sizes, [d["cpu_cores"][proc] for d in data], "o-" if proc == "total" else ".--", label=proc)
        if kind == "tanks":
            ax.axhline(SCALE_CPU.limit, color="grey", ls=":", lw=1)
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
        f"(make bench, {r['when']}, {r.get('commit', '?')}; dotted lines: targets)",
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
    ax.set_title(
        f"1 kHz hand-off, {r['rounds']} interleaved rounds pooled (make bench, {r['when']}, {r.get('commit', '?')})",
        fontsize=10,
    )
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return path


def plot_browser(r: dict, path: Path) -> Path:
    """Publish -> drawn in the browser, stage by stage (p50 bars, p99 marks), each case beside its bare page."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cases = list(r["browser"])
    fig, ax = plt.subplots(figsize=(8, 1.6 + 0.75 * len(cases)), constrained_layout=True)
    colors = plt.cm.tab10.colors
    for row, case in enumerate(cases):
        tut, bare = r["browser"][case]["tutorial"], r["browser"][case]["bare"]
        left = 0.0
        for i, (key, words) in enumerate(BROWSER_STAGES):
            width = tut[key]["p50"] or 0.0
            ax.barh(row + 0.18, width, left=left, height=0.34, color=colors[i], label=words if row == 0 else None)
            left += width
        ax.plot([tut["publish_to_drawn"]["p99"]], [row + 0.18], "k|", ms=14, mew=2)
        ax.barh(
            row - 0.18,
            bare["sent_to_drawn"]["p50"] or 0.0,
            height=0.34,
            color="lightgrey",
            label="bare page: send -> drawn" if row == 0 else None,
        )
        ax.plot([bare["sent_to_drawn"]["p99"]], [row - 0.18], "|", color="grey", ms=14, mew=2)
    # A case far beyond the others (the page starved of CPU) would squeeze them into a corner: its bars are
    # cut at 200 ms and their p99 written out.
    xmax = 200.0
    for row, case in enumerate(cases):
        tut, bare = r["browser"][case]["tutorial"], r["browser"][case]["bare"]
        for y, p99 in ((row + 0.18, tut["publish_to_drawn"]["p99"]), (row - 0.18, bare["sent_to_drawn"]["p99"])):
            if p99 is not None and p99 > xmax:
                ax.text(
                    xmax * 0.99,
                    y,
                    f"p99 {p99:,.0f} ms >",
                    ha="right",
                    va="center",
                    fontsize=7,
                    bbox={"facecolor": "white", "edgecolor": "none", "pad": 1},
                )
    ax.set_xlim(0, xmax)
    ax.set_yticks(range(len(cases)), cases)
    ax.invert_yaxis()
    ax.axvline(2 * 1000 / 60, color="red", ls=":", lw=1)
    ax.set_xlabel("ms from publish (tutorial) or send (bare page) to drawn: bars p50 per stage, marks p99")
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.22), ncol=3)
    ax.grid(alpha=0.3, axis="x")
    ax.set_title(
        f"A state's way to the pixel, headless Chromium (make bench, {r['when']}, {r.get('commit', '?')})", fontsize=10
    )
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return path


def plot_learners(r: dict, path: Path) -> Path:
    """A class on one server: real-time factor, state age, CPU and memory against the number of learners."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from benchmarks.targets import LEARNERS_TARGETS

    runs = r["learners"]
    ns = sorted(int(n) for n in runs if "failed" not in runs[n])  # a class that failed has no figures to draw
    data = [runs[str(n)] for n in ns]
    fig, axes = plt.subplots(2, 2, figsize=(10, 7), constrained_layout=True)
    ax = axes[0, 0]
    ax.plot(ns, [d["real_time_factor_min"] for d in data], "o-", label="lowest learner")
    ax.plot(ns, [float(np.median(d["real_time_factor"])) for d in data], "s--", label="median learner")
    ax.axhline(LEARNERS_TARGETS[0].limit, color="grey", ls=":", lw=1)
    ax.set_title("real-time factor")
    ax.legend(fontsize=8)
    ax = axes[0, 1]
    unknown = float("nan")  # a class where a learner was shown no state in the window: no point
    worst = [unknown if d["age_ms_p99_max"] is None else d["age_ms_p99_max"] for d in data]
    ax.plot(ns, worst, "o-", label="p99, worst learner")
    ax.plot(
        ns,
        [unknown if d["age_ms_pooled"]["p50"] is None else d["age_ms_pooled"]["p50"] for d in data],
        "s--",
        label="p50, all learners",
    )
    ax.axhline(LEARNERS_TARGETS[1].limit, color="grey", ls=":", lw=1)  # the target, ms
    ax.set_yscale("log")
    ax.set_title("viewer: state age when applied, ms")
    ax.legend(fontsize=8)
    ax = axes[1, 0]
    roles = sorted({k for d in data for k in d["cores_by_role"]})
    bottom = np.zeros(len(ns))
    for role in roles:
        values = np.array([d["cores_by_role"].get(role, 0.0) for d in data])
        ax.bar([str(n) for n in ns], values, bottom=bottom, label=role)
        bottom += values
    ax.plot([str(n) for n in ns], [d["cores_busy"] for d in data], "k.-", label="machine busy")
    ax.axhline(r["machine"]["cpus"], color="red", ls=":", lw=1)
    ax.set_title("CPU cores")
    ax.legend(fontsize=7)
    ax = axes[1, 1]
    ax.plot(ns, [d["memory_mb_per_learner_mean"] for d in data], "o-", label="per learner (PSS)")
    ax.axhline(LEARNERS_TARGETS[2].limit, color="grey", ls=":", lw=1)
    ax.set_ylim(0, None)
    ax.set_title("memory per learner, MB")
    for a in axes.flat:
        a.set_xlabel("learners on one hub")
        a.grid(alpha=0.3)
    cores = r["machine"]["cpus"]
    source = r.get("source", "make bench")
    fig.suptitle(f"A class on one server ({cores} cores; {source}, {r['when']}, {r.get('commit', '?')})")
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return path
