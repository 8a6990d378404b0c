"""The benchmark suite's bookkeeping: plots reach the book only through make bench-figures; late-join targets."""

from __future__ import annotations

import json

import pytest

from benchmarks import publish
from benchmarks.experiments.late_join import summary
from benchmarks.report import runs_table, spread
from benchmarks.targets import LATE_JOIN_TARGETS

pytestmark = pytest.mark.unit


def test_bench_figures_copies_a_runs_plots_and_names_the_run(tmp_path):
    run, book = tmp_path / "results", tmp_path / "static"
    run.mkdir(), book.mkdir()
    (run / "latest.json").write_text(json.dumps({"when": "2026-11-24 01:00", "commit": "abc1234"}))
    for i, name in enumerate(publish.PLOTS):
        (run / name).write_bytes(bytes([i]) * 10)
    assert publish.publish(run, book) == "2026-11-24 01:00, commit abc1234"
    assert [(book / name).read_bytes() for name in publish.PLOTS] == [bytes([i]) * 10 for i in range(3)]


def test_bench_figures_refuses_a_run_without_its_plots(tmp_path):
    (tmp_path / "latest.json").write_text(json.dumps({"when": "x"}))
    (tmp_path / "bench_scale.png").write_bytes(b"png")
    with pytest.raises(FileNotFoundError, match="bench_latency.png, bench_browser.png"):
        publish.publish(tmp_path, tmp_path / "book")


def test_make_bench_never_writes_into_the_book():
    from benchmarks import run
    from benchmarks.paths import BOOK_STATIC

    source = open(run.__file__, encoding="utf-8").read()
    assert "plots = Path(args.plots) if args.plots else RESULTS" in source
    assert "BOOK_STATIC /" not in source and str(BOOK_STATIC) not in source


def test_late_join_summary_and_targets():
    assert summary([]) == {"n": 0, "p50": None, "p95": None, "max": None}
    s = summary([0.1] * 19 + [3.0])
    assert s["n"] == 20 and s["p50"] == 0.1 and s["max"] == 3.0 and 0.1 < s["p95"] < 3.0
    run = {
        "late_join": {
            "viewer": {"project": {"p95": 0.3}, "fast_dds_default": {"p95": 2.4}},
            "recorder": {"project": {"p95": 1.2}, "fast_dds_default": {"p95": 0.9}},
        }
    }
    viewer, recorder = (t.row(run) for t in LATE_JOIN_TARGETS)
    assert viewer["pass"] and viewer["measured"] == "0.30 s" and "2.40 s" in viewer["baseline"]
    assert not recorder["pass"]
    assert [t.row({}) for t in LATE_JOIN_TARGETS if t.needs is None or {}.get(t.needs)] == []


