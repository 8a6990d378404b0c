"""The report of a run: the printed summary, and the targets as Markdown (one run, or several saved runs)."""

from __future__ import annotations

import json
import re
from pathlib import Path


def verdict(passed: bool | None) -> str:
    """A row's verdict as the tables write it (None: a target not held in that run)."""
    return "n/a" if passed is None else "pass" if passed else "**FAIL**"


def targets_markdown(r: dict) -> str:
    """The targets as a Markdown table (the book's first table)."""
    lines = ["| target | measured | baseline, same run | ratio | |", "|---|---|---|---|---|"]
    for t in r["targets"]:
        lines.append(f"| {t['target']} | {t['measured']} | {t['baseline']} | {t['ratio']} | {verdict(t['pass'])} |")
    return "\n".join(lines) + "\n"


def _number(text: str) -> tuple[float, str] | None:
    """The leading number of a row's figure and what follows it ("1.38x" -> (1.38, "x"), "0.94 s" -> (0.94, " s"),
    "49,751 steps/s" -> (49751.0, " steps/s")); None when it has none ("yes")."""
    m = re.match(r"\s*([-+]?[\d,]*\.?\d+)(.*)$", text or "")
    if m is None:
        return None
    return float(m.group(1).replace(",", "")), m.group(2)


def spread(values: list[str]) -> str:
    """The lowest and highest of the same figure over runs, written as the rows write them ("1.06\u20131.16x");
    the text itself when the runs agree, every run's text when a figure is not a number or the units differ.

    Raises:
        ValueError: no figures.
    """
    if not values:
        raise ValueError("no figures to spread")
    numbers = [_number(v) for v in values]
    if any(n is None for n in numbers) or len({unit for _, unit in numbers}) != 1:
        return values[0] if len(set(values)) == 1 else " / ".join(values)
    lo, hi = min(values, key=lambda v: _number(v)[0]), max(values, key=lambda v: _number(v)[0])
    unit = numbers[0][1]
    return lo if lo == hi else f"{lo[: len(lo) - len(unit)].strip()}\u2013{hi.strip()}"


def runs_table(paths: list[str]) -> str:
    """The targets of several saved runs (``latest.json`` files) as one Markdown table.

    The measured figure, baseline and ratio are the last run's; then the
    spread over the runs (the lowest and highest ratio, or figure where a
    target has no ratio), how many runs met the target, and every run's
    ratio (or figure) and verdict, in order.

    Raises:
        ValueError: the runs do not hold the same targets in the same order.
    """
    runs = [json.loads(Path(p).read_text()) for p in paths]
    last = runs[-1]
    names = [t["target"] for t in last["targets"]]
    for path, r in zip(paths, runs):
        if [t["target"] for t in r["targets"]] != names:
            raise ValueError(f"{path} holds other targets than {paths[-1]}: runs of different suites")
    numbers = ", ".join(str(i + 1) for i in range(len(runs)))
    lines = [
        f"| target | measured | baseline, same run | ratio | spread | met | runs {numbers} |",
        "|---|---|---|---|---|---|---|",
    ]
    for i, t in enumerate(last["targets"]):
        rows = [r["targets"][i] for r in runs]
        shown = [u["ratio"] or u["measured"] for u in rows]
        each = "; ".join(f"{v} {verdict(u['pass'])}" for v, u in zip(shown, rows))
        met = sum(bool(u["pass"]) for u in rows)
        lines.append(
            f"| {t['target']} | {t['measured']} | {t['baseline']} | {t['ratio']} | {spread(shown)} | "
            f"{met} of {len(rows)} | {each} |"
        )
    return "\n".join(lines) + "\n"


