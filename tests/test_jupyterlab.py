"""The notebooks in JupyterLab, in a real browser: headless Chromium driven by Playwright.

What a learner does and sees, checked on the page itself:

* notebook 01 (``test_teleop_panel_drives_the_tank``): run it to the teleop
  panel, push the forward stick (``left V``) with the keyboard, and see in
  screenshots of the inline 3D view that the tank drives off.  Stop: the
  panel's line and the view's caption say "stopped", Start is offered and
  Stop is not, and the view keeps the run's last frame; Start: the same
  view follows the new run (the tank is back where it started).  The
  section's ``reset()`` turns the view into a recording of the tank and
  disables the panel, saying why.
* notebook 03 (``test_step3_views_side_by_side``): the simulation's and the
  viewer's live views are side by side in one output, both drawing the
  tank; turning the turret with the panel turns it in the viewer's view,
  another node's.  Kernel > Restart: the views say they are not live any
  more (a notice over their last frames, and the caption).
* the notebooks of ``IN_MAKE_TEST`` (``test_run_all``): the two above
  (03's in ``make test-more``, marked by ``MORE``);
  every notebook ``notebooks/[0-9][0-9]_*.ipynb`` with
  ``RTT_LAB_ALL=1`` (``make test-lab``).  Run All
  runs every cell once, in order, with no error output and no stderr
  output but the committed notebook's; every live view has its scene from
  the kernel within 2 s of its output appearing, while the notebook still
  runs (``tests/lab_browser.py``'s ``WATCH_VIEWS``); every 3D view draws the tank (never
  blank, never the browser's error page), in each of its panes; a caption
  says "live" only under a live page whose server answers, and a live page
  always has such a caption; and, the notebooks ending with ``reset()``,
  every panel is disabled, with a line saying why.  (nbval runs every
  notebook in ``make test``; Run All of all ten in JupyterLab took 140 to
  over 175 s of the suite on this 2-core machine, whose speed varies by
  half within an hour, and ``make test`` must stay under 10 minutes.)

JupyterLab serves a copy of the notebooks (the learner's files and Jupyter
settings are never touched), without ``RTT_TEST_MODE`` and with
``RTT_NETWORK_HOSTS=off`` (notebook 08 as a learner without root has it):
live runs last until ``reset()``, as for a learner, so the test drives them
at its own pace.  Two lanes run at once, each a JupyterLab server with its
own ROS_DOMAIN_ID and its own Chromium, taking the notebooks longest first:
the module stays within ``BUDGET`` on a shared 2-core machine.
Waits are polls with deadlines.  Servers, kernels (with their meshcat
servers) and browsers are stopped at the end, failed or not; the browsers
may load nothing but 127.0.0.1.  Screenshots stay in the test's tmp folder
(its path is in every failure; ``-s`` prints the log).
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import queue
import re
import shutil
import threading
import time
import traceback
import urllib.request
from datetime import datetime
from pathlib import Path

import numpy as np
import pytest

from conftest import ROOT

pytest.importorskip("playwright.sync_api", reason="playwright is not installed (pip install -e .[test])")
pytest.importorskip("psutil", reason="psutil is not installed (pip install -e .[test])")

from playwright.sync_api import Error as PlaywrightError  # noqa: E402
from playwright.sync_api import expect

from tests.lab_browser import WATCH_VIEWS, views_slow_to_draw  # noqa: E402

from jupyterlab import CHROMIUM, JupyterLab, browser  # noqa: E402 - after the skips

pytestmark = [
    pytest.mark.browser,
    pytest.mark.skipif(not Path(CHROMIUM).exists(), reason="chromium is not installed (make test installs it)"),
]

ALL = os.environ.get("RTT_LAB_ALL") == "1"  # make test-lab: every notebook
# the interactive ones (00: nbval, and make test-lab); make test runs 01's (the teleop panel), make test-more 03's
# (two views side by side): both are Run All in JupyterLab with a learner's part, as are the hub's and the
# network lab's live views in make test
IN_MAKE_TEST = {"01_step1_tank_controller", "03_step3_viewer"}
MORE = {"03_step3_viewer"}
NOTEBOOKS = sorted(n for n in (ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb") if ALL or n.stem in IN_MAKE_TEST)
# s, for the whole module: servers, browsers and its notebooks (all ten took 140 to over 175 s here)
BUDGET = 300.0 if ALL else 150.0
TEARDOWN = 15.0  # s of the budget kept for stopping the servers and browsers
LANES = 2
pytestmark.append(pytest.mark.timeout(BUDGET + 5))
TANK_PIXELS = 150  # olive pixels that say the tank is drawn (it covers 300 to 3000 in these views)
NO_PROXY = urllib.request.build_opener(urllib.request.ProxyHandler({}))  # 127.0.0.1 only, never a proxy
CELLS = ".jp-NotebookPanel:not(.lm-mod-hidden) .jp-Notebook .jp-Cell"  # one notebook is open at a time


# ---- pictures -----------------------------------------------------------------------------------------------
def picture(png: bytes) -> np.ndarray:
    """A PNG screenshot as an (H, W, 3) float array in 0..1."""
    import matplotlib.image

    return matplotlib.image.imread(io.BytesIO(png), format="png")[:, :, :3]


def olive(image: np.ndarray) -> np.ndarray:
    """Where the tank's olive paint is: green beats blue, as tests/browser.py's greenish_pixels
    counts, and dull (red above 0.15, green under 0.6; the paint is about 0.37, 0.44, 0.24): not
    the bright green of highlighted code or of a plot's line, which must never pass for the tank."""
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    return (g > b + 0.06) & (g >= r) & (r > 0.15) & (g < 0.6)


