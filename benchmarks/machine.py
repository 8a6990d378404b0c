"""The machine's state beside a run's verdicts: a probe taken at the start and at the end of ``make bench``.

A ratio to a same-run baseline cancels most of a machine's mood, not all of
it: on a busy or throttled machine the two sides of a comparison do not slow
down alike.  So each run records how fast this machine was when it started
and when it ended: bare ``mj_step`` steps per second on the tank (one core,
no ROS), the load average, and the other processes' CPU meanwhile.  Two runs'
verdicts can then be compared knowing whether the machine was the same.
"""

from __future__ import annotations

import os
import time

import mujoco
import psutil

from benchmarks.paths import ROOT


def probe(seconds: float = 2.0) -> dict:
    """``{"mj_step_per_s", "load_average", "others_cpu_cores", "when"}`` measured over ``seconds``.

    ``others_cpu_cores``: CPU used by every process but this one while the
    steps ran (cores); a busy neighbour shows there.
    """
    model = mujoco.MjModel.from_xml_path(str(ROOT / "model" / "tank.xml"))
    data = mujoco.MjData(model)
    me = psutil.Process()
    total0, mine0 = psutil.cpu_times(), me.cpu_times()
    steps, t0 = 0, time.perf_counter()
    while time.perf_counter() - t0 < seconds:
        for _ in range(200):
            mujoco.mj_step(model, data)
        steps += 200
    elapsed = time.perf_counter() - t0
    total1, mine1 = psutil.cpu_times(), me.cpu_times()
    busy = (total1.user + total1.system) - (total0.user + total0.system)
    mine = (mine1.user + mine1.system) - (mine0.user + mine0.system)
    return {
        "when": time.strftime("%Y-%m-%d %H:%M:%S"),
        "mj_step_per_s": round(steps / elapsed),
        "load_average": [round(x, 2) for x in os.getloadavg()],
        "others_cpu_cores": round(max(0.0, busy - mine) / elapsed, 2),
    }


def gpu() -> str | None:
    """The GPU the benchmarks' Chromium draws with, or None when it draws in software (SwiftShader).

    None when the machine has no render node (``/dev/dri/renderD*``) or the
    browser is launched with ``--disable-gpu`` (tests/jupyterlab.py's
    ``CHROMIUM_FLAGS``, as on this project's machines).
    """
    from pathlib import Path

    from tests.jupyterlab import CHROMIUM_FLAGS

    nodes = sorted(Path("/dev/dri").glob("renderD*")) if Path("/dev/dri").is_dir() else []
    if not nodes or "--disable-gpu" in CHROMIUM_FLAGS:
        return None
    return str(nodes[0])


if __name__ == "__main__":
    print(probe(), gpu())