def print_report(r: dict) -> None:
    """Print a run's figures, section by section (times in ms unless marked), then its targets."""
    sim = r["simulation_speed"]
    for when in ("start", "end"):
        m = r.get(f"machine_at_{when}")
        if m:
            print(
                f"machine at the {when} ({m['when']}): bare mj_step {m['mj_step_per_s']:,} steps/s, "
                f"load average {m['load_average']}, other processes {m['others_cpu_cores']} cores"
            )
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
        runs = f"{s['pairs']} interleaved pairs of {s['steps_per_run']} steps"
        print(f"  {name:5s} " + ", ".join(parts) + f"  [{runs}; {', '.join(s.get('controllers', []))}]")
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
        f"  {'run':14s} {'p50':>7s} {'p90':>7s} {'p99':>7s} {'max':>8s}   {'bare p50':>8s} {'bare p99':>8s}  "
        "ratio p50/p99"
    )
    for key, run in r["pipeline"].items():
        bare = r["bare"][key]["latency_ms"]
        lat = run["latency_ms"]
        print(
            f"  {key:14s} {lat['p50']:7.3f} {lat['p90']:7.3f} {lat['p99']:7.3f} {lat['max']:8.3f}   "
            f"{bare['p50']:8.3f} {bare['p99']:8.3f}  {lat['p50'] / bare['p50']:.2f} / {lat['p99'] / bare['p99']:.2f}"
        )
    for key, bare in r.get("bare_events_executor", {}).items():
        lat, tutorial = bare["latency_ms"], r["pipeline"][key]["latency_ms"]
        print(
            f"  (not a target: {key} bare pair with its subscriber on the EventsExecutor: p50 {lat['p50']:.3f}, "
            f"p99 {lat['p99']:.3f}; the tutorial's p50/p99 are {tutorial['p50'] / lat['p50']:.2f}x"
            f" / {tutorial['p99'] / lat['p99']:.2f}x these)"
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
        m, age, update, cpu = run["messages"], run["displayed_age_ms"], run["scene_update_ms"], run["cpu_cores"]
        print(
            f"  {key:14s} displayed age p50 {age['p50']:.2f} ms, p99 {age['p99']:.2f} ms "
            f"(first half {run['displayed_age_p99_ms_first_half']}, "
            f"second half {run['displayed_age_p99_ms_second_half']}); "
            f"{run['frames_per_s']} frames/s; scene update p50 {update['p50']:.3f} ms, "
            f"p99 {update['p99']:.3f} ms; messages applied {m['applied']}, coalesced {m['coalesced']}, "
            f"max pending {m['max_pending']}, spin thread stepped aside {m['yields']} times "
            f"({m['yield_timeouts']} gave up); CPU cores sim {cpu['simulation']}, viewer "
            f"{cpu['viewer']}, total {cpu['total']} (bare pair {r['bare'][key]['cpu_cores']})"
        )
    print(
        "\n== meshcat cost per frame (ms): a frame's transforms in one message vs meshcat's round trip per body, "
        "same server, "
        "interleaved"
    )
    for name, u in r["scene_update"].items():
        one, round_trip = u["one_message"], u["round_trip_per_body"]
        print(
            f"  {name:6s} {u['transforms']} transforms: one message p50 {one['p50']:.3f} "
            f"p99 {one['p99']:.3f}; round trip per body p50 {round_trip['p50']:.3f} "
            f"p99 {round_trip['p99']:.3f} ({u['speedup_p50']}x)"
        )
    print(
        f"\n== start-up: launch to first state shown: {r['startup']['first_state_s']} s, "
        f"median {r['startup']['median_s']} s"
    )
    lj = r.get("late_join")
    if lj:
        print(f"\n== late join ({lj['starts']} starts each, next to a running 0.1 Hz publisher): s to the kept state")
        for kind in ("viewer", "recorder"):
            for name, f in lj[kind].items():
                print(
                    f"  {kind:8s} {name:16s} p50 {f['p50']} p95 {f['p95']} max {f['max']} "
                    f"(missed {lj['missed'][kind][name]})"
                )
        for name, c in lj["idle_per_participant"].items():
            print(
                f"  an idle participant, {name}: {c['cpu_cores']} CPU cores, "
                f"{c['udp_datagrams_per_s']} UDP datagrams/s sent (this machine's, per participant)"
            )
    scale = r.get("scale")
    if scale:
        print(
            f"\n== scale ({scale['rate_hz']:g} Hz publishers, {scale['rounds']} rounds of "
            f"{scale['seconds_per_run']:g} s, pooled): simulation speed vs bare mj_step (as fast as possible) and "
            "real-time factor (lowest run); the viewer; displayed-state age at first display p99; CPU cores"
        )
        for kind in ("tanks", "joints"):
            for n, s in scale[kind].items():
                sp, cpu = s["simulation_speed"], s["cpu_cores"]
                parts = ", ".join(f"{k} {v:.2f}" for k, v in cpu.items())
                print(
                    f"  {n:>2s} {kind:6s}: {sp['publisher_50Hz_ratio']:.3f}x bare "
                    f"({sp['publisher_50Hz_steps_per_s']:,} vs {sp['bare_steps_per_s']:,} steps/s), "
                    f"RTF {s['real_time_factor']}; {s['frames_per_s']} frames/s, "
                    f"scene update p50 {s['scene_update_ms']['p50']:.2f} p99 {s['scene_update_ms']['p99']:.2f} ms; "
                    f"age p99 {s['first_shown_age_ms']['p99']:.2f} ms "
                    f"(every frame: {s['displayed_age_ms']['p99']:.2f}); CPU {parts}"
                )
    if r.get("browser"):
        from benchmarks.experiments.browser import STAGES, VIEWPORT

        print(
            f"\n== publish -> pixel in headless Chromium, {VIEWPORT['width']}x{VIEWPORT['height']} px, SwiftShader "
            "(ms, p50/p99 per stage; bare: the same transforms replayed to meshcat's own server and page, "
            "one message each)"
        )
        for case, b in r["browser"].items():
            tut, bare = b["tutorial"], b["bare"]
            stages = ", ".join(f"{k} {tut[k]['p50']}/{tut[k]['p99']}" for k, _ in STAGES)
            print(
                f"  {case}: publish->drawn {tut['publish_to_drawn']['p50']}/{tut['publish_to_drawn']['p99']} "
                f"({tut['states_drawn']} states drawn; {stages}); page {tut['frames_per_s']} frames/s, "
                f"{tut['messages_per_s']} messages/s; "
                f"bare send->drawn {bare['sent_to_drawn']['p50']}/{bare['sent_to_drawn']['p99']}, "
                f"{bare['frames_per_s']} frames/s, {bare['messages_per_s']} messages/s"
            )
            if tut.get("page"):
                page = tut["page"]
                print(
                    f"    the tutorial's page: multisampling {'on' if page['antialias'] else 'off'}, "
                    f"{page.get('detail', 'full')} detail, {page['renderer']}"
                )
    if r.get("network"):
        from benchmarks.experiments.network import print_table

        print("\n== across hosts (two network namespaces; benchmarks.experiments.network)")
        print_table(r["network"])
    print_targets(r)


def print_targets(r: dict) -> None:
    """Print a run's targets, one line each, and the experiments that failed, if any."""
    print("\n== targets")
    for key, why in r.get("failed", {}).items():
        print(f"  [FAIL] the {key} experiment failed; its targets read n/a. Its last words: {why.splitlines()[-1]}")
    for t in r["targets"]:
        figure = (
            t["measured"]
            + (f" vs {t['baseline']}" if t["baseline"] else "")
            + (f" ({t['ratio']})" if t["ratio"] else "")
        )
        print(f"  [{verdict(t['pass']).strip('*').upper()}] {t['target']}: {figure}")
