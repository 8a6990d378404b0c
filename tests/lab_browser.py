"""A learner's browser, as a program: open a notebook in JupyterLab, run it, and measure its live 3D view.

``python -m tests.lab_browser URL HOST [BUSY_S]`` runs headless Chromium (it may
load nothing but ``HOST``: the test's JupyterLab), opens ``URL`` (a notebook
whose first cell starts a run with a live view and shows it, and whose
last cell is trivial), runs the first cell and then checks, printing one
JSON line of what it measured:

- with ``BUSY_S`` (a notebook of :func:`step2_notebook` with that ``busy_s``), it
  runs all cells instead, and while the busy cell runs measures
  ``first_picture_s`` (from the view's output appearing to its scene
  drawn), ``moved_busy`` and ``fps_busy``, then reloads the page and
  measures ``reload_busy_s`` (from the reload to the scene;
  ``scene_after_view_busy_s``: from the view's output being back),
  ``moved_after_busy``, and whether the scene and the moving came before
  the cell ended (``reload_busy_before_end``); then the
  below, once the kernel is idle, but the reload (the page has had one);

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
import re
import sys
import time
from pathlib import Path

import numpy as np

from tests.jupyterlab import browser

VIEW = "iframe.rtt-live-view"
STATS = f"() => {{ const f = document.querySelector('{VIEW}'); return f && f.parentElement.rttView || null; }}"


# From now on, each live view on the page gets a record in window.rttViewTimes (by its id): its label, when
# its output appeared, when it had its first scene from the kernel (drawn), and when it left the page; ms on
# the page's clock (performance.now()), polled every 50 ms.
WATCH_VIEWS = """() => {
    if (window.rttViewWatch) clearInterval(window.rttViewWatch);
    window.rttViewTimes = {};
    window.rttViewWatch = setInterval(() => {
        const now = performance.now(), seen = new Set();
        for (const f of document.querySelectorAll('iframe.rtt-live-view')) {
            const v = f.parentElement.rttView;
            if (!v) continue;
            seen.add(v.id);
            const t = window.rttViewTimes[v.id] ||
                (window.rttViewTimes[v.id] = {label: f.title, appeared: now, drawn: null, gone: null});
            if (t.drawn === null && v.scenes > 0) t.drawn = now;
        }
        for (const [id, t] of Object.entries(window.rttViewTimes)) if (!seen.has(id) && t.gone === null) t.gone = now;
    }, 50);
}"""


def views_slow_to_draw(times: dict, now: float, most_ms: float = 2000.0) -> list[str]:
    """The views of ``window.rttViewTimes`` that had no scene within ``most_ms`` of their output appearing,
    as of ``now`` (the page's ``performance.now()``); one that left the page sooner, undrawn, had no time to."""
    slow = []
    for t in times.values():
        end = next((x for x in (t["drawn"], t["gone"]) if x is not None), now)
        if end - t["appeared"] > most_ms:
            what = "its scene" if t["drawn"] is not None else "gone, undrawn," if t["gone"] is not None else "undrawn"
            slow.append(f"{t['label']}: {what} {end - t['appeared']:.0f} ms after its output appeared")
    return slow


def step2_notebook(path: Path, node: str = "rtt", busy_s: float = 0.0) -> None:
    """Write the notebook this program runs: Step 2 with its live view (node ``node``), a cell that keeps the
    kernel busy ``busy_s`` s if that is not 0 (standing in for a scripted drive), then a trivial cell."""
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
        *([nbformat.v4.new_code_cell(f"import time\n\ntime.sleep({busy_s})")] if busy_s else []),
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


def run_first_cell(page, url: str, most_s: float = 90.0, run_all: bool = False) -> None:
    """Open the notebook at ``url`` in JupyterLab, wait until its kernel is idle, and run its first cell
    (every cell, with ``run_all``, as the Run menu's Run All Cells).

    Raises:
        playwright's TimeoutError: the notebook or its kernel was not ready within ``most_s`` s.
    """
    page.goto(url)
    cells = page.locator(".jp-Notebook .jp-Cell")
    cells.first.wait_for(timeout=most_s * 1000)
    page.wait_for_function(
        "document.querySelector('#jp-main-statusbar').innerText.includes('Idle')", timeout=most_s * 1000
    )
    if run_all:
        run_all_cells(page)
        return
    kernel_ready(page, most_s)
    run_cell(page, cells.first, lambda: page.keyboard.press("Control+Enter"))


# The page's notebook has a kernel, started and idle, by the server's own word (JupyterLab's and Notebook 7's
# indicators read idle before a kernel exists, and Run All then asks which kernel to start).
# The server's base URL is the page's own (a hub's learner: /user/<name>/).
KERNEL_READY = """async () => {
    const config = document.getElementById('jupyter-config-data');
    const base = (config && JSON.parse(config.textContent).baseUrl) || '/';
    const xsrf = (document.cookie.match(/(?:^|; )_xsrf=([^;]*)/) || [])[1];  // a hub's server asks for it
    const headers = xsrf ? {'X-XSRFToken': decodeURIComponent(xsrf)} : {};
    const answer = await fetch(base + 'api/sessions', {credentials: 'same-origin', headers});
    if (!answer.ok) throw new Error(`${base}api/sessions: ${answer.status} ${await answer.text()}`);
    const sessions = await answer.json();
    return sessions.some(s => s.kernel && s.kernel.execution_state === 'idle');
}"""


def kernel_ready(page, most: float = 90.0) -> None:
    """Wait until the server has a session whose kernel is idle (the page's notebook's: the tests open one)."""
    wait_for(page, lambda: page.evaluate(KERNEL_READY), "the notebook's kernel", most)


def run_menu(page, item: str) -> None:
    """Run > ``item`` (e.g. "Run All Cells") from JupyterLab's or Notebook 7's menu bar."""
    page.locator(".lm-MenuBar-itemLabel", has_text="Run").first.click()
    page.locator(".lm-Menu-itemLabel", has_text=item).first.click()


def run_cell(page, cell, run, tries: int = 3) -> None:
    """Select ``cell`` (a locator) and ``run()`` (a keystroke, a menu item); again, up to ``tries`` times,
    10 s apart, until its prompt changes (a page that has just loaded may drop a keystroke or a click).

    Raises:
        TimeoutError: its prompt had not changed after ``tries`` tries.
    """
    prompt = cell.locator(".jp-InputPrompt")
    before = prompt.inner_text()
    for _ in range(tries):
        cell.locator(".jp-InputArea-editor").click()
        run()
        try:
            wait_for(page, lambda: prompt.inner_text() != before, "the cell to start", 10)
            return
        except TimeoutError:
            page.keyboard.press("Escape")  # a menu left open
    raise TimeoutError(f"the cell did not start after {tries} tries: its prompt stayed {before!r}")


def run_all_cells(page) -> None:
    """Run > Run All Cells once the notebook's kernel is ready, until the first cell has started.

    Raises:
        TimeoutError: the first cell had not started after three tries.
    """
    kernel_ready(page)
    run_cell(page, page.locator(".jp-Notebook .jp-Cell").first, lambda: run_menu(page, "Run All Cells"))


def while_busy(page, out: dict, busy_s: float) -> None:
    """Run All has begun: the view draws and moves while the busy cell (``busy_s`` s) runs, and after a reload in it."""
    cells = page.locator(".jp-Notebook .jp-Cell")
    busy = cells.nth(1).locator(".jp-InputPrompt")
    wait_for(page, lambda: page.locator(VIEW).count() > 0, "the live view's output", 90)
    shown = time.monotonic()
    wait_for(page, lambda: (page.evaluate(STATS) or {}).get("scenes"), "the live view's scene while a cell runs", 60)
    out["first_picture_s"] = round(time.monotonic() - shown, 2)
    out["moved_busy"] = wait_for(page, lambda: moving(page), "the view moving while a cell runs", 10)
    f0, t0 = page.evaluate(STATS)["frames"], time.monotonic()
    page.wait_for_timeout(2000)
    out["fps_busy"] = round((page.evaluate(STATS)["frames"] - f0) / (time.monotonic() - t0), 1)
    assert "[*]" in busy.inner_text(), "the busy cell ended before the view was measured: make it longer"
    page.keyboard.press("Control+s")  # the view's output is in the file the reload opens
    page.wait_for_timeout(1000)  # saved: JupyterLab has no event for it a page can wait on
    start = time.monotonic()
    page.reload()
    wait_for(page, lambda: page.locator(VIEW).count() > 0, "the view's output after a reload in a busy cell", 60)
    back = time.monotonic()
    wait_for(page, lambda: (page.evaluate(STATS) or {}).get("scenes"), "the scene after a reload in a busy cell", 60)
    out["reload_busy_s"] = round(time.monotonic() - start, 2)
    out["scene_after_view_busy_s"] = round(time.monotonic() - back, 2)  # JupyterLab's own loading left out
    out["moved_after_busy"] = wait_for(page, lambda: moving(page), "moving after a reload in a busy cell", 10)
    out["moved_after_busy_s"] = round(time.monotonic() - start, 2)  # from the reload: seen moving (1 s of it)
    # the busy cell began as the view's output came (the cell before it ends with it): what it had left then
    out["busy_left_at_reload_s"] = round(busy_s - (start - shown), 2)
    out["reload_busy_before_end"] = out["moved_after_busy_s"] < out["busy_left_at_reload_s"]  # scene, and moving
    # the busy cell's end: the trivial cell, run now, answers only after it (the kernel's indicator is no sign:
    # each of the view's messages says busy, then idle, from the views' subshell)
    trivial = page.locator(".jp-Notebook .jp-Cell").last
    trivial.click()
    page.keyboard.press("Control+Enter")
    answered = lambda: re.search(r"\[\d+\]", trivial.locator(".jp-InputPrompt").inner_text())  # noqa: E731
    wait_for(page, answered, "the busy cell's end", 60)


def main(url: str, host: str, busy: str = "") -> None:
    out: dict = {}
    with browser(width=1100, height=900, host=host) as page:
        run_first_cell(page, url, run_all=bool(busy))
        cells = page.locator(".jp-Notebook .jp-Cell")
        if busy:
            while_busy(page, out, float(busy))
        wait_for(page, lambda: (page.evaluate(STATS) or {}).get("scenes"), "the live view's scene", 90)
        wait_for(page, lambda: (page.evaluate(STATS) or {}).get("frames", 0) > 10, "frames in the view", 60)
        out["moved"] = wait_for(page, lambda: moving(page), "the view moving", 30)
        f0, t0 = page.evaluate(STATS)["frames"], time.monotonic()
        page.wait_for_timeout(3000)
        out["fps"] = round((page.evaluate(STATS)["frames"] - f0) / (time.monotonic() - t0), 1)
        out["cell_ms"] = []
        trivial = cells.last
        for _ in range(5):
            trivial.click()
            before = trivial.locator(".jp-InputPrompt").inner_text()
            start = time.monotonic()
            page.keyboard.press("Control+Enter")
            wait_for(
                page,
                lambda before=before: (p := trivial.locator(".jp-InputPrompt").inner_text()) != before and "*" not in p,
                "the cell",
                30,
            )
            out["cell_ms"].append(round(1000 * (time.monotonic() - start)))
        if not busy:  # (with busy, the page has been reloaded already, in the busy cell)
            reload_idle(page, out)
        out["dropped"] = page.evaluate(STATS)["dropped"]
    print(json.dumps(out), flush=True)


def reload_idle(page, out: dict) -> None:
    """Save, reload the page with the kernel idle, and time the view's scene coming back; it moves again."""
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


if __name__ == "__main__":
    main(*sys.argv[1:4])
