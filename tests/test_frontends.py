"""A live view in the Jupyter front ends the README names, each in a real browser (``make test-lab``).

The README names JupyterLab, Notebook 7, VS Code and Colab.  Here, with
the demo joystick driving, Step 2's notebook (its view, then a cell that
keeps the kernel busy, as a scripted drive does) runs with Run All in:

- **Notebook 7** (``jupyter notebook``): the view draws within 2 s of its
  output appearing and moves while the busy cell runs;
- **JupyterLab as Colab runs it**: no nodelay server extension (the kernel's
  WebSocket keeps Nagle's algorithm) and Jupyter's default IOPub limits.
  The view draws and moves as above, keeps at least 20 frames/s, and the
  page never says "IOPub message rate exceeded".

JupyterLab with the extension is ``tests/test_network_lab.py``'s and
``tests/test_jupyterlab.py``'s.  VS Code and Colab cannot run here: the
README says so.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.jupyterlab import WITHOUT_NODELAY, JupyterLab, browser
from tests.lab_browser import (
    STATS,
    VIEW,
    WATCH_VIEWS,
    moving,
    run_all_cells,
    step2_notebook,
    views_slow_to_draw,
    wait_for,
)

pytestmark = [pytest.mark.browser, pytest.mark.slow]

ROOT = Path(__file__).resolve().parents[1]
BUSY_S = 12


@pytest.fixture
def joystick():
    proc = subprocess.Popen(
        [sys.executable, "-m", "tutorial.tools.rtt_joy", "--demo"],
        env=dict(os.environ, PYTHONPATH=str(ROOT)),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    yield proc
    proc.terminate()
    proc.wait(10)


def run_all_with_a_busy_cell(app: str, tmp_path: Path, server_args=()) -> dict:
    """Step 2's notebook, Run All, in ``app`` ("lab" or "notebook"); what the page showed while the busy cell ran."""
    step2_notebook(tmp_path / "step2.ipynb", f"rtt_{app}", busy_s=BUSY_S)
    out: dict = {}
    env = {"PYTHONPATH": str(ROOT), "RTT_TEST_MODE": None}  # a run lasts until the kernel stops, as for a learner
    with JupyterLab(tmp_path, env=env, server_args=server_args, app=app) as lab, browser(1100, 900) as page:
        page.goto(lab.notebook_url("step2.ipynb", workspace="frontends"))
        page.locator(".jp-Notebook .jp-Cell").first.wait_for(timeout=90_000)
        page.evaluate(WATCH_VIEWS)
        run_all_cells(page)
        wait_for(page, lambda: page.locator(VIEW).count() > 0, "the view's output", 120)
        shown = time.monotonic()
        wait_for(page, lambda: (page.evaluate(STATS) or {}).get("scenes"), "the view's scene", 30)
        out["first_picture_s"] = round(time.monotonic() - shown, 2)
        wait_for(page, lambda: moving(page), "the view moving while a cell runs", 10)  # raises if it does not
        f0, t0 = page.evaluate(STATS)["frames"], time.monotonic()
        page.wait_for_timeout(3000)
        out["fps_busy"] = round((page.evaluate(STATS)["frames"] - f0) / (time.monotonic() - t0), 1)
        busy_prompt = page.locator(".jp-Notebook .jp-Cell").nth(1).locator(".jp-InputPrompt")
        out["busy_still"] = "[*]" in busy_prompt.inner_text()
        times, now = page.evaluate("[window.rttViewTimes, performance.now()]")
        out["slow_views"] = views_slow_to_draw(times, now)
        out["iopub_limit_hit"] = page.get_by_text("IOPub message rate exceeded").count() > 0
        out["dropped"] = page.evaluate(STATS)["dropped"]
        lab.note_processes()
    print(f"{app} {' '.join(server_args)}: {out}")
    return out


def check(got: dict) -> None:
    assert got["busy_still"], f"the busy cell ended before the view was measured: {got}"
    assert got["first_picture_s"] < 2, f"the view's first picture came {got['first_picture_s']} s after its output"
    assert not got["slow_views"], got["slow_views"]
    assert got["dropped"] == 0, f"the view dropped frames: {got}"


def test_notebook_7_draws_the_view_while_a_cell_runs(tmp_path, joystick):
    check(run_all_with_a_busy_cell("notebook", tmp_path))


def test_jupyterlab_as_colab_runs_it_draws_at_20_frames_a_second_within_the_iopub_limits(tmp_path, joystick):
    got = run_all_with_a_busy_cell("lab", tmp_path, WITHOUT_NODELAY)
    check(got)
    assert got["fps_busy"] >= 20, f"the view drew {got['fps_busy']} frames/s without the nodelay extension"
    assert not got["iopub_limit_hit"], "the page says the IOPub message rate was exceeded"