def tank_at(image: np.ndarray) -> tuple[float, float] | None:
    """Centre of the tank's olive pixels, (x, y) px, or None when the tank is not drawn."""
    ys, xs = np.nonzero(olive(image))
    return (float(xs.mean()), float(ys.mean())) if len(xs) >= TANK_PIXELS else None


def distance(a, b) -> float:
    return float(np.hypot(a[0] - b[0], a[1] - b[1]))


def changed_pixels(a: np.ndarray, b: np.ndarray) -> int:
    return int(np.count_nonzero(np.abs(a - b).max(axis=2) > 0.1))


# Whether all of an element is in sight in its scrolling box (the notebook): not under the toolbar or
# the status bar.
IN_SIGHT_JS = """e => {
    let box = e.parentElement;
    while (box && !(box.scrollHeight > box.clientHeight && getComputedStyle(box).overflowY !== 'visible')) {
        box = box.parentElement;
    }
    const r = e.getBoundingClientRect(), c = box ? box.getBoundingClientRect() : {top: 0, bottom: innerHeight};
    return r.top >= c.top - 0.5 && r.bottom <= c.bottom + 0.5;
}"""


# ---- a lane: one server, one browser page, the notebooks it takes ----------------------------------------------
class Lane:
    """One JupyterLab server and one page, on its thread; where screenshots go; the module's deadline."""

    def __init__(self, number: int, lab: JupyterLab, page, shots: Path, start: float, log: list, stop: threading.Event):
        self.number, self.lab, self.page, self.shots = number, lab, page, shots
        self.start, self.deadline, self.stop = start, start + BUDGET - TEARDOWN, stop
        self._log = log
        self.page_errors: list[str] = []
        self.count = 0  # cells the current kernel has run: its last execution count

    def page_error(self, error) -> None:
        """An uncaught error in the page: JupyterLab's or a recording's fails the notebook being checked.

        One in a live meshcat page (meshcat's own page, served by a run) is
        logged only: a page whose run closes while it loads fails to load
        meshcat's script, and is replaced by its recording at once.
        """
        where = re.search(r"(https?://[^\s)]+|about:srcdoc)", error.stack or "")
        source = where.group(1) if where else "?"
        line = f"{error.message} (at {source})"
        if source.startswith(self.lab.url) or source.startswith("about:") or source == "?":
            self.page_errors.append(line)
        else:
            self.log(f"an error in a live meshcat page, not ours: {line}")

    def log(self, what: str) -> None:
        line = f"[{time.monotonic() - self.start:6.1f} s] lane {self.number}: {what}"
        self._log.append(line)  # list.append is atomic: the lanes share the log
        print(line)

    def left(self, most: float) -> float:
        """Seconds a wait may take: at most ``most``, and never past the module's deadline."""
        left = self.deadline - time.monotonic()
        if left <= 0 or self.stop.is_set():
            raise AssertionError(f"over the module's budget of {BUDGET:.0f} s, or the test was stopped")
        return min(most, left)

    def ms(self, most: float) -> float:
        return self.left(most) * 1000

    def poll(self, what: str, probe, most: float, every: float = 0.2):
        """Call ``probe()`` until it returns something true; that value. Fails after ``most`` s."""
        deadline = time.monotonic() + self.left(most)
        while True:
            value = probe()
            if value:
                return value
            if time.monotonic() > deadline:
                raise AssertionError(f"{what}: not within {most:.0f} s (screenshots in {self.shots})")
            self.page.wait_for_timeout(every * 1000)  # the page keeps running while we wait

    def shot(self, locator, name: str) -> np.ndarray:
        """A screenshot of what ``locator`` covers on the page, saved as ``name``.png.

        Taken again until the element stood still while it was taken: the
        cells out of sight are laid out when they come into sight, so the
        page may shift under a screenshot, which would then show the wrong
        thing (code, a plot) where the element was.
        """

        def steady():
            locator.evaluate("e => e.scrollIntoView({block: 'center'})")
            box = locator.bounding_box(timeout=self.ms(30))
            if not box or min(box["width"], box["height"]) < 1:
                return None
            try:
                png = self.page.screenshot(clip=box, timeout=self.ms(30))
            except PlaywrightError:  # out of the page after all: the page moved
                return None
            # the page did not move while it was taken (JupyterLab scrolls too), and all of it was in sight
            return png if locator.bounding_box() == box and locator.evaluate(IN_SIGHT_JS) else None

        png = self.poll(f"a steady screenshot of {name}", steady, 20, every=0.1)
        (self.shots / f"{name}.png").write_bytes(png)
        return picture(png)

    def tank_in(self, locator, name: str, most: float = 30) -> tuple[np.ndarray, tuple[float, float]]:
        """Wait until ``locator``'s screenshot shows the tank; the picture and where the tank is."""
        found = {}

        def drawn():
            found["image"] = self.shot(locator, name)
            return tank_at(found["image"])

        at = self.poll(f"the tank drawn in {name}.png", drawn, most, every=0.1)
        return found["image"], at

    def still_tank(self, locator, name: str, most: float = 20) -> tuple[float, float]:
        """Wait until two screenshots in a row show the tank in the same place (within 1.5 px); where."""
        last = {}

        def still():
            _, at = self.tank_in(locator, name)
            before, last["at"] = last.get("at"), at
            return before is not None and distance(before, at) < 1.5 and at

        return self.poll(f"the tank standing still in {name}.png", still, most, every=0.3)


