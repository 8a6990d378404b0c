"""From a published state to the pixel: the viewer's meshcat page in a real browser, stage by stage.

    python -m benchmarks.experiments.browser [--seconds 8] [--cases tank_50Hz tank_1kHz tanks_8 arm_48]

Each case runs the simulation and the Step 3 viewer as two processes, as
``make bench``'s pipeline runs do, but the viewer draws in meshcat, and
Debian's Chromium (headless, driven by Playwright, as the JupyterLab test
drives it) shows the viewer's page.  For every state the page draws, five
moments are joined on the state's stamp, each taken where it happens:

========================  ====================================================
moment                    taken by
========================  ====================================================
published                 the simulation's step clock (``benchmarks.probes.StepClock``)
received by the viewer    the viewer's subscription callback (its probe)
sent to meshcat           the viewer's zmq socket, tapped (``benchmarks.viewer_proc --record-meshcat``)
received by the page      the page's WebSocket, hooked before meshcat's own handler runs
drawn                     the end of the first ``viewer.render()`` (three.js) after it arrived
========================  ====================================================

A message is recognised in the page by the CRC-32 of its bytes (the server
forwards the bytes it was sent unchanged), in order.  The page's clock
(``performance.timeOrigin + performance.now()``, 0.1 ms) is turned into
``time.monotonic_ns()`` by the offset between the two read from the page at
the end of its run (:meth:`Page.clock_offset_ns`), not through this
machine's wall clock.
A state the viewer never drew (at 1 kHz it draws at most 60 frames a second,
the newest state each time) has no drawn moment and is not counted.

The viewer sends each frame as one ``set_transforms`` message
(:mod:`tutorial.view.meshcat_batch`), to the project's server and page; a
page message is then joined to every state of its frame.  ``--unbatched``
runs the viewer on meshcat's own server and page instead, one message per
transform, as before that command (to compare, in the same conditions).
On this machine the project's page draws without multisampling and with
fewer triangles for round shapes (:mod:`tutorial.view.meshcat_page`);
``--full-detail`` keeps meshcat's triangle counts (``?detail=full``), to
compare.

**The baseline, in the same run**: a bare script replays, to a bare meshcat
server and page, the exact transforms the viewer sent (the scene, then every
transform, at the moments it sent them), in meshcat's own protocol (one
``set_transform`` per body, as meshcat-python sends them): no ROS and no
tutorial code on its path, only zmq and meshcat's own server and page (bound
to 127.0.0.1).  Its figure is send -> drawn.  The page's frames per second are its ``requestAnimationFrame``
callbacks per second.

**Every point of the page's frame, on both sides.**  A page draws at its
animation frames, 60 a second here, so a message waits for the next one:
anywhere from 0 to 16.7 ms, by where in the frame it lands.  Both the
viewer and headless Chromium keep time by this machine's clock, so the
viewer's sends would land on a few points of the page's frame, the same
for a whole run, and where those sit is one draw of chance per page:

* at 1 kHz the viewer draws at its own 60 a second, one point (send -> the
  frame before it, measured at 60: p50 6.5 ms and p90 7.0 ms in one run,
  13.4 and 13.6 ms in another); the bare page's p99 was 33.6 ms in one run
  and 6.9 ms in the next, 2026-11-25;
* at 50 Hz a state every 20 ms lands on five points 3.3 ms apart, which
  moves a p99 by up to 3.3 ms (the bare page at 15.9 ms in one run, 18.0
  in the next; ours at 19.4 ms against the first: 1.22x, a miss).

So the viewer here draws at most :data:`VIEW_FRAME_RATE` frames a second,
and a publisher slower than that publishes :data:`SLIDE` times slower
than its case says (49.9 Hz for 50 Hz: one step of 1 ms more every 25th
state): the sends slide through every point of the page's frame, in the
run and in each replay of its tape alike.  Both sides report where their
sends landed (``send_phase_ms``: send -> the page's animation frame before
it, not capped at a frame: a stalled page shows more).
"""

from __future__ import annotations

import argparse
import json
import os
import queue
import random
import subprocess
import sys
import tempfile
import threading
import time
import zlib
from pathlib import Path

import numpy as np

from benchmarks.procs import py, start
from benchmarks.scale_projects import arm_projects, tanks_projects
from benchmarks.stats import pct
from tutorial.view.meshcat_batch import SET_TRANSFORMS, split_batch

