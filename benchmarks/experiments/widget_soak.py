"""A live view whose page is gone: does anything grow in the kernel?  Its memory over minutes.

    python -m benchmarks.experiments.widget_soak [--minutes 10]

JupyterLab runs a notebook that starts Step 2 with its live view while the
demo joystick drives the tank.  Chromium opens it, waits until the view
draws, and then closes (the learner closed the tab).  The run goes on
drawing into its widget for ``--minutes``, and the kernel's resident memory
is read every 15 s.  The baseline is the same kernel in the same run: its
memory in the first minute after the page closed.  Printed: the samples,
the growth from the first minute to the end, and the slope over the second
half (MB per minute).
"""

from __future__ import annotations

import argparse
import json
import os
import random
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import psutil

ROOT = Path(__file__).resolve().parents[2]


def soak(minutes: float, every_s: float = 15.0) -> dict:
    from playwright.sync_api import sync_playwright

    from tests.jupyterlab import CHROMIUM, CHROMIUM_FLAGS, JupyterLab
    from tests.lab_browser import STATS, run_first_cell, step2_notebook

    with tempfile.TemporaryDirectory() as d:
        step2_notebook(Path(d) / "soak.ipynb")
        joystick = subprocess.Popen(
            [sys.executable, "-m", "tutorial.tools.rtt_joy", "--demo"],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        try:
            with JupyterLab(Path(d), env={"PYTHONPATH": str(ROOT), "RTT_TEST_MODE": None}) as lab:
                with sync_playwright() as pw:
                    browser = pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_FLAGS)
                    page = browser.new_page(viewport={"width": 1000, "height": 800})
                    run_first_cell(page, lab.notebook_url("soak.ipynb", workspace="soak"))
                    page.wait_for_function(
                        f"(() => {{ const s = ({STATS})(); return s && s.frames > 60; }})()", timeout=90_000
                    )
                    frames = page.evaluate(STATS)
                    browser.close()  # the tab is gone
                lab.note_processes()
                kernels = [
                    p
                    for p in psutil.Process(lab.proc.pid).children(recursive=True)
                    if "ipykernel" in " ".join(p.cmdline())
                ]
                kernel = kernels[0]
                t0 = time.monotonic()
                samples = []
                while time.monotonic() - t0 < minutes * 60:
                    samples.append((round(time.monotonic() - t0, 1), kernel.memory_info().rss))
                    time.sleep(every_s)  # sampling, not synchronisation
                samples.append((round(time.monotonic() - t0, 1), kernel.memory_info().rss))
        finally:
            joystick.kill()
            joystick.wait(10)
    t = np.array([s[0] for s in samples]) / 60.0
    mb = np.array([s[1] for s in samples]) / 2**20
    first_minute = mb[t <= 1.0]
    half = t >= t[-1] / 2
    slope = float(np.polyfit(t[half], mb[half], 1)[0]) if half.sum() > 2 else None
    return {
        "minutes": round(float(t[-1]), 2),
        "frames_drawn_before_close": frames["frames"],
        "rss_mb_first_minute": round(float(first_minute.mean()), 1),
        "rss_mb_end": round(float(mb[-1]), 1),
        "growth_mb": round(float(mb[-1] - first_minute.mean()), 1),
        "slope_mb_per_min_second_half": None if slope is None else round(slope, 3),
        "samples_mb": [round(float(x), 1) for x in mb],
    }


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--minutes", type=float, default=10.0)
    args = p.parse_args(argv)
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 100)))
    print(json.dumps(soak(args.minutes), indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