# ---- JupyterLab --------------------------------------------------------------------------------------------
def menu(lane: Lane, menu_name: str, command: str) -> None:
    lane.page.locator(".lm-MenuBar-item", has_text=menu_name).click(timeout=lane.ms(30))
    lane.page.locator(f"li[data-command='{command}']").click(timeout=lane.ms(30))


def open_notebook(lane: Lane, name: str) -> None:
    """Open ``name`` from the file browser, as a learner does, and wait for its kernel to be idle.

    The lane's first notebook loads JupyterLab, in a fresh workspace; the
    others open in the same page (loading JupyterLab costs seconds).
    """
    page = lane.page
    if not page.url.startswith(lane.lab.url):
        page.goto(f"{lane.lab.url}/lab/workspaces/rtt", timeout=lane.ms(60))
    page.locator(".jp-DirListing-itemText", has_text=name).dblclick(timeout=lane.ms(60))
    page.locator(".lm-TabBar-tab.jp-mod-current", has_text=name).wait_for(timeout=lane.ms(30))
    cells = len(json.loads((lane.lab.root / name).read_text())["cells"])
    lane.poll(f"{name}: its {cells} cells shown", lambda: page.locator(CELLS).count() == cells, 60)
    page.locator("#jp-main-statusbar").get_by_text("| Idle").wait_for(timeout=lane.ms(60))
    lane.count = 0  # a fresh kernel: each notebook is opened once, and its kernel shut down after
    lane.log(f"{name}: open, kernel idle")


def close_notebook(lane: Lane) -> None:
    """Shut the notebook's kernel down (its runs, nodes and meshcat servers with it) and close its tab."""
    out_of_sight(lane)
    lane.lab.note_processes()
    menu(lane, "Kernel", "kernelmenu:shutdown")  # it ends on its own time; the server's close() makes sure
    menu(lane, "File", "application:close")
    discard = lane.page.locator(".jp-Dialog-button", has_text="Discard")  # asked only if changed since saved

    def closed():
        if discard.is_visible():
            discard.click()
        return lane.page.locator(CELLS).count() == 0

    lane.poll("the notebook's tab closed", closed, 30)


def restart_kernel(lane: Lane) -> None:
    """Kernel > Restart Kernel, confirmed: a fresh kernel (nothing run yet)."""
    menu(lane, "Kernel", "kernelmenu:restart")
    lane.page.locator(".jp-Dialog-button.jp-mod-accept").click(timeout=lane.ms(30))
    status = lane.page.locator("#jp-main-statusbar")
    with contextlib.suppress(PlaywrightError):  # the old kernel's "Idle" first goes (unless it was quick)
        status.get_by_text("| Idle").wait_for(state="detached", timeout=lane.ms(5))
    status.get_by_text("| Idle").wait_for(timeout=lane.ms(60))
    lane.count = 0


def out_of_sight(lane: Lane) -> None:
    """Scroll to the notebook's first cell, its title: no 3D page in sight.

    A recording on screen plays its animation all the time, and in a
    browser drawing in software that takes a CPU core and slows the page
    (JupyterLab with it); one out of sight is not drawn.
    """
    lane.page.locator(CELLS).first.evaluate("e => e.scrollIntoView({block: 'start'})")


def select_cell(lane: Lane, index: int) -> None:
    """Select cell ``index`` in command mode, as a click on its left margin does."""
    lane.page.locator(CELLS).nth(index).locator(".jp-InputPrompt").click(timeout=lane.ms(30))


def prompts(lane: Lane) -> list:
    """Each code cell's execution count: an int, "*" (queued or running), None (never run), or "?"
    (its input is collapsed, as a worked solution's is: no prompt shows)."""
    shown = lane.page.locator(f"{CELLS}.jp-CodeCell").evaluate_all(
        "cells => cells.map(c => { const p = c.querySelector('.jp-InputArea-prompt'); return p && p.textContent; })"
    )
    values = []
    for text in shown:
        inside = "?" if text is None else text.strip().removesuffix(":").strip("[]").strip()
        values.append(int(inside) if inside.isdigit() else (inside if inside in ("*", "?") else None))
    return values


def code_positions(cells: list[dict], first: int, last: int) -> list[int]:
    """Positions among the code cells of the code cells from cell ``first`` to cell ``last``."""
    indices = [i for i, c in enumerate(cells) if c["cell_type"] == "code"]
    return [k for k, i in enumerate(indices) if first <= i <= last]