def test_learners_targets_and_plot(tmp_path):
    """A class on one server: each target's verdict from the class of 8 against one learner, and the plot."""
    from benchmarks.plots import plot_learners
    from benchmarks.targets import LEARNERS_TARGETS

    def one(n, rtf, age_p99, mb, cores=0.19):
        return {
            "real_time_factor": [rtf] * n, "real_time_factor_min": rtf, "age_ms_p99_max": age_p99,
            "age_ms_pooled": {"p50": age_p99 / 3}, "memory_mb_per_learner_mean": mb, "cores_busy": 0.25 * n,
            "cores_by_role": {"kernels": 0.14 * n, "learners' servers": 0.05 * n}, "cores_per_learner": cores,
        }  # fmt: skip

    run = {"machine": {"cpus": 2}, "when": "now", "learners": {"1": one(1, 1.0, 0.8, 277), "8": one(8, 1.0, 32.9, 232)},
           "learners_before": {"1": one(1, 1.0, 0.9, 277, cores=0.49)}}  # fmt: skip
    rtf, age, memory, cores = (t.row(run) for t in LEARNERS_TARGETS)
    assert rtf["pass"] and age["pass"] and memory["pass"] and cores["pass"] and age["measured"] == "32.9 ms"
    assert cores["measured"] == "0.190 cores" and "cuts of 2026-11-27 and 28 0.490 cores" in cores["baseline"]
    failed_before = dict(run, learners_before={"1": {"learners": 1, "failed": "TimeoutError: ..."}})
    assert (
        LEARNERS_TARGETS[3].row(failed_before)["pass"] and LEARNERS_TARGETS[3].row(failed_before)["baseline"] == "n/a"
    )
    run["learners"]["8"] = one(8, 0.98, 33.1, 1100)  # behind real time, ages past 33 ms, over 1 GiB
    run["learners"]["1"] = one(1, 1.0, 0.8, 277, cores=0.21)  # a learner costs over a fifth of a core
    assert not any(t.row(run)["pass"] for t in LEARNERS_TARGETS)
    assert [t.row({}) for t in LEARNERS_TARGETS if t.needs is None or {}.get(t.needs)] == []  # not run: left out
    path = plot_learners(run, tmp_path / "bench_learners.png")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_class_that_fails_keeps_the_smaller_classes_figures(monkeypatch, tmp_path, capsys):
    """A class the machine cannot carry (a learner's cell timed out) is kept as failed, the smaller classes'
    figures stay, no larger class is tried, the targets of the failed size read n/a, and the plot draws the rest."""
    from benchmarks.experiments import learners
    from benchmarks.plots import plot_learners
    from benchmarks.targets import LEARNERS_TARGETS

    tried = []

    def one_class(n, *_args):
        tried.append(n)
        if n >= 8:
            raise TimeoutError("a learner's cell did not finish")
        return {
            "real_time_factor": [1.0] * n, "real_time_factor_min": 1.0, "age_ms_p99_max": 3.0 * n,
            "age_ms_pooled": {"p50": 1.0}, "memory_mb_per_learner_mean": 250.0, "cores_busy": 0.4 * n,
            "cores_by_role": {"kernels": 0.2 * n}, "learners_with_no_state_in_window": 0, "frames_per_s_min": 38.0,
            "client_cores": 0.05, "cores_per_learner": 0.2,
        }  # fmt: skip

    monkeypatch.setattr(learners, "one_class", one_class)
    out = learners.learners_per_server((1, 2, 4, 8, 16), 1.0, 0.1)
    assert tried == [1, 2, 4, 8] and sorted(out) == ["1", "2", "4", "8"]
    assert out["4"]["age_ms_p99_max"] == 12.0
    assert out["8"] == {"learners": 8, "failed": "TimeoutError: a learner's cell did not finish"}
    assert "8 learners: the class failed (TimeoutError" in capsys.readouterr().out
    run = {"machine": {"cpus": 2}, "when": "now", "learners": out}
    assert [t.row(run)["measured"] for t in LEARNERS_TARGETS[:3]] == ["n/a"] * 3  # the class of 8's
    assert not any(t.row(run)["pass"] for t in LEARNERS_TARGETS[:3])
    assert plot_learners(run, tmp_path / "bench_learners.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
    "values, written",
    [
        (["1.38x", "1.92x", "1.06x"], "1.06\u20131.92x"),
        (["49,751 steps/s", "59,524 steps/s"], "49,751\u201359,524 steps/s"),
        (["0.94 s", "0.94 s"], "0.94 s"),
        (["yes", "yes"], "yes"),
        (["yes", "no"], "yes / no"),
        (["n/a", "1.2x"], "n/a / 1.2x"),
        (["10.2 ms", "9.5 ms"], "9.5\u201310.2 ms"),  # by number, not by text
        (["950 steps/s", "1,200 steps/s"], "950\u20131,200 steps/s"),
        (["0.9 s", "900 ms"], "0.9 s / 900 ms"),  # units differ: not one spread
    ],
)
def test_the_spread_of_a_figure_over_runs(values, written):
    assert spread(values) == written


def _saved_run(path, ratios_and_verdicts):
    targets = [
        {"target": f"t{i}", "measured": "1 ms", "baseline": "", "ratio": ratio, "pass": ok}
        for i, (ratio, ok) in enumerate(ratios_and_verdicts)
    ]
    path.write_text(json.dumps({"targets": targets}))
    return str(path)


def test_runs_table_counts_the_runs_that_met_each_target(tmp_path):
    a = _saved_run(tmp_path / "a.json", [("1.1x", True), ("2.0x", False)])
    b = _saved_run(tmp_path / "b.json", [("1.3x", True), ("1.4x", True)])
    rows = runs_table([a, b]).splitlines()[2:]
    assert rows[0].split(" | ")[4:6] == ["1.1\u20131.3x", "2 of 2"]
    assert rows[1].split(" | ")[4:6] == ["1.4\u20132.0x", "1 of 2"]


def test_runs_table_refuses_runs_of_different_suites(tmp_path):
    a = _saved_run(tmp_path / "a.json", [("1.1x", True)])
    b = _saved_run(tmp_path / "b.json", [("1.1x", True), ("1.4x", True)])
    with pytest.raises(ValueError, match="other targets"):
        runs_table([a, b])


def test_no_figures_have_no_spread():
    with pytest.raises(ValueError, match="no figures"):
        spread([])


