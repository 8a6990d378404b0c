"""The statistics the figures are made of: percentiles, paired ratios, a bootstrap interval of a median."""

from __future__ import annotations

import numpy as np

from benchmarks.procs import in_thread


def pct(values, scale=1.0) -> dict:
    """p50/p90/p99/max of ``values`` times ``scale``, rounded (empty: None)."""
    if len(values) == 0:
        return {"n": 0, "p50": None, "p90": None, "p99": None, "max": None}
    a = np.asarray(values, dtype=float) * scale
    return {
        "n": int(a.size),
        "p50": round(float(np.percentile(a, 50)), 3),
        "p90": round(float(np.percentile(a, 90)), 3),
        "p99": round(float(np.percentile(a, 99)), 3),
        "max": round(float(a.max()), 3),
    }


def interleaved_ratios(run, bare, more) -> tuple[list[float], list[float], list[float]]:
    """Time ``run()`` between bare runs (``bare()`` on a thread of its own) while ``more(pairs so far)``.

    Each ``run()`` (steps/s) is divided by the mean of the bare runs on
    either side; a bare run is shared by the pairs before and after it, so
    a drift of the machine's speed over seconds cancels out.

    Returns:
        (ratios, the run() speeds, the bare speeds: two per pair).
    """
    ratios, speeds, bares = [], [], []
    before = in_thread(bare)
    while more(len(ratios)):
        speed = run()
        after = in_thread(bare)
        ratios.append(speed / ((before + after) / 2))
        speeds.append(speed)
        bares += [before, after]
        before = after
    return ratios, speeds, bares


def median_ci95(values, resamples: int = 2000) -> tuple[float, float]:
    """Bootstrap 95 % confidence interval of the median of ``values`` (a fixed seed: the same data, the same answer).

    It resamples single values, so it covers the scatter among them and
    nothing that moves them all together: the simulation-speed pairs of one
    run share the machine's state of that half minute, and two runs'
    intervals need not overlap (set F's first and third did not).
    """
    x = np.asarray(values, dtype=float)
    rng = np.random.default_rng(0)
    medians = np.median(x[rng.integers(0, x.size, size=(resamples, x.size))], axis=1)
    lo, hi = np.percentile(medians, [2.5, 97.5])
    return float(lo), float(hi)