def run(lane: Lane, command: str, code_cells: list[int], what: str, most: float) -> None:
    """Give a Run menu ``command`` and wait until it has run ``code_cells`` (positions among the code cells).

    The kernel numbers what it runs, so each of those cells must show the
    next number, in order: every cell ran, once, top to bottom.  Fails when
    they do not within ``most`` s, or when the run has stopped short (an error).
    """
    expected = list(range(lane.count + 1, lane.count + 1 + len(code_cells)))
    status = lane.page.locator("#jp-main-statusbar")
    menu(lane, "Run", command)
    quiet = {"polls": 0}

    def shown(p):  # what the cells show, and what they should, leaving out those with no prompt shown
        return ([p[k] for k in code_cells if p[k] != "?"], [e for k, e in zip(code_cells, expected) if p[k] != "?"])

    def finished():
        p = prompts(lane)
        idle = "| Idle" in status.inner_text()
        got, want = shown(p)
        if got == want and idle:
            return p
        quiet["polls"] = quiet["polls"] + 1 if "*" not in p and idle else 0
        return p if quiet["polls"] >= 4 else None  # idle with nothing queued for 1.2 s: it stopped short

    p = lane.poll(f"{what} to finish", finished, most, every=0.3)
    got, want = shown(p)
    if got != want:
        stderr = "application/vnd.jupyter.stderr"  # how JupyterLab shows stderr and errors
        errors = texts(lane.page.locator(f"{CELLS} .jp-OutputArea-output[data-mime-type='{stderr}']"))
        raise AssertionError(
            f"{what}: the code cells show {got}, not {want}; the last stderr output or error:\n"
            + (errors[-1][-1500:] if errors else "none")
        )
    lane.count += len(code_cells)
    lane.log(f"{what}: done")


def save(lane: Lane, name: str) -> dict:
    """Save the notebook (the lane's copy) and return it as JSON: the outputs the page shows."""
    menu(lane, "File", "docmanager:save")
    lane.poll(f"{name} saved", lambda: lane.page.locator(".lm-TabBar-tab.jp-mod-current.jp-mod-dirty").count() == 0, 30)
    return json.loads((lane.lab.root / name).read_text())


def code_cell_index(cells: list[dict], test, after: int = -1) -> int:
    """Index (among all cells) of the first code cell after ``after`` whose source passes ``test``."""
    return next(i for i, c in enumerate(cells) if i > after and c["cell_type"] == "code" and test("".join(c["source"])))


def run_up_to(lane: Lane, cells: list[dict], index: int) -> None:
    """Run every cell from the top to cell ``index`` (Run > Run All Above Selected Cell, below it)."""
    select_cell(lane, index + 1)
    run(lane, "notebook:run-all-above", code_positions(cells, 0, index), f"running the cells up to cell {index}", 90)


def texts(locator) -> list[str]:
    """The text of each element (``textContent``: the browser skips laying out cells out of sight,
    and ``innerText`` is empty there)."""
    return locator.evaluate_all("elements => elements.map(e => e.textContent)")


def output_text(cell) -> str:
    return " ".join(texts(cell.locator(".jp-OutputArea-output")))


# ---- what every notebook must show after Run All ------------------------------------------------------------
FRAMES_JS = """frames => frames.map(f => {
    const live = f.classList.contains('rtt-live-view');  // a live view: a widget (tutorial/view/widget)
    const child = f.closest('.jp-OutputArea-child');
    const next = child && child.nextElementSibling;
    const caption = live ? f.parentElement.querySelector('.rtt-caption') : next;
    const doc = f.contentDocument;  // a live view and a recording are srcdoc pages: same origin
    return {live: live, scenes: live && f.parentElement.rttView ? f.parentElement.rttView.scenes : null,
            caption: caption ? caption.textContent : '',
            canvases: doc ? doc.querySelectorAll('canvas').length : null,
            panes: doc ? Array.from(doc.querySelectorAll('.pane'), p => {
                const r = p.getBoundingClientRect(); return [r.left, r.right]; }) : []};
})"""


