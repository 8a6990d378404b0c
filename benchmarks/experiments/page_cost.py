"""What one frame of the meshcat page costs the browser, and where its main thread waits.

    python -m benchmarks.experiments.page_cost [--model arm48 --count 1] [--detail low full] [--seconds 4]

A still scene (``--count`` copies of ``model/<model>.xml``, drawn once by
the project's :class:`tutorial.view.scene.Scene` on the project's meshcat
server) is opened in Debian's Chromium, headless, as the browser
experiment opens it (:class:`benchmarks.experiments.browser.Page`), and the
page is made to draw every animation frame.  For each page setting
(``?detail=low`` and ``?detail=full``, :mod:`tutorial.view.meshcat_page`)
it prints:

- **Chromium's CPU by kind of process**, cores, over ``--seconds``
  (``psutil``, the processes of the browser this run started): the GPU
  process (where SwiftShader rasterizes WebGL without a GPU), the
  renderers (the page's JavaScript and its main thread) and the others;
- **the page's frames/s** (its ``requestAnimationFrame`` callbacks), over
  those seconds and again while it is traced (tracing slows the page);
- **where the page's main thread spends a frame**, from a Chromium trace
  (``Browser.start_tracing``) of two seconds, the mean of each slice (one a
  frame): the whole main frame
  (``ProxyMain::BeginMainFrame``), the animation-frame callbacks (meshcat's
  render, in JavaScript) and the wait for the GPU process inside the
  commit (``GLES2::ReadPixels``: without GPU compositing, Chromium copies
  each WebGL frame back for its software compositor, and the main thread
  waits until the frame is drawn).

Nothing moves and no ROS runs: this is the drawing alone, on whatever else
the machine is doing (run it on an idle machine).  Every server and page
is on 127.0.0.1.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import sys
import time
from collections import defaultdict

# The main thread's trace slices :func:`main_thread_ms` reports, by what they are.
SLICES = {
    "main frame": "ProxyMain::BeginMainFrame",
    "animation-frame callbacks (meshcat's render)": "FrameRequestCallbackCollection::ExecuteFrameCallbacks",
    "waiting for the GPU process (ReadPixels)": "GLES2::ReadPixels",
}
MAIN_THREAD = "CrRendererMain"
TRACE_CATEGORIES = ["devtools.timeline", "blink", "gpu", "cc", "viz", "toplevel"]


def main_thread_ms(trace: dict) -> dict:
    """Count and mean duration (ms) of each of :data:`SLICES` on the page's main thread of a Chromium trace.

    Each of them runs once a frame, so a mean is per frame.

    Args:
        trace: a Chromium trace, ``{"traceEvents": [...]}`` (complete events, ``ph == "X"``, ``dur`` in µs;
            thread names from the ``thread_name`` metadata events).

    Returns:
        ``{label: {"n": count, "mean_ms": mean duration}}``; a slice that never ran has ``n == 0`` and
        ``mean_ms`` None.  Slices on other threads (the GPU process's, the compositor's) are not counted.
    """
    names = {}
    for e in trace.get("traceEvents", []):
        if e.get("ph") == "M" and e.get("name") == "thread_name":
            names[(e.get("pid"), e.get("tid"))] = e.get("args", {}).get("name")
    totals = defaultdict(lambda: [0, 0.0])
    wanted = {v: k for k, v in SLICES.items()}
    for e in trace.get("traceEvents", []):
        if e.get("ph") != "X" or e.get("name") not in wanted or "dur" not in e:
            continue
        if names.get((e.get("pid"), e.get("tid"))) != MAIN_THREAD:
            continue
        total = totals[wanted[e["name"]]]
        total[0] += 1
        total[1] += e["dur"] / 1000.0
    out = {}
    for label in SLICES:
        n, total_ms = totals[label]
        out[label] = {"n": n, "mean_ms": round(total_ms / n, 2) if n else None}
    return out


def _chromium_cpu_s() -> dict:
    """``{pid: (kind, CPU seconds so far)}`` of the Chromium processes this process started (through Playwright).

    ``kind`` is ``gpu``, ``renderer`` or ``other``.  Only descendants of this process: another job's
    browser is not counted.
    """
    import psutil

    seconds = {}
    for proc in psutil.Process().children(recursive=True):
        try:
            cmd = " ".join(proc.cmdline())
            if "chromium" not in cmd:
                continue
            kind = "gpu" if "--type=gpu-process" in cmd else "renderer" if "--type=renderer" in cmd else "other"
            t = proc.cpu_times()
            seconds[proc.pid] = (kind, t.user + t.system)
        except psutil.Error:  # a process that ended meanwhile: not counted
            continue
    return seconds


def _cores(before: dict, after: dict, seconds: float) -> dict:
    """Cores by kind between two :func:`_chromium_cpu_s` readings, over the processes in both."""
    cores = defaultdict(float)
    for pid, (kind, t1) in after.items():
        if pid in before:
            cores[kind] += (t1 - before[pid][1]) / seconds
    return {kind: round(c, 2) for kind, c in sorted(cores.items())}


def page_cost(model: str, count: int, details: list[str], seconds: float) -> dict:
    """Draw a still scene every frame in Chromium, once per page setting; its cost (see the module's docstring).

    Runs on the calling thread (Playwright's sync API and the meshcat socket are both that thread's).

    Returns:
        ``{detail: {"cores": {kind: cores}, "frames_per_s": f, "traced_frames_per_s": f, "draw_calls": n,
        "triangles": n, "main_thread": main_thread_ms(...), "page": window.rttPage}}``.

    Raises:
        RuntimeError: the meshcat server did not start; playwright's ``TimeoutError``: the page did not
        load or draw within 30 s.
    """
    import mujoco

    from benchmarks.experiments.browser import Page
    from benchmarks.paths import ROOT
    from tutorial.core.world import ModelEntry, build_world
    from tutorial.tools.standalone.meshcat_server import start_server
    from tutorial.tools.standalone.sinks import frame_sink
    from tutorial.view.scene import Scene

    entries = [ModelEntry(f"M{i}", str(ROOT / "model" / f"{model}.xml")) for i in range(count)]
    m = build_world(entries)
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)
    server = start_server()
    out = {}
    try:
        vis = server.visualizer()
        scene = Scene(vis, m, sink=frame_sink(vis))
        scene.build(d)
        scene.close()
        for detail in details:
            page = Page(server.web_url + f"?detail={detail}")  # closes its browser itself if it fails to open
            try:
                out[detail] = _measure(page, seconds)
            finally:
                page.close()
    finally:
        server.close()
    return out


def _measure(page, seconds: float) -> dict:
    """One page setting of :func:`page_cost`: the page draws every frame; its cost, then a trace."""
    p = page.page
    rafs = "window.__rtt.rafs.length"
    p.wait_for_function("window.rttPage !== undefined")
    # Every animation frame draws (meshcat draws only after a change): the cost of a busy page.
    p.evaluate("(() => { const f = () => { viewer.set_dirty(); requestAnimationFrame(f); }; f(); })()")
    # Settled: 30 frames drawn since, and the scene complete (the same triangles 10 frames apart).
    p.wait_for_function(f"{rafs} > {p.evaluate(rafs) + 30}", timeout=30000)
    info = "viewer.renderer.info.render"
    deadline = time.monotonic() + 30.0
    while True:
        calls, triangles = p.evaluate(f"[{info}.calls, {info}.triangles]")
        p.wait_for_function(f"{rafs} > {p.evaluate(rafs) + 10}", timeout=30000)
        if p.evaluate(f"{info}.triangles") == triangles > 0 or time.monotonic() > deadline:
            break
    cpu0, raf0, t0 = _chromium_cpu_s(), p.evaluate(rafs), time.monotonic()
    time.sleep(seconds)  # the measuring window itself, not a wait for anything
    cpu1, raf1, t1 = _chromium_cpu_s(), p.evaluate(rafs), time.monotonic()
    page._browser.start_tracing(page=p, categories=TRACE_CATEGORIES)
    raf2, t2 = p.evaluate(rafs), time.monotonic()
    time.sleep(2.0)  # the traced window
    raf3, t3 = p.evaluate(rafs), time.monotonic()
    trace = json.loads(page._browser.stop_tracing())
    return {
        "cores": _cores(cpu0, cpu1, t1 - t0),
        "frames_per_s": round((raf1 - raf0) / (t1 - t0), 1),
        "traced_frames_per_s": round((raf3 - raf2) / (t3 - t2), 1),
        "draw_calls": calls,
        "triangles": triangles,
        "main_thread": main_thread_ms(trace),
        "page": p.evaluate("window.rttPage"),
    }


def report(result: dict) -> str:
    """The figures of :func:`page_cost` as lines of text (any thread)."""
    lines = []
    for detail, r in result.items():
        cores = ", ".join(f"{k} {v:.2f}" for k, v in r["cores"].items())
        lines.append(
            f"detail={detail}: {r['frames_per_s']} frames/s ({r['traced_frames_per_s']} while traced), "
            f"{r['draw_calls']} draw calls, "
            f"{r['triangles']} triangles; Chromium cores: {cores}"
        )
        for label, s in r["main_thread"].items():
            mean = "-" if s["mean_ms"] is None else f"{s['mean_ms']:.2f} ms"
            lines.append(f"    main thread, {label}: {mean} a frame ({s['n']} frames traced)")
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--model", default="arm48", help="a model/<name>.xml (default arm48)")
    p.add_argument("--count", type=int, default=1, help="copies of it side by side (default 1)")
    p.add_argument("--detail", nargs="+", choices=("low", "full"), default=["low", "full"])
    p.add_argument("--seconds", type=float, default=4.0, help="s of drawing over which CPU is measured (default 4)")
    args = p.parse_args(argv)
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"  # no ROS runs here; the project's rule all the same
    os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 100)))
    print(report(page_cost(args.model, args.count, args.detail, args.seconds)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
