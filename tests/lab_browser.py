"""A learner's browser, as a program: open a notebook in JupyterLab, run it, and measure its live 3D view.

``python -m tests.lab_browser URL HOST`` runs headless Chromium (it may
load nothing but ``HOST``: the test's JupyterLab), opens ``URL`` (a notebook
whose first cell starts a run with a live view and shows it, and whose
second cell is trivial), runs the first cell and then checks, printing one
JSON line of what it measured:

- ``moved``: the view draws, and its picture changes while the run drives
  (the pixels that changed between two screenshots 1 s apart);
- ``fps``: frames the view drew from the kernel per second, over 3 s;
- ``cell_ms``: how long the trivial cell took, from Shift+Enter to its
  output, five times (while the view is live);
- ``reload_s``: after saving and reloading the page, the seconds from the
  reload to the view having its scene again (``scene_after_view_s``: from
  the view's output being back in the page, JupyterLab's own loading left
  out), and ``moved_after``: that it moves again.

tests/test_network_lab.py runs it on a host of its own (tests/netns.py),
so the browser reaches the kernel only through Jupyter's port.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

from tests.jupyterlab import browser

VIEW = "iframe.rtt-live-view"
STATS = f"() => {{ const f = document.querySelector('{VIEW}'); return f && f.parentElement.rttView || null; }}"


def step2_notebook(path: Path, node: str = "rtt") -> None:
    """Write the notebook this program runs: Step 2 with its live view (node ``node``), then a trivial cell."""
    import nbformat

    nb = nbformat.v4.new_notebook()
    nb.cells = [
        nbformat.v4.new_code_cell(
            "from tutorial.notebook.runs import BackgroundApp, load\n"
            "from tutorial.notebook.session import init_ros\n\n"
            "init_ros()\n"
            f'sim = BackgroundApp(load("step2.yaml"), node_name="{node}", label="simulation /{node}").start()\n'
            "sim.show(height=320)"
        ),
        nbformat.v4.new_code_cell("1 + 1"),
    ]
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    nbformat.write(nb, path)


def screenshot(page) -> np.ndarray:
    from io import BytesIO

    from PIL import Image

    return np.asarray(Image.open(BytesIO(page.locator(VIEW).first.screenshot())).convert("L")).astype(int)


def wait_for(page, predicate, what: str, most: float):
    deadline = time.monotonic() + most
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        page.wait_for_timeout(100)
    raise TimeoutError(f"{what}: not within {most:.0f} s")


def changed(page) -> int:
    before = screenshot(page)
    page.wait_for_timeout(1000)
    return int((np.abs(screenshot(page) - before) > 24).sum())


def moving(page) -> int:
    """The pixels that changed in 1 s, if over 200 (the tank driving), else 0."""
    n = changed(page)
    return n if n > 200 else 0


def run_first_cell(page, url: str, most_s: float = 90.0) -> None:
    """Open the notebook at ``url`` in JupyterLab, wait until its kernel is idle, and run its first cell.

    Raises:
        playwright's TimeoutError: the notebook or its kernel was not ready within ``most_s`` s.
    """
    page.goto(url)
    cells = page.locator(".jp-Notebook .jp-Cell")
    cells.first.wait_for(timeout=most_s * 1000)
    page.wait_for_function(
        "document.querySelector('#jp-main-statusbar').innerText.includes('Idle')", timeout=most_s * 1000
    )
    cells.first.click()
    page.keyboard.press("Control+Enter")


def main(url: str, host: str) -> None:
    out: dict = {}
    with browser(width=1100, height=900, host=host) as page:
        run_first_cell(page, url)
        cells = page.locator(".jp-Notebook .jp-Cell")
        wait_for(page, lambda: (page.evaluate(STATS) or {}).get("scenes"), "the live view's scene", 90)
        wait_for(page, lambda: (page.evaluate(STATS) or {}).get("frames", 0) > 10, "frames in the view", 60)
        out["moved"] = wait_for(page, lambda: moving(page), "the view moving", 30)
        f0, t0 = page.evaluate(STATS)["frames"], time.monotonic()
        page.wait_for_timeout(3000)
        out["fps"] = round((page.evaluate(STATS)["frames"] - f0) / (time.monotonic() - t0), 1)
        out["cell_ms"] = []
        trivial = cells.nth(1)
        for k in range(5):
            trivial.click()
            start = time.monotonic()
            page.keyboard.press("Control+Enter")
            wait_for(page, lambda k=k: f"[{k + 2}]" in trivial.locator(".jp-InputPrompt").inner_text(), "the cell", 30)
            out["cell_ms"].append(round(1000 * (time.monotonic() - start)))
        page.keyboard.press("Control+s")
        page.wait_for_timeout(1000)  # saved: JupyterLab has no event for it a page can wait on
        start = time.monotonic()
        page.reload()
        wait_for(page, lambda: page.locator(VIEW).count() > 0, "the view's page after a reload", 60)
        shown = time.monotonic()
        wait_for(page, lambda: (page.evaluate(STATS) or {}).get("scenes"), "the scene after a reload", 60)
        out["reload_s"] = round(time.monotonic() - start, 2)
        out["scene_after_view_s"] = round(time.monotonic() - shown, 2)  # JupyterLab's own loading left out
        out["moved_after"] = wait_for(page, lambda: moving(page), "moving after reload", 30)
        out["dropped"] = page.evaluate(STATS)["dropped"]
    print(json.dumps(out), flush=True)


if __name__ == "__main__":
    main(*sys.argv[1:3])
