"""The live view over the notebook's own connection, beside the meshcat page over its own WebSocket, same run.

    python -m benchmarks.experiments.widget [--seconds 8] [--cases tank_50Hz tanks_8] [--rounds 3] [--remote]

For each case, the Step 3 viewer first runs for real (``browser.tutorial_run``:
simulation, joystick, viewer) and its frames are taped: every command it
sent to meshcat, at the moment it sent it.  The tape is then replayed, at
the same moments, two ways, ``WIDGET_ROUNDS`` times each and alternating,
and each time the state handed to the view is timed to the pixel (each
side's samples pooled over its rounds; each round's p99s kept beside):

- **page**: to the project's meshcat server and its page in Chromium (the
  page every view was before: a WebSocket of its own), the frames exactly
  as the viewer sent them; handed -> drawn is the send to the server ->
  the end of the page's next render (``browser.analyse_bare``);
- **widget**: in a JupyterLab kernel, into a :class:`MeshcatWidget`
  shown in JupyterLab in Chromium (the view is 480 x 380 px, as the page);
  handed -> drawn is the kernel's ``put`` of the state -> the view's
  animation frame after the frame holding it (``window.rttProbe``).  A
  state that a newer one replaced before it went out is not counted, as a
  state the page never drew is not;
- **widget_plain**: the same, on a server without the project's nodelay
  extension, as Colab or a plain ``pip install`` runs it (each frame waits
  for Nagle's algorithm on the kernel's WebSocket).

The tape comes from ``browser.tutorial_run``, whose publisher runs
``browser.SLIDE`` times slower than its case (49.9 Hz for 50 Hz), so its
states slide through every point of a page's 60 Hz frame, in each replay
alike (at exactly 50 Hz they land on five points, placed by chance per
page: two pages, two draws, a ratio moved by up to a fifth).  Both sides
report where the states they count landed (``send_phase_ms``,
``browser.since_frame_ms``).

``--remote`` also runs the browser on a second host with a 5 Mbit/s link
(50 ms latency) to the kernel's (``tutorial.tools.network.hosts``; root only):
the frames the view draws from the kernel per second, and a trivial
cell's time (tests/lab_browser.py).
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

from benchmarks.experiments.browser import (
    CASES,
    bare_run,
    bare_samples,
    clock_offset_ns,
    since_frame,
    tutorial_run,
)
from benchmarks.stats import pct

ROOT = Path(__file__).resolve().parents[2]
WIDGET_CASES = ("tank_50Hz", "tanks_8")
WIDGET_ROUNDS = 3  # interleaved replays of one tape to each side per case, pooled (widget_vs_page)

REPLAY_CELL = """\
import json, os, threading, time
import msgpack, umsgpack
from tutorial.view.widget.widget import MeshcatWidget

tape = json.load(open({tape!r}))
w = MeshcatWidget("benchmark", 380)
w.layout.width = "480px"
w.probe = []
first = next(i for i, c in enumerate(tape) if c[4] is not None)
for c in tape[:first]:
    w.put([umsgpack.unpackb(bytes.fromhex(c[3]))])
puts = []

def replay():
    deadline = time.monotonic() + 60
    while w.hellos == 0 and time.monotonic() < deadline:
        time.sleep(0.01)  # the view opens when the browser has drawn the output
    time.sleep(1.0)  # the scene is drawn once before the clock starts
    t0, base = time.monotonic_ns(), tape[first][0]
    for c in tape[first:]:
        wait = (t0 + (c[0] - base) - time.monotonic_ns()) / 1e9
        if wait > 0:
            time.sleep(wait)
        data = bytes.fromhex(c[3])
        commands = msgpack.unpackb(data)["commands"] if c[1] == "set_transforms" else [msgpack.unpackb(data)]
        puts.append(time.monotonic_ns())
        w.put(commands)
    time.sleep(0.5)
    with open({out!r} + ".part", "w") as f:
        json.dump({{"puts": puts, "sent": w.probe, "replaced": w.flow.commands_replaced}}, f)
    os.replace({out!r} + ".part", {out!r})

