"""The benchmark suite's bookkeeping: plots reach the book only through make bench-figures; late-join targets."""

from __future__ import annotations

import json

import pytest

from benchmarks import publish
from benchmarks.experiments.late_join import summary
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

    def one(n, rtf, age_p99, mb):
        return {
            "real_time_factor": [rtf] * n, "real_time_factor_min": rtf, "age_ms_p99_max": age_p99,
            "age_ms_pooled": {"p50": age_p99 / 3}, "memory_mb_per_learner_mean": mb, "cores_busy": 0.25 * n,
            "cores_by_role": {"kernels": 0.16 * n, "learners' servers": 0.05 * n},
        }  # fmt: skip

    run = {"machine": {"cpus": 2}, "when": "now", "learners": {"1": one(1, 1.0, 0.8, 277), "8": one(8, 1.0, 1.5, 232)}}
    rtf, age, memory = (t.row(run) for t in LEARNERS_TARGETS)
    assert rtf["pass"] and age["pass"] and memory["pass"] and age["measured"] == "1.5 ms"
    run["learners"]["8"] = one(8, 0.98, 1.7, 1100)  # behind real time, ages past 2 x 0.8 ms, over 1 GiB
    assert not any(t.row(run)["pass"] for t in LEARNERS_TARGETS)
    assert [t.row({}) for t in LEARNERS_TARGETS if t.needs is None or {}.get(t.needs)] == []  # not run: left out
    path = plot_learners(run, tmp_path / "bench_learners.png")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
