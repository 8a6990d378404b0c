"""Start-up: seconds from the launch command to the first state the viewer shows."""

from __future__ import annotations

import signal
import statistics
import subprocess
import sys
import time

from benchmarks.paths import ROOT


def startup(repeats: int) -> dict:
    """Seconds from starting ``launch_py/step3_launch.py --demo`` to the viewer's first applied state."""
    times = []
    for _ in range(repeats):
        t0 = time.monotonic()
        proc = subprocess.Popen(
            [sys.executable, "-u", str(ROOT / "launch_py" / "step3_launch.py"), "--demo"],
            cwd=ROOT,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        first = None
        deadline = t0 + 60
        for line in proc.stdout:
            if line.startswith("[rtt_viewer]") and "first joint state" in line:
                first = time.monotonic() - t0
                break
            if time.monotonic() > deadline:
                break
        proc.send_signal(signal.SIGINT)
        try:
            proc.communicate(timeout=20)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.communicate()
        if first is None:
            raise RuntimeError("the viewer showed no state within 60 s of the launch")
        times.append(first)
    return {"first_state_s": [round(t, 3) for t in times], "median_s": round(statistics.median(times), 3)}