FRAME_MS = 1000.0 / 60.0
STAGES = (  # (key, what happens in it), in order: their sum is publish -> drawn
    ("publish_to_callback", "ROS delivery"),
    ("callback_to_applied", "hand-off to the main thread"),
    ("applied_to_sent", "frame pacing and scene update"),
    ("sent_to_page", "meshcat server, WebSocket, a busy page"),
    ("page_to_drawn", "the page's next render"),
)
CASES = {  # name: (kind, size, publisher rate Hz)
    "tank_50Hz": ("tanks", 1, 50.0),
    "tank_1kHz": ("tanks", 1, 1000.0),
    "tanks_8": ("tanks", 8, 50.0),
    "arm_48": ("arm", 48, 50.0),
}
# The page's size: one view of the notebooks' side-by-side display (380 px high, half a column wide).
# This machine has no GPU: Chromium rasterizes with SwiftShader on the CPU, on the same two cores as the
# simulation and the viewer, at a cost that grows with the pixels.  Measured with the bare replay of one
# tank at 50 Hz: 60 frames/s and send -> page p50 1 to 3 ms up to 480 x 360; 57 frames/s and 20 ms at
# 640 x 480; 25 to 39 frames/s and 34 to 41 ms at 800 x 600.  A browser with a GPU does not pay it.
VIEWPORT = {"width": 480, "height": 380}
# The viewer's frame rate here (RTT_FRAME_RATE), and how much slower than its case a publisher below that
# rate publishes: each run's sends slide through every point of the page's frame (the docstring says why).
VIEW_FRAME_RATE = 59.0
SLIDE = 1.002
CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--enable-unsafe-swiftshader",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-quic",
    "--no-first-run",
]

# Runs in the page before meshcat's own script: hooks its WebSocket and its renders.
PAGE_PROBE = r"""
window.__rtt = {msgs: [], renders: [], render_ms: [], rafs: []};
(function () {
  const now = () => performance.timeOrigin + performance.now();
  const table = new Uint32Array(256);
  for (let n = 0; n < 256; n++) {
    let c = n;
    for (let k = 0; k < 8; k++) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
    table[n] = c >>> 0;
  }
  function crc32(bytes) {
    let c = 0xffffffff;
    for (let i = 0; i < bytes.length; i++) c = table[(c ^ bytes[i]) & 0xff] ^ (c >>> 8);
    return (c ^ 0xffffffff) >>> 0;
  }
  const Native = window.WebSocket;
  function Probed(url, protocols) {
    const ws = protocols === undefined ? new Native(url) : new Native(url, protocols);
    ws.addEventListener("message", (ev) => {
      const t = now();
      if (ev.data instanceof ArrayBuffer) window.__rtt.msgs.push([t, crc32(new Uint8Array(ev.data))]);
    });
    return ws;
  }
  Probed.prototype = Native.prototype;
  window.WebSocket = Probed;
  function frame() { window.__rtt.rafs.push(now()); requestAnimationFrame(frame); }
  requestAnimationFrame(frame);
  const hook = setInterval(() => {
    if (window.viewer && window.viewer.render) {
      const render = window.viewer.render.bind(window.viewer);
      window.viewer.render = function () {
        const t0 = now();
        const r = render();
        const t1 = now();
        window.__rtt.renders.push(t1);
        window.__rtt.render_ms.push(t1 - t0);
        return r;
      };
      window.viewer.__rtt_hooked = true;
      clearInterval(hook);
    }
  }, 2);
})();
"""


