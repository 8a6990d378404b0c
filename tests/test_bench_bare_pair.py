"""The bare rclpy pair's hand-off variant (the A/B of ``benchmarks.experiments.cross_process``), as processes."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from benchmarks.paths import ROOT
from benchmarks.procs import finish, py, start

pytestmark = pytest.mark.cross_process


def test_bare_pair_with_the_hand_off_notes_every_state_on_its_main_thread(tmp_path):
    """The A/B's ``bare_hand_off`` variant: the states arrive through the SpinThread and the hand-off."""
    probe = tmp_path / "bare.json"
    sub, pub = start(py("benchmarks.bare_pair", "sub", "--duration", "4", "--hand-off"), probe), None
    try:
        pub = start(py("benchmarks.bare_pair", "pub", "--rate", "200.0", "--duration", "2.5"))
        finish(pub, 30)
        finish(sub, 30)
    finally:
        for proc in (sub, pub):
            if proc is not None and proc.poll() is None:
                proc.kill()
                proc.wait(10)
    received = json.loads(probe.read_text())["received"]
    assert len(received) >= 200, len(received)  # 500 sent; discovery may eat the first ones
    assert all(noted > stamp for stamp, noted in received)  # noted after the stamp, on this host's clock
    stamps = [stamp for stamp, _ in received]
    assert stamps == sorted(set(stamps))  # in order, none twice (the hand-off may drop a state, never repeat one)


def test_bare_pair_refuses_the_hand_off_where_it_means_nothing():
    for args in (["pub", "--hand-off"], ["sub", "--hand-off", "--executor", "events"]):
        done = subprocess.run(
            [sys.executable, "-m", "benchmarks.bare_pair", *args], cwd=ROOT, capture_output=True, text=True, timeout=60
        )
        assert done.returncode == 2 and "--hand-off is for the sub role" in done.stderr, done.stderr