def check_views(lane: Lane, stem: str) -> list[str]:
    """Every 3D view on the page draws the tank in each of its panes, and says truly whether it is live."""
    frames = lane.page.locator(f"{CELLS} .jp-OutputArea-output iframe")
    seen = []
    for k, info in enumerate(frames.evaluate_all(FRAMES_JS)):
        frame, live, caption = frames.nth(k), info["live"], info["caption"]
        what = f"{stem} view {k} ({'live' if live else 'recording'})"
        if live:  # a live widget: it has its scene from the kernel, and its caption says live
            assert "(live)" in caption, f"{what}: its caption says {caption!r}"
            scenes = lambda: frames.evaluate_all(FRAMES_JS)[k]["scenes"]  # noqa: B023, E731 - called in this iteration
            lane.poll(f"{what}: its scene from the kernel", scenes, 30)
            frame.element_handle().content_frame().locator("canvas").first.wait_for(
                state="attached", timeout=lane.ms(30)
            )
            panes = [None]
        else:
            assert "(live)" not in caption, f"{what}: its caption says live: {caption!r}"

            def drawing():  # meshcat's viewer has made its canvas in every pane
                now = frames.evaluate_all(FRAMES_JS)[k]  # noqa: B023 - called in this iteration
                return now if now["canvases"] and now["canvases"] >= max(len(now["panes"]), 1) else None

            panes = lane.poll(f"{what}: its page drawing", drawing, 30)["panes"] or [None]
        name = f"{stem}_view{k}"

        def every_pane_has_the_tank():
            image = lane.shot(frame, name)  # noqa: B023 - called in this iteration
            return all(tank_at(image if p is None else image[:, int(p[0]) + 1 : int(p[1]) - 1]) for p in panes)  # noqa: B023 - called in this iteration

        lane.poll(
            f"{what}: the tank drawn in each of its {len(panes)} pane(s) ({name}.png)",
            every_pane_has_the_tank,
            30,
            every=0.1,
        )
        seen.append(f"view {k}: {'live' if live else 'recording'}, {len(panes)} pane(s)")
    return seen


def views_in(notebook: dict) -> int:
    """How many 3D views (``<iframe>`` elements, live or recordings) a saved notebook's outputs hold."""
    return sum(
        "".join(output.get("data", {}).get("text/html", "")).count("<iframe")
        for cell in notebook["cells"]
        if cell["cell_type"] == "code"
        for output in cell.get("outputs", [])
    )


def stderr_of(cell: dict) -> str:
    return "".join(
        "".join(o["text"]) for o in cell.get("outputs", []) if o["output_type"] == "stream" and o["name"] == "stderr"
    )


def check_outputs(saved: dict, committed: dict, stem: str, first: int) -> None:
    """Every code cell ran once, in order, from execution count ``first``; no error output; stderr only
    where the committed notebook has the same."""
    counts = [c["execution_count"] for c in saved["cells"] if c["cell_type"] == "code"]
    assert counts == list(range(first, first + len(counts))), f"{stem}: execution counts {counts}"
    problems = []
    for i, (cell, old) in enumerate(zip(saved["cells"], committed["cells"])):
        for o in cell.get("outputs", []):
            if o["output_type"] == "error":
                problems.append(f"cell {i}: {o['ename']}: {o['evalue']}")
        if stderr_of(cell) != stderr_of(old):
            problems.append(f"cell {i} wrote to stderr:\n{stderr_of(cell)}")
    assert not problems, f"{stem} after Run All:\n" + "\n".join(problems)


def check_panels_closed(lane: Lane, stem: str) -> None:
    """After the final reset(): no control is left, and each panel's output is its stand-in, saying how to
    get the panel back (a saved notebook holds no widget that needs a kernel)."""
    outputs = lane.page.locator(f"{CELLS} .jp-OutputArea-output")
    controls = outputs.locator("button.widget-button, .widget-slider, .jupyter-widgets-disconnected").count()
    assert controls == 0, f"{stem}: {controls} controls left after the final reset()"
    for text in texts(outputs.filter(has_text="Not live now")):
        assert "run this cell to use it (in JupyterLab)" in text, f"{stem}: a panel says {text!r}"