def clock_offset_ns(page, tries: int = 20) -> int:
    """A Playwright page's clock minus ``time.monotonic_ns()``, ns (:meth:`Page.clock_offset_ns` says why so)."""
    best = None
    for _ in range(tries):
        a = time.monotonic_ns()
        t = page.evaluate("performance.timeOrigin + performance.now()")
        b = time.monotonic_ns()
        if best is None or b - a < best[0]:
            best = (b - a, round(t * 1e6) - (a + b) // 2)
    return best[1]


class Page:
    """A headless Chromium page on a meshcat URL, with :data:`PAGE_PROBE` in it (one thread only)."""

    def __init__(self, url: str, timeout_s: float = 30.0):
        from playwright.sync_api import sync_playwright

        assert url.startswith("http://127.0.0.1:"), url
        self._pw = sync_playwright().start()
        self._browser = None
        try:
            self._browser = self._pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
            self.page = self._browser.new_page(viewport=VIEWPORT)
            self.page.add_init_script(PAGE_PROBE)
            self.page.goto(url)
            self.page.wait_for_function("window.viewer && window.viewer.__rtt_hooked", timeout=timeout_s * 1000)
        except BaseException:  # no browser or Playwright left behind by a page that did not open
            self.close()
            raise

    def clock_offset_ns(self, tries: int = 20) -> int:
        """The page's clock minus ``time.monotonic_ns()``, ns: subtract it from a page time (in ns) to compare.

        Read from the page itself, not through this machine's wall clock:
        the page's times are ``performance.timeOrigin + performance.now()``,
        whose origin is the wall clock when the page was made and which
        moves with the monotonic clock after; a wall clock that was off then
        (a virtual machine's clock sync) would shift every one of them (one
        case of eight tanks once matched no state at all).  Of ``tries`` readings, the one with the shortest round trip
        is kept; the uncertainty is half of it (well under 1 ms here).
        """
        return clock_offset_ns(self.page, tries)

    def samples(self) -> dict:
        """``{"msgs": [[ms, crc32], ...], "renders": [ms], "render_ms": [ms], "rafs": [ms], "offset_ns": ns,
        "page": {...} or None}`` so far.

        Times are the page's clock (ms); ``offset_ns`` is :meth:`clock_offset_ns`, read now; ``page`` is
        the project's page's ``window.rttPage`` (:mod:`tutorial.view.meshcat_page`), None on meshcat's own.
        """
        samples = self.page.evaluate("window.__rtt")
        samples["offset_ns"] = self.clock_offset_ns()
        # The project's page: its renderer, multisampling and detail (meshcat's own page: None).
        samples["page"] = self.page.evaluate("window.rttPage || null")
        return samples

    def close(self) -> None:
        if self._browser is not None:
            self._browser.close()
        self._pw.stop()


def _lines(proc: subprocess.Popen) -> queue.Queue:
    """A queue of the process's stdout lines, read by a thread of its own."""
    q: queue.Queue = queue.Queue()

    def read():
        for line in iter(proc.stdout.readline, ""):
            q.put(line)
        q.put(None)

    threading.Thread(target=read, daemon=True).start()
    return q


def _meshcat_url(lines: queue.Queue, timeout: float) -> str:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            line = lines.get(timeout=max(0.0, deadline - time.monotonic()))
        except queue.Empty:
            break
        if line is None:
            break
        if line.startswith("{") and '"meshcat_url"' in line:
            return json.loads(line)["url"]
    raise RuntimeError("the viewer printed no meshcat URL")


def _wait(proc: subprocess.Popen, timeout: float) -> None:
    try:
        proc.wait(timeout)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait(10)
        raise RuntimeError(f"{proc.args} did not finish in {timeout} s") from None
    if proc.returncode != 0:
        raise RuntimeError(f"{proc.args} exited {proc.returncode}: {proc.stderr.read()[-2000:]}")


def publisher_rate_parameter(rate: float) -> str:
    """The ``-p`` argument that sets a case's publisher rate (Hz) for its run: :data:`SLIDE` times slower
    below :data:`VIEW_FRAME_RATE`, and always written as a ROS double (``1000.0``, never ``1000``: the
    parameter is declared a double, and an integer is refused)."""
    rate = float(rate if rate > VIEW_FRAME_RATE else rate / SLIDE)
    return f"RttJointStatePublisher.rate:={rate!r}"


def tutorial_run(case: str, seconds: float, directory: Path, batch: bool = True, query: str = "") -> dict:
    """One case through the tutorial: simulation, viewer, its page; the raw records of each.

    ``batch=False`` gives the viewer meshcat's own server and page, so it sends one command per transform.
    ``query`` is added to the page's address (``"?detail=full"``: the project's page keeps meshcat's
    triangle counts, :mod:`tutorial.view.meshcat_page`).
    """
    kind, size, rate = CASES[case]
    sim_project, view_project = (tanks_projects if kind == "tanks" else arm_projects)(size, directory)
    sim_probe, view_probe, tape = directory / "sim.json", directory / "view.json", directory / "tape.json"
    viewer = start(
        py("benchmarks.viewer_proc", str(view_project), "--duration", str(seconds + 12.0))
        + ["--record-meshcat", str(tape)]
        + ([] if batch else ["--meshcat-no-batch"]),
        view_probe,
        {"RTT_FRAME_RATE": str(VIEW_FRAME_RATE)},
    )
    procs = [viewer]
    page = None
    try:
        url = _meshcat_url(_lines(viewer), 60)
        page = Page(url + query)
        sim = start(
            py("tutorial.tools.rtt_run", str(sim_project), "--headless", "--duration", str(seconds), "--json")
            + ["--ros-args", "-p", publisher_rate_parameter(rate)],
            sim_probe,
        )
        procs.append(sim)
        joystick = (
            start(py("tutorial.tools.rtt_joy", "--demo", "--duration", str(seconds + 6.0))) if kind == "tanks" else None
        )
        if joystick is not None:
            procs.append(joystick)
        _wait(sim, seconds + 40)
        samples = page.samples()
        _wait(viewer, seconds + 40)
    finally:
        if page is not None:
            page.close()
        for proc in procs:
            if proc.poll() is None:
                proc.kill()
                proc.wait(10)
    views = {}
    for f in directory.glob("view.*.json"):
        views[f.name.split(".")[1]] = json.loads(f.read_text())
    return {
        "sim": json.loads(sim_probe.read_text()),
        "views": views,
        "tape": json.loads(tape.read_text()),
        "page": samples,
    }


def bare_run(tape: list, lead_s: float = 1.0, batch: bool = False) -> tuple[dict, list]:
    """Replay ``tape`` to a bare meshcat server and page, at its moments; the page's samples and the send log.

    The tape is first turned into meshcat's own protocol (:func:`bare_commands`:
    one ``set_transform`` per body, as meshcat-python sends them), and the
    server is meshcat's own with its own page (``start_server(batch=False)``,
    bound to 127.0.0.1).  ``batch=True`` replays the frames as the viewer sent
    them, to the project's server and page instead.  The scene's commands (every one before the first
    transform that names a body) go first, then each transform at its
    recorded offset from the first.  Sends are pipelined (a DEALER socket,
    then the replies), so a frame's commands leave together.
    """
    import zmq

    from tutorial.tools.standalone.meshcat_server import start_server

    tape = tape if batch else bare_commands(tape)
    server = start_server(batch=batch)
    page = None
    sock = zmq.Context.instance().socket(zmq.DEALER)
    sock.setsockopt(zmq.LINGER, 0)
    sock.connect(server.zmq_url)
    sent: list[tuple[int, int]] = []  # (monotonic ns, crc32)
    try:
        page = Page(server.web_url)
        first = next(i for i, c in enumerate(tape) if c[4] is not None)
        in_flight = 0

        def send(command) -> None:
            nonlocal in_flight
            data = bytes.fromhex(command[3])
            sock.send_multipart([b"", command[1].encode(), command[2].encode(), data])
            sent.append((time.monotonic_ns(), zlib.crc32(data)))
            in_flight += 1

        def collect() -> None:
            nonlocal in_flight
            while in_flight:
                if not sock.poll(5000):
                    raise RuntimeError("the bare meshcat server did not answer")
                sock.recv_multipart()
                in_flight -= 1

        for command in tape[:first]:
            send(command)
            collect()
        time.sleep(lead_s)  # not synchronisation: the page draws the scene once before the clock starts
        t0, base = time.monotonic_ns(), tape[first][0]
        for command in tape[first:]:
            due = t0 + (command[0] - base)
            wait = (due - time.monotonic_ns()) / 1e9
            if wait > 0:
                collect()  # a frame's transforms went out together; their replies come before the next frame
                time.sleep(wait)
            send(command)
        collect()
        time.sleep(0.5)  # the last frames reach the page
        samples = page.samples()
    finally:
        if page is not None:
            page.close()
        sock.close()
        server.close()
    return samples, sent


def since_frame(sends_ns: list, rafs_ms: list, offset_ns: int) -> np.ndarray:
    """Each send (monotonic ns) -> the page's animation frame before it (page ms; ``offset_ns``:
    :meth:`Page.clock_offset_ns`), ns; a send before the first frame is left out, and with no frame, every one."""
    frames = np.sort(np.asarray(rafs_ms, dtype=float)) * 1e6 - offset_ns
    if frames.size == 0:
        return np.zeros(0)
    sends = np.asarray(sends_ns, dtype=float)
    i = np.searchsorted(frames, sends, side="right") - 1
    return (sends - frames[np.clip(i, 0, None)])[i >= 0]


def since_frame_ms(sends_ns: list, rafs_ms: list, offset_ns: int) -> dict:
    """Percentiles (ms) of :func:`since_frame`."""
    return pct(since_frame(sends_ns, rafs_ms, offset_ns), 1e-6)


def _match(msgs: list, crcs: list[int]) -> list[tuple[int, int]]:
    """``(page message index, sent index)`` pairs: each page message to the next sent one of the same CRC."""
    pairs, j = [], 0
    for i, (_, crc) in enumerate(msgs):
        k = j
        while k < len(crcs) and crcs[k] != crc:
            k += 1
        if k < len(crcs):
            pairs.append((i, k))
            j = k + 1
    return pairs


def tape_states(record: list) -> list[tuple[str, int | None]]:
    """The ``(body, stamp)`` of each state a tape record shows: one for a ``set_transform``, one per body
    for a frame sent as one ``set_transforms`` (``benchmarks.viewer_proc.CommandTape``)."""
    body, stamp = record[4], record[5]
    if record[1] == SET_TRANSFORMS:
        return list(zip(body, stamp))
    return [(body, stamp)]


def bare_commands(tape: list) -> list[list]:
    """The tape as meshcat's own protocol: each ``set_transforms`` frame becomes its ``set_transform``
    commands, at the same moment, in order (what a bare script sends a bare server)."""
    out = []
    for record in tape:
        if record[1] != SET_TRANSFORMS:
            out.append(record)
            continue
        for parts, data in split_batch(bytes.fromhex(record[3])):
            out.append([record[0], "set_transform", "/" + "/".join(parts), data.hex(), "frame", None])
    return out


def _first_after(times: np.ndarray, t: float) -> float | None:
    i = int(np.searchsorted(times, t, side="left"))
    return float(times[i]) if i < len(times) else None


def analyse_tutorial(run: dict, warmup: float) -> dict:
    """Stage by stage, per state drawn (ms), for one tutorial run."""
    step_wall = {round(t / 1000): w for t, w in zip(run["sim"]["sim_ns"], run["sim"]["wall_ns"])}
    end_ns = run["sim"]["wall_ns"][-1]
    applied = {}
    for body, v in run["views"].items():
        for stamp, arrived, done in v["applied"]:
            applied.setdefault((body, stamp), (arrived, done))
    transforms = [c for c in run["tape"] if c[4] and c[1] in ("set_transform", SET_TRANSFORMS)]
    crcs = [zlib.crc32(bytes.fromhex(c[3])) for c in transforms]
    page = run["page"]
    offset_ns = page["offset_ns"]
    renders = np.array(sorted(page["renders"]))
    to_mono = lambda page_ms: page_ms * 1e6 - offset_ns  # noqa: E731 - one line of arithmetic
    start_ns = min(c[0] for c in transforms) + int(warmup * 1e9)
    stages = {k: [] for k in (*(key for key, _ in STAGES), "publish_to_drawn")}
    seen, sends = set(), []
    for i, k in _match(page["msgs"], crcs):
        sent_ns = transforms[k][0]
        received = to_mono(page["msgs"][i][0])
        drawn = _first_after(renders, page["msgs"][i][0])
        if not (start_ns <= sent_ns <= end_ns) or drawn is None:
            continue
        sends.append(sent_ns)
        drawn = to_mono(drawn)
        for body, stamp in tape_states(transforms[k]):  # a frame sent as one message shows several states
            if (body, stamp) in seen or stamp is None:
                continue
            step = step_wall.get(round(stamp / 1000))
            arrived_done = applied.get((body, stamp))
            if step is None or arrived_done is None:
                continue
            seen.add((body, stamp))
            arrived, done = arrived_done
            for key, value in (
                ("publish_to_callback", arrived - step),
                ("callback_to_applied", done - arrived),
                ("applied_to_sent", sent_ns - done),
                ("sent_to_page", received - sent_ns),
                ("page_to_drawn", drawn - received),
                ("publish_to_drawn", drawn - step),
            ):
                stages[key].append(value)
    out = {k: pct(v, 1e-6) for k, v in stages.items()}
    out.update(_page_rates(page, start_ns, end_ns, offset_ns), states_drawn=len(seen))
    out["send_phase_ms"] = since_frame_ms(sends, page["rafs"], offset_ns)
    return out


def bare_samples(samples: dict, sent: list, warmup: float) -> dict:
    """The bare replay's raw figures: per state, send -> page, send -> drawn and send -> the frame before (ns);
    and the page's rates (:func:`_page_rates`)."""
    offset_ns = samples["offset_ns"]
    renders = np.array(sorted(samples["renders"]))
    crcs = [c for _, c in sent]
    start_ns = sent[0][0] + int(warmup * 1e9)
    to_page, to_drawn, sends = [], [], []
    for i, k in _match(samples["msgs"], crcs):
        t_sent = sent[k][0]
        if t_sent < start_ns:
            continue
        received = samples["msgs"][i][0] * 1e6 - offset_ns
        drawn = _first_after(renders, samples["msgs"][i][0])
        if drawn is None:
            continue
        to_page.append(received - t_sent)
        to_drawn.append(drawn * 1e6 - offset_ns - t_sent)
        sends.append(t_sent)
    return {
        "sent_to_page": to_page,
        "sent_to_drawn": to_drawn,
        "send_phase": list(since_frame(sends, samples["rafs"], offset_ns)),
        "rates": _page_rates(samples, start_ns, sent[-1][0], offset_ns),
    }


def analyse_bare(samples: dict, sent: list, warmup: float) -> dict:
    """send -> page and send -> drawn (ms) for the bare replay."""
    raw = bare_samples(samples, sent, warmup)
    out = {"sent_to_page": pct(raw["sent_to_page"], 1e-6), "sent_to_drawn": pct(raw["sent_to_drawn"], 1e-6)}
    out.update(raw["rates"])
    out["send_phase_ms"] = pct(raw["send_phase"], 1e-6)
    return out


def _page_rates(page: dict, start_ns: int, end_ns: int, offset_ns: int) -> dict:
    """The page's frames (requestAnimationFrame), renders and WebSocket messages per second within [start, end]
    (monotonic ns), and the time of its render calls (ms, the whole run)."""

    def per_s(times):
        t = np.array([x * 1e6 - offset_ns for x in times])
        t = t[(t >= start_ns) & (t <= end_ns)]
        return round(float((len(t) - 1) / ((t[-1] - t[0]) * 1e-9)), 1) if len(t) > 1 else None

    return {
        "page": page.get("page"),
        "frames_per_s": per_s(page["rafs"]),
        "renders_per_s": per_s(page["renders"]),
        "messages_per_s": per_s([m[0] for m in page["msgs"]]),
        "render_js_ms": pct(page["render_ms"], 1.0),  # three.js's render call (the rasterizing is elsewhere)
    }


def pixel_latency(cases: list[str], seconds: float, warmup: float, batch: bool = True, query: str = "") -> dict:
    """Every case: the tutorial's stages and the bare replay's, in the same run.

    ``batch=False``: the tutorial as before ``set_transforms`` (one message per transform), to compare;
    ``query``: added to the tutorial page's address (:func:`tutorial_run`).
    """
    out = {}
    for case in cases:
        with tempfile.TemporaryDirectory() as d:
            run = tutorial_run(case, seconds, Path(d), batch, query)
        samples, sent = bare_run(run["tape"])
        out[case] = {
            "tutorial": analyse_tutorial(run, warmup),
            "bare": analyse_bare(samples, sent, warmup),
        }
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--seconds", type=float, default=8.0, help="simulated seconds per case (default 8)")
    p.add_argument("--warmup", type=float, default=2.0, help="s left out at the start of each run (default 2)")
    p.add_argument("--cases", nargs="+", choices=list(CASES), default=list(CASES))
    p.add_argument(
        "--unbatched",
        action="store_true",
        help="the viewer on meshcat's own server: one message per transform, as before set_transforms",
    )
    p.add_argument(
        "--full-detail",
        action="store_true",
        help="the project's page keeps meshcat's triangle counts on a software renderer (?detail=full), to compare",
    )
    args = p.parse_args(argv)
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 100)))
    query = "?detail=full" if args.full_detail else ""
    r = pixel_latency(args.cases, args.seconds, args.warmup, batch=not args.unbatched, query=query)
    print(json.dumps(r, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