def test_each_round_keeps_its_own_p50():
    from benchmarks.experiments.cross_process import _round_p50s

    assert _round_p50s([{"latency": [100_000, 300_000, 200_000]}, {"latency": []}, {"latency": [150_000]}]) == [
        0.2,
        None,
        0.15,
    ]


def test_cross_process_ab_refuses_an_unknown_variant(capsys):
    from benchmarks.experiments.cross_process import main

    with pytest.raises(SystemExit) as exit_:
        main(["--variants", "bare,pipline"])
    assert exit_.value.code == 2 and "unknown variants ['pipline']" in capsys.readouterr().err


def test_an_experiment_that_fails_does_not_end_the_run(capsys):
    """A full run is half an hour: one experiment's error is kept, the others' figures are not lost."""
    from benchmarks.run import Experiments

    r: dict = {}
    measure = Experiments(r)

    def hub_did_not_start():
        raise TimeoutError("the hub did not answer")

    assert measure("learners", hub_did_not_start) is False
    assert measure("startup", lambda: {"median_s": 0.9}) is True
    assert measure("pipeline", lambda: {"pipeline": {"a": 1}, "bare": {"a": 2}}, merge=True) is True
    assert r["startup"] == {"median_s": 0.9} and r["pipeline"] == {"a": 1} and r["bare"] == {"a": 2}
    assert "learners" not in r and "TimeoutError: the hub did not answer" in r["failed"]["learners"]
    assert "learners: the experiment FAILED" in capsys.readouterr().err

    def interrupted():
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):  # Ctrl-C still stops the run
        measure("scale", interrupted)


def test_a_failed_experiments_targets_read_n_a_and_fail():
    from benchmarks.targets import LEARNERS_TARGETS, TARGETS, targets

    run = {"failed": {"learners": "Traceback ...\nTimeoutError"}}
    rows = targets(run)
    learners = [t.label for t in LEARNERS_TARGETS]
    assert [row["target"] for row in rows if row["target"] in learners] == learners  # failed: in the table
    assert all(row["measured"] == "n/a" and not row["pass"] for row in rows)  # nothing else was measured either
    assert {row["target"] for row in rows} == {t.label for t in TARGETS if t.needs in (None, "learners")}
    with pytest.raises(KeyError):  # no experiment failed: a missing figure is a bug, not an n/a
        targets({})
    quick = targets({"quick": True})  # a smoke test's run lacks sizes on purpose: n/a, fails
    assert quick and all(row["measured"] == "n/a" and not row["pass"] for row in quick)


def test_a_gpu_only_target_reads_n_a_without_a_gpu_and_is_held_with_one():
    from benchmarks.report import verdict
    from benchmarks.targets import BROWSER_TARGETS, GPU_ONLY

    gpu_only = [t for t in BROWSER_TARGETS if t.gpu_only]
    assert len(gpu_only) == len(GPU_ONLY) and all("ms (two 60 Hz frames)" in t.label for t in gpu_only)
    case = {"tutorial": {"publish_to_drawn": {"p99": 50.0}}, "bare": {"sent_to_drawn": {"p99": 451.0}}}
    run = {"browser": dict.fromkeys(GPU_ONLY, case)}
    for t in gpu_only:
        row = t.row(run)  # no GPU: not held, not a miss
        assert row["pass"] is None and row["measured"].startswith("n/a: no GPU"), row
        assert t.row({**run, "gpu": "/dev/dri/renderD128"})["pass"] is False  # with one: 50 ms misses 33.3 ms
    assert verdict(None) == "n/a" and verdict(False) == "**FAIL**" and verdict(True) == "pass"
    # the same cases' ratio to the bare page is held without a GPU (50 ms against 451 ms: met)
    ratios = [t for t in BROWSER_TARGETS if not t.gpu_only and "x the bare page" in t.label and "arm" in t.label]
    assert len(ratios) == 1 and ratios[0].row(run)["pass"] is True


@pytest.mark.more  # a smoke test of one experiment's processes: make bench runs it in full
def test_round_trips_times_both_targets_and_stops_their_processes():
    import psutil

    from benchmarks.experiments.round_trips import measure

    before = {p.pid for p in psutil.Process().children(recursive=True)}
    figures = measure(calls=5, rounds=1)
    assert figures["calls"] == 5
    for kind in ("service", "parameter_set"):
        assert figures[kind]["tutorial_ms"]["n"] == 5 and figures[kind]["bare_ms"]["n"] == 5
        assert 0 < figures[kind]["tutorial_ms"]["p50"] < 1000 and figures[kind]["p50_ratio"] > 0
    assert {p.pid for p in psutil.Process().children(recursive=True)} <= before  # the tank and the bare node ended