# ---- what a learner does in notebooks 01 and 03 --------------------------------------------------------------
def drive_the_tank(lane: Lane, cells: list[dict]) -> None:
    """Notebook 01: run to the teleop panel, drive with the forward stick, release, Stop, Start, reset()."""
    teleop = code_cell_index(cells, lambda src: "TeleopPanel()" in src)
    shown = max(i for i in range(teleop) if cells[i]["cell_type"] == "code" and ".show(" in "".join(cells[i]["source"]))
    reset = code_cell_index(cells, lambda src: src.startswith("reset()"), after=teleop)
    run_up_to(lane, cells, teleop)
    # make's environment leaves out nbgrader's Validate, which calls any lesson notebook a success, and
    # make notebooks all of nbgrader: its menu and panels are the teacher's and the class's
    assert lane.page.locator(".jp-Toolbar-item", has_text="Validate").count() == 0, "a Validate button is shown"
    menus = lane.page.locator(".lm-MenuBar-itemLabel")
    expect(menus.filter(has_text="Kernel")).to_have_count(1)  # the menu bar is there
    assert menus.filter(has_text="Nbgrader").count() == 0, f"an Nbgrader menu is shown: {menus.all_inner_texts()}"
    panel, view_cell = lane.page.locator(CELLS).nth(teleop), lane.page.locator(CELLS).nth(shown)
    view = view_cell.locator("iframe.rtt-live-view")
    line = panel.locator(".widget-html-content", has_text="/rtt:")
    start, stop = panel.get_by_role("button", name="Start"), panel.get_by_role("button", name="Stop")
    line.filter(has_text="running").wait_for(timeout=lane.ms(30))
    assert start.is_disabled() and stop.is_enabled(), "while running, Stop is offered and Start is not"
    assert "(live): running" in output_text(view_cell), output_text(view_cell)

    _, at_start = lane.tank_in(view, "01_live_1_before")
    forward = panel.locator(".widget-hslider", has_text="left V")
    handle = forward.locator(".noUi-handle")
    handle.focus()
    for _ in range(10):  # ten steps of 0.05: half forward, 1 m/s
        handle.press("ArrowRight")
    expect(forward.locator(".widget-readout")).to_have_text("0.50", timeout=lane.ms(10))
    lane.poll(
        "the tank driving off in the live view (01_live_2_driving.png)",
        lambda: distance(lane.tank_in(view, "01_live_2_driving")[1], at_start) > 40,
        20,
    )
    panel.get_by_role("button", name="release sticks").click()  # the kernel sets the sliders back
    expect(forward.locator(".widget-readout")).to_have_text("0.00", timeout=lane.ms(10))

    stop.click()
    line.filter(has_text="stopped at t =").wait_for(timeout=lane.ms(30))
    lane.poll("Start offered, Stop not, once stopped", lambda: start.is_enabled() and stop.is_disabled(), 10)
    assert "(live): stopped at t =" in output_text(view_cell), output_text(view_cell)
    stopped_at = lane.still_tank(view, "01_live_3_stopped")  # the run's last frame, where the tank went
    assert distance(stopped_at, at_start) > 40, "the stopped view does not show where the tank went"

    start.click()
    line.filter(has_text="running").wait_for(timeout=lane.ms(30))
    lane.poll(
        "the same view showing the restarted run: the tank back at its start (01_live_4_restarted.png)",
        lambda: distance(lane.tank_in(view, "01_live_4_restarted")[1], at_start) < 3,
        30,
    )
    assert "(live): running" in output_text(view_cell), output_text(view_cell)

    # the section's reset(): the view becomes its recording, the panel closes and says so
    select_cell(lane, reset)  # then Run > Run Selected Cell and Do not Advance
    run(lane, "notebook:run-cell", code_positions(cells, reset, reset), "the section's reset()", 30)
    recording = view_cell.locator("iframe[srcdoc]:not(.rtt-live-view)")
    recording.wait_for(timeout=lane.ms(30))
    assert view_cell.locator("iframe.rtt-live-view").count() == 0, "a live page is left after reset()"
    assert "Recorded" in output_text(view_cell), output_text(view_cell)
    lane.tank_in(recording, "01_live_5_recording")
    lane.poll(  # the panels' outputs become their stand-ins, as the view's became its recording
        "the panels replaced by their stand-ins after reset()",
        lambda: panel.locator("button.widget-button, .widget-slider").count() == 0,
        10,
    )
    assert output_text(panel).count("Not live now: run this cell to use it (in JupyterLab).") == 2, output_text(panel)


def two_views_side_by_side(lane: Lane, cells: list[dict]) -> None:
    """Notebook 03: the simulation's and the viewer's live views, side by side; the viewer follows the turret."""
    teleop = code_cell_index(cells, lambda src: "TeleopPanel()" in src)
    shown = max(
        i for i in range(teleop) if cells[i]["cell_type"] == "code" and "views.show(" in "".join(cells[i]["source"])
    )
    run_up_to(lane, cells, teleop)
    # make's environment leaves out nbgrader's Validate, which calls any lesson notebook a success, and
    # make notebooks all of nbgrader: its menu and panels are the teacher's and the class's
    assert lane.page.locator(".jp-Toolbar-item", has_text="Validate").count() == 0, "a Validate button is shown"
    menus = lane.page.locator(".lm-MenuBar-itemLabel")
    expect(menus.filter(has_text="Kernel")).to_have_count(1)  # the menu bar is there
    assert menus.filter(has_text="Nbgrader").count() == 0, f"an Nbgrader menu is shown: {menus.all_inner_texts()}"
    panel, view_cell = lane.page.locator(CELLS).nth(teleop), lane.page.locator(CELLS).nth(shown)
    live = view_cell.locator("iframe.rtt-live-view")
    assert live.count() == 2, f"notebook 03 shows {live.count()} live views, not two"
    left, right = live.nth(0).bounding_box(), live.nth(1).bounding_box()
    assert abs(left["y"] - right["y"]) < 2 and left["x"] + left["width"] <= right["x"] + 1, (left, right)
    assert min(left["width"], right["width"]) > 300, (left, right)
    caption = output_text(view_cell)
    assert "simulation /rtt (live)" in caption and "viewer /rtt_viewer (live)" in caption, caption
    lane.tank_in(live.nth(0), "03_live_simulation")
    before, _ = lane.tank_in(live.nth(1), "03_live_viewer_before")
    for label in ("/rtt:", "/rtt_viewer:"):
        panel.locator(".widget-html-content", has_text=label).filter(has_text="running").wait_for(timeout=lane.ms(30))

    turret = panel.locator(".widget-hslider", has_text="right H")
    turret.locator(".noUi-handle").focus()
    for _ in range(6):  # right stick a little to the right, -0.3: the turret turns at 0.6 rad/s
        turret.locator(".noUi-handle").press("ArrowLeft")  # (full stick: a whole turn, looking as before, in 3 s)
    expect(turret.locator(".widget-readout")).to_have_text(re.compile("^(-|\u2212)0.30$"), timeout=lane.ms(10))

    def turned():
        after, _ = lane.tank_in(live.nth(1), "03_live_viewer_turned")
        # the turret is a cylinder: only its barrel shows the turn (100 to 200 px); a still page changes none
        return changed_pixels(after, before) > 50

    lane.poll("the viewer's view turning the turret (03_live_viewer_turned.png)", turned, 30)
    panel.get_by_role("button", name="release sticks").click()

    # Kernel > Restart while both run: the runs and their widgets stop, and the kernel can no longer
    # say so; the output itself must: a notice over each view's last frame, and the captions.
    restart_kernel(lane)
    notices = view_cell.locator(".rtt-not-live")
    lane.poll("a notice over each view", lambda: notices.count() == 2 and notices, 20)
    assert all("Not live any more" in t for t in notices.all_inner_texts()), notices.all_inner_texts()
    caption = output_text(view_cell)
    assert "(not live)" in caption and "(live)" not in caption, caption
    lane.tank_in(live.nth(0), "03_after_kernel_restart")  # the last frame, under the notice
    panel.screenshot(path=str(lane.shots / "03_panel_after_kernel_restart.png"))