threading.Thread(target=replay, daemon=True).start()
w
"""

# In the view's iframe: its animation frames, to count the frames per second the view's page draws.
IFRAME_RAFS = """() => {
  const f = document.querySelector('iframe.rtt-live-view');
  if (!f || !f.contentWindow || !f.contentWindow.viewer) return false;  // meshcat's page not loaded yet
  if (f.contentWindow.__rafs) return true;
  const w = f.contentWindow;
  w.__rafs = [];
  const tick = () => { w.__rafs.push(performance.timeOrigin + performance.now()); w.requestAnimationFrame(tick); };
  w.requestAnimationFrame(tick);
  return true;
}"""


def widget_run(tape: list, directory: Path, timeout_s: float = 120.0, nodelay: bool = True) -> dict:
    """Replay ``tape`` into a MeshcatWidget in a JupyterLab kernel, shown in Chromium; the raw records.

    ``nodelay=False``: the server as Colab or a plain ``pip install`` runs it, without the project's
    nodelay extension (``tests.jupyterlab.WITHOUT_NODELAY``).
    """
    import nbformat
    from playwright.sync_api import sync_playwright

    from tests.jupyterlab import CHROMIUM, CHROMIUM_FLAGS, WITHOUT_NODELAY, JupyterLab
    from tests.lab_browser import STATS, run_first_cell

    tape_file, out = directory / "tape.json", directory / "widget_out.json"
    tape_file.write_text(json.dumps(tape))
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_code_cell(REPLAY_CELL.format(tape=str(tape_file), out=str(out)))]
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    nbformat.write(nb, directory / "replay.ipynb")
    args = () if nodelay else WITHOUT_NODELAY
    with JupyterLab(directory, env={"PYTHONPATH": str(ROOT)}, server_args=args) as lab, sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_FLAGS)
        try:
            page = browser.new_page(viewport={"width": 1000, "height": 800})
            page.add_init_script("window.rttProbe = [];")
            run_first_cell(page, lab.notebook_url("replay.ipynb", workspace="replay"))
            page.wait_for_function(IFRAME_RAFS, timeout=60_000)
            deadline = time.monotonic() + timeout_s
            while not out.exists():
                if time.monotonic() > deadline:
                    raise RuntimeError("the kernel's replay did not finish")
                page.wait_for_timeout(200)
            probe = page.evaluate("window.rttProbe")
            rafs = page.evaluate("document.querySelector('iframe.rtt-live-view').contentWindow.__rafs")
            stats = page.evaluate(STATS)
            offset_ns = clock_offset_ns(page)
        finally:
            browser.close()
    kernel = json.loads(out.read_text())
    return dict(kernel, probe=probe, rafs=rafs, offset_ns=offset_ns, page=stats.get("page"), dropped=stats["dropped"])


def widget_samples(run: dict, warmup: float) -> dict:
    """One widget replay's raw figures: per state, handed -> drawn, sent -> page, page -> drawn and handed -> the
    view's frame before (ns); the view's frames/s and messages/s."""
    puts = np.array(run["puts"], dtype=np.int64)
    sent = dict(run["sent"])  # frame number -> monotonic ns sent
    offset = run["offset_ns"]
    start_ns = int(puts[0]) + int(warmup * 1e9)
    handed_to_drawn, sent_to_page, page_to_drawn = [], [], []
    counted = set()
    for n, received, drawn in run["probe"]:
        if drawn is None or n not in sent:
            continue
        t_sent = sent[n]
        i = int(np.searchsorted(puts, t_sent, side="right")) - 1  # the newest state put before it went
        if i < 0 or puts[i] < start_ns or i in counted:
            continue
        counted.add(i)
        drawn_ns, received_ns = drawn * 1e6 - offset, received * 1e6 - offset
        handed_to_drawn.append(drawn_ns - puts[i])
        sent_to_page.append(received_ns - t_sent)
        page_to_drawn.append(drawn_ns - received_ns)
    rafs = np.array([t * 1e6 - offset for t in run["rafs"]])
    rafs = rafs[(rafs >= start_ns) & (rafs <= puts[-1])]
    fps = round(float((len(rafs) - 1) / ((rafs[-1] - rafs[0]) * 1e-9)), 1) if len(rafs) > 1 else None
    frames = [t for _, t in run["sent"] if t >= start_ns]
    return {
        "handed_to_drawn": handed_to_drawn,
        "sent_to_page": sent_to_page,
        "page_to_drawn": page_to_drawn,
        "send_phase": list(since_frame([int(t) for t in puts[sorted(counted)]], run["rafs"], offset)),
        "frames_per_s": fps,
        "messages_per_s": round(len(frames) / ((puts[-1] - start_ns) * 1e-9), 1) if frames else None,
        "states_handed": int((puts >= start_ns).sum()),
        "states_drawn": len(counted),
        "dropped": run["dropped"],
        "page": run["page"],
    }


def _lowest(rounds: list[dict], key: str):
    """The lowest ``key`` of the ``rounds`` (a rate: its slowest round's); None when no round has one."""
    return min((r[key] for r in rounds if r.get(key) is not None), default=None)


def _pooled(rounds: list[dict], latencies: tuple[str, ...]) -> dict:
    """Percentiles (ms) of each latency over the samples of all ``rounds``; a rate is its slowest round's."""
    out = {k: pct([x for r in rounds for x in r[k]], 1e-6) for k in latencies}
    out["send_phase_ms"] = pct([x for r in rounds for x in r["send_phase"]], 1e-6)
    out["frames_per_s"] = _lowest(rounds, "frames_per_s")
    out["frames_per_s_rounds"] = [r["frames_per_s"] for r in rounds]
    out["messages_per_s"] = _lowest(rounds, "messages_per_s")
    return out


def summarise_widget(rounds: list[dict]) -> dict:
    """The widget's figures over the pooled samples of ``rounds`` (:func:`widget_samples`)."""
    out = _pooled(rounds, ("handed_to_drawn", "sent_to_page", "page_to_drawn"))
    for k in ("states_handed", "states_drawn", "dropped"):
        out[k] = sum(r[k] for r in rounds)
    out["page"] = rounds[0]["page"]
    return out


def summarise_page(rounds: list[dict]) -> dict:
    """The meshcat page's figures over the pooled samples of ``rounds`` (:func:`browser.bare_samples`)."""
    flat = [{**r, **r["rates"]} for r in rounds]  # the page's rates beside its samples
    out = _pooled(flat, ("sent_to_page", "sent_to_drawn"))
    out["renders_per_s"] = _lowest(flat, "renders_per_s")
    out["page"] = rounds[0]["rates"]["page"]
    out["render_js_ms_rounds"] = [r["rates"]["render_js_ms"] for r in rounds]
    return out


SIDES = ("page", "widget", "widget_plain")  # widget_plain: the server without the nodelay extension (Colab)


def widget_vs_page(cases: list[str], seconds: float, warmup: float, rounds: int = WIDGET_ROUNDS) -> dict:
    """Every case: the taped viewer replayed to the WebSocket page, to the widget, and to the widget on a
    server without the project's nodelay extension (as Colab or a plain ``pip install`` runs it), ``rounds``
    times each.

    The replays rotate (round r starts at side r of :data:`SIDES`), so a
    drift of the machine over the minutes of a case falls on every side,
    and each side's samples are pooled over its rounds: a p99 of one
    replay's 300 states is its third-latest state (one run's three rounds
    gave eight tanks 1.26x, 1.26x and 1.14x the page: the Benchmarks page,
    "Live views in the notebook").  Each round's own p99s and their ratios
    are kept in ``rounds``, to show that spread.
    """
    out = {}
    for case in cases:
        got: dict[str, list] = {side: [] for side in SIDES}
        each = []
        with tempfile.TemporaryDirectory() as d:
            tape = tutorial_run(case, seconds, Path(d))["tape"]
            for r in range(rounds):
                order = SIDES[r % len(SIDES) :] + SIDES[: r % len(SIDES)]
                for side in order:
                    if side == "page":
                        got[side].append(bare_samples(*bare_run(tape, batch=True), warmup))
                    else:
                        run = widget_run(tape, Path(tempfile.mkdtemp(dir=d)), nodelay=side == "widget")
                        got[side].append(widget_samples(run, warmup))
                page_p99 = pct(got["page"][-1]["sent_to_drawn"], 1e-6)["p99"]
                row = {"first": order[0], "page_p99_ms": page_p99}
                for side in ("widget", "widget_plain"):
                    p99 = pct(got[side][-1]["handed_to_drawn"], 1e-6)["p99"]
                    row[f"{side}_p99_ms"] = p99
                    row[f"{side}_ratio"] = round(p99 / page_p99, 3) if page_p99 and p99 else None
                    row[f"{side}_frames_per_s"] = got[side][-1]["frames_per_s"]
                each.append(row)
                print(f"widget {case}, round {r + 1} of {rounds}: {json.dumps(row)}", flush=True)
        out[case] = {
            "page": summarise_page(got["page"]),
            "widget": summarise_widget(got["widget"]),
            "widget_plain": summarise_widget(got["widget_plain"]),
            "rounds": each,
        }
        print(f"widget {case}: {json.dumps(out[case])}", flush=True)
    return out


FIRST_PICTURE_CELLS = (
    "import time\n\nimport meshcat.geometry as g\n\nfrom tutorial.view.widget.widget import MeshcatWidget\n\n\n"
    "def view():\n"
    '    w = MeshcatWidget("first picture", 300)\n'
    '    w.visualizer()["box"].set_object(g.Box([0.2, 0.2, 0.2]))\n'
    "    return w",
    "view()",
    "time.sleep(3)",  # the busy cell: Run Selected Cell and All Below runs it right after the view's cell
)


def first_picture(tries: int = 10) -> dict:
    """How long a new view's first picture takes, from its output appearing to its scene drawn, ms, with the
    kernel idle (its cell alone) and busy (a 3 s cell queued right after it, as Run All does), ``tries``
    of each, alternating, in one JupyterLab page (after one view not counted: the page's first fetches
    meshcat's viewer script)."""
    import nbformat

    from tests.jupyterlab import JupyterLab, browser
    from tests.lab_browser import WATCH_VIEWS, kernel_ready, run_cell, run_menu, wait_for

    times: dict[str, list[float]] = {"idle": [], "busy": []}
    with tempfile.TemporaryDirectory() as d:
        nb = nbformat.v4.new_notebook()
        nb.cells = [nbformat.v4.new_code_cell(c) for c in FIRST_PICTURE_CELLS]
        nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
        nbformat.write(nb, Path(d) / "first.ipynb")
        with JupyterLab(Path(d), env={"PYTHONPATH": str(ROOT)}) as lab, browser(1000, 800) as page:
            page.goto(lab.notebook_url("first.ipynb", workspace="first"))
            cells = page.locator(".jp-Notebook .jp-Cell")
            kernel_ready(page)
            page.evaluate(WATCH_VIEWS)
            run_cell(page, cells.first, lambda: page.keyboard.press("Control+Enter"))

            prompts = page.locator(".jp-Notebook .jp-Cell .jp-InputPrompt")
            for k in range(2 * tries + 1):
                kind = "busy" if k % 2 else "idle"
                # no cell running or queued (not the kernel's indicator: each view message says busy, then idle)
                wait_for(page, lambda: not any("*" in p for p in prompts.all_inner_texts()), "the kernel idle", 60)
                before = set(page.evaluate("Object.keys(window.rttViewTimes)"))
                if kind == "idle":
                    run_cell(page, cells.nth(1), lambda: page.keyboard.press("Control+Enter"))
                else:
                    run_cell(page, cells.nth(1), lambda: run_menu(page, "Run Selected Cell and All Below"))

                def drawn(before=before):
                    new = [t for i, t in page.evaluate("window.rttViewTimes").items() if i not in before]
                    return new[0] if new and new[0]["drawn"] is not None else None

                t = wait_for(page, drawn, f"a new view's picture ({kind})", 60)
                if k:  # the first view of the page also fetches meshcat's viewer script: not counted
                    times[kind].append(t["drawn"] - t["appeared"])
            lab.note_processes()
    out = {kind: {**pct(ms, 1.0), "ms": [round(x) for x in ms]} for kind, ms in times.items()}
    print(f"first picture: {json.dumps(out)}", flush=True)
    return out


def remote(mbit: float = 5.0) -> dict:
    """JupyterLab on one host, Chromium on another over a ``mbit`` link: the view's frames/s and a cell's time."""
    from tests.jupyterlab import JupyterLab
    from tests.lab_browser import step2_notebook
    from tutorial.tools.network.hosts import Network

    with tempfile.TemporaryDirectory() as d, Network(("robot", "operator")) as net:
        robot, operator = net["robot"], net["operator"]
        step2_notebook(Path(d) / "remote.ipynb")
        joystick = subprocess.Popen(
            robot.command([sys.executable, "-m", "tutorial.tools.rtt_joy", "--demo"]),
            env=robot.env(PYTHONPATH=str(ROOT)),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        env = {"ROS_AUTOMATIC_DISCOVERY_RANGE": "SUBNET", "PYTHONPATH": str(ROOT), "RTT_TEST_MODE": None}
        try:
            operator.limit_rate(mbit)
            with JupyterLab(Path(d), env=env, ip=robot.address, prefix=robot.command([])) as lab:
                url = lab.notebook_url("remote.ipynb", "r")
                done = subprocess.run(
                    operator.command([sys.executable, "-m", "tests.lab_browser", url, robot.address]),
                    cwd=ROOT,
                    env=operator.env(PYTHONPATH=str(ROOT)),
                    capture_output=True,
                    text=True,
                    timeout=300,
                )
                lab.note_processes()
        finally:
            joystick.kill()
            joystick.wait(10)
        if done.returncode != 0:
            raise RuntimeError(f"the remote browser failed: {done.stderr[-2000:]}")
        got = json.loads(done.stdout.strip().splitlines()[-1])
        got["mbit"] = mbit
        got["cell_ms_max"] = max(got["cell_ms"])
        return got


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seconds", type=float, default=8.0, help="simulated seconds per case (default 8)")
    p.add_argument("--warmup", type=float, default=2.0, help="s left out at the start of each run (default 2)")
    p.add_argument("--cases", nargs="+", choices=list(CASES), default=list(WIDGET_CASES))
    p.add_argument("--rounds", type=int, default=WIDGET_ROUNDS, help=f"replays per side (default {WIDGET_ROUNDS})")
    p.add_argument("--remote", action="store_true", help="also the browser on a second host over 5 Mbit/s (root)")
    p.add_argument("--first-picture", action="store_true", help="only a new view's first picture, kernel idle/busy")
    args = p.parse_args(argv)
    if args.first_picture:
        print(json.dumps(first_picture(), indent=1))
        return 0
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 100)))
    r = {"cases": widget_vs_page(args.cases, args.seconds, args.warmup, args.rounds)}
    if args.remote:
        r["remote"] = remote()
    print(json.dumps(r, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
