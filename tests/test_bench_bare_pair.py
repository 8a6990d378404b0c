"""The bare rclpy pair's hand-off variant (the A/B of ``benchmarks.experiments.cross_process``), as processes."""

from __future__ import annotations

import subprocess
import sys

import pytest

from benchmarks.experiments.cross_process import bare_pair_run
from benchmarks.paths import ROOT

pytestmark = pytest.mark.cross_process


def test_bare_pair_with_the_hand_off_notes_every_state_on_its_main_thread():
    """The A/B's ``bare_hand_off`` variant: the states arrive through the SpinThread and the hand-off."""
    run = bare_pair_run(rate=200.0, seconds=2.0, warmup=0.2, joints=2, hand_off=True)
    assert run["received"] >= 200, run["received"]  # about 400 sent; discovery may eat the first ones
    assert len(run["latency"]) > 0 and min(run["latency"]) > 0  # noted after the stamp, on this host's clock


def test_bare_pair_refuses_the_hand_off_where_it_means_nothing():
    for args in (["pub", "--hand-off"], ["sub", "--hand-off", "--executor", "events"]):
        done = subprocess.run(
            [sys.executable, "-m", "benchmarks.bare_pair", *args], cwd=ROOT, capture_output=True, text=True, timeout=60
        )
        assert done.returncode == 2 and "--hand-off is for the sub role" in done.stderr, done.stderr