INTERACTIVE = {
    "01_step1_tank_controller": ("teleop", drive_the_tank),
    "03_step3_viewer": ("side by side", two_views_side_by_side),
}
CHECKS = {
    "01_step1_tank_controller": "test_teleop_panel_drives_the_tank",  # the tests that report them
    "03_step3_viewer": "test_step3_views_side_by_side",
}


def failure(exc: BaseException) -> str:
    """An exception as the test's failure: what, and where in this file."""
    here = [f for f in traceback.extract_tb(exc.__traceback__) if f.filename == __file__]
    where = " <- ".join(f"line {f.lineno} ({f.name})" for f in reversed(here))
    return f"{type(exc).__name__}: {exc}\n  at {where}"


def run_notebook(lane: Lane, notebook: Path, outcome: dict) -> None:
    """Open ``notebook``, do what a learner does in it (if anything), Run All, check; results in ``outcome``."""
    stem, name = notebook.stem, notebook.name
    committed = json.loads(notebook.read_text())
    errors_before = len(lane.page_errors)
    try:
        open_notebook(lane, name)
        if stem in INTERACTIVE:
            check, interact = INTERACTIVE[stem]
            try:
                interact(lane, committed["cells"])
                outcome[f"{stem}: {check}"] = None
            except Exception as exc:  # noqa: BLE001 - reported by its own test; Run All (reset() first) goes on
                outcome[f"{stem}: {check}"] = failure(exc)
                with contextlib.suppress(Exception):
                    lane.page.screenshot(path=str(lane.shots / f"{stem}_{check}_failed.png"), timeout=10_000)
                restart_kernel(lane)  # Run All from a known state
            lane.log(f"{stem}: {check}: {'passed' if outcome[f'{stem}: {check}'] is None else 'FAILED'}")
        first = lane.count + 1
        out_of_sight(lane)
        lane.page.evaluate(WATCH_VIEWS)  # each live view, timed while the notebook still runs
        run(
            lane,
            "runmenu:run-all",
            code_positions(committed["cells"], 0, len(committed["cells"])),
            f"{stem}: Run All",
            120,
        )
        times, now = lane.page.evaluate("[window.rttViewTimes, performance.now()]")
        slow = views_slow_to_draw(times, now)
        assert not slow, f"{stem}: live views slow to draw while the notebook ran: {slow}"
        lane.log(f"{stem}: {len(times)} live view(s) drew within 2 s of appearing, while the notebook ran")
        saved = save(lane, name)
        check_outputs(saved, committed, stem, first)
        seen = check_views(lane, stem)
        expected = views_in(saved)
        assert len(seen) == expected, f"{stem}: {len(seen)} 3D views on the page, {expected} in its outputs"
        out_of_sight(lane)
        check_panels_closed(lane, stem)
        lane.log(f"{stem}: outputs, views and panels checked: " + "; ".join(seen))
        errors = lane.page_errors[errors_before:]
        assert not errors, f"{stem}: errors in the page: {errors}"
        outcome[stem] = None
    except Exception as exc:  # noqa: BLE001 - the notebook's test reports it
        outcome[stem] = failure(exc)
        lane.log(f"{stem}: FAILED; the page as it was: {stem}_failed.png")
        with contextlib.suppress(Exception):
            lane.page.screenshot(path=str(lane.shots / f"{stem}_failed.png"), timeout=10_000)
    finally:
        try:
            close_notebook(lane)
        except Exception as exc:  # noqa: BLE001 - start the next notebook from a fresh page
            lane.log(f"{stem}: closing it failed ({type(exc).__name__}); the lane reloads JupyterLab")
            lane.page.goto("about:blank")


def estimate(notebook: Path) -> float:
    """Roughly how long a notebook takes, s: its committed run's cell times, and a learner's part."""
    total = 5.0 + (25.0 if notebook.stem in INTERACTIVE else 0.0)
    for cell in json.loads(notebook.read_text())["cells"]:
        times = cell.get("metadata", {}).get("execution", {})
        if "iopub.execute_input" in times and "shell.execute_reply" in times:
            total += (
                datetime.fromisoformat(times["shell.execute_reply"].replace("Z", "+00:00"))
                - datetime.fromisoformat(times["iopub.execute_input"].replace("Z", "+00:00"))
            ).total_seconds()
    return total


def selected_notebooks(session) -> list[Path]:
    """The notebooks the selected tests need (``pytest -k 00_setup`` runs that one only)."""
    wanted = set()
    for item in session.items:
        if getattr(item, "originalname", None) == "test_run_all":
            wanted.add(item.callspec.params["notebook"])
        for stem, check in CHECKS.items():
            if item.name == check:
                wanted.add(ROOT / "notebooks" / f"{stem}.ipynb")
    return sorted(wanted & set(NOTEBOOKS)) if wanted else NOTEBOOKS


@pytest.fixture(scope="module")
def outcome(request, tmp_path_factory):
    """Run ``NOTEBOOKS`` in JupyterLab, ``LANES`` at once; {check: None when it passed, else why it failed}."""
    start = time.monotonic()
    notebooks = selected_notebooks(request.session)
    root = tmp_path_factory.mktemp("notebooks")
    for notebook in notebooks:
        shutil.copy(notebook, root / notebook.name)
    shots = tmp_path_factory.mktemp("screenshots")
    log = [f"screenshots in {shots}"]
    print("\n" + log[0])
    todo: queue.Queue = queue.Queue()
    for notebook in sorted(notebooks, key=estimate, reverse=True):  # longest first: the lanes end together
        todo.put(notebook)
    results: dict[str, str | None] = {}
    refused: list[str] = []
    stop = threading.Event()  # set if this fixture is interrupted (e.g. by the timeout): the lanes wind up

    def lane_thread(number: int) -> None:
        # Each lane its own ROS 2 domain (two notebooks both start a node /rtt), in a range no other
        # session of this test suite uses (tests/conftest.py picks 1 to 100); ROS stays on this machine.
        # No RTT_TEST_MODE: live runs last until reset(), as for a learner.
        domain = int(os.environ["ROS_DOMAIN_ID"]) + 101 * number
        # RTT_NETWORK_HOSTS=off: notebook 08 shows here what a learner without root sees (its cells say why and
        # go on); its two-host cells run for real under nbval, and in the network tier.  Both at once would not
        # fit the budget.
        env = {
            "RTT_TEST_MODE": None,
            "ROS_DOMAIN_ID": domain,
            "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
            "RTT_NETWORK_HOSTS": "off",
        }
        try:
            with JupyterLab(root, env=env) as lab, browser(refused=refused) as page:
                lane = Lane(number, lab, page, shots, start, log, stop)
                page.on("pageerror", lane.page_error)
                lane.log(f"JupyterLab on {lab.url}, ROS_DOMAIN_ID {domain}")
                while time.monotonic() < lane.deadline and not stop.is_set():
                    try:
                        notebook = todo.get_nowait()
                    except queue.Empty:
                        break
                    run_notebook(lane, notebook, results)
                lab.note_processes()
        except Exception as exc:  # noqa: BLE001 - the notebooks it did not take go to the other lane, or fail
            log.append(f"lane {number} failed: {failure(exc)}")

    lanes = min(LANES, len(notebooks))
    threads = [threading.Thread(target=lane_thread, args=(n,), name=f"jupyterlab-lane-{n}") for n in range(lanes)]
    for t in threads:
        t.start()
    try:
        for t in threads:
            t.join(max(1.0, start + BUDGET - time.monotonic()))
    finally:  # interrupted or not, nothing of this module runs on after it
        stop.set()
        for t in threads:
            t.join(TEARDOWN)
    over = [t.name for t in threads if t.is_alive()]
    results["the browsers stayed on this machine"] = (
        f"they asked for pages off this machine: {refused}" if refused else None
    )
    results["every lane ended"] = f"still running after {BUDGET:.0f} s: {over}" if over else None
    text = "\n".join(log)
    outcome = {name: (None if error is None else f"{error}\n--- log:\n{text}") for name, error in results.items()}
    outcome["log"] = text
    yield outcome


def verdict(outcome: dict, check: str) -> None:
    """The test of ``check`` passes when it ran and passed; its failure, or the lanes' log, otherwise."""
    assert check in outcome, f"{check}: not run (over the budget, or its lane failed)\n--- log:\n{outcome['log']}"
    assert outcome[check] is None, outcome[check]


@pytest.mark.parametrize(
    "notebook", [pytest.param(n, id=n.stem, marks=[pytest.mark.more] if n.stem in MORE else []) for n in NOTEBOOKS]
)
def test_run_all(outcome, notebook):
    verdict(outcome, notebook.stem)


def test_teleop_panel_drives_the_tank(outcome):
    verdict(outcome, "01_step1_tank_controller: teleop")


@pytest.mark.more
def test_step3_views_side_by_side(outcome):
    verdict(outcome, "03_step3_viewer: side by side")


def test_browsers_stayed_on_this_machine_and_every_lane_ended(outcome):
    verdict(outcome, "the browsers stayed on this machine")
    verdict(outcome, "every lane ended")
