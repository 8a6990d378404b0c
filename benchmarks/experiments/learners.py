"""Learners per server: N learners on ``make hub``'s JupyterHub, each running Step 3 with its live views.

    python -m benchmarks.experiments.learners [--learners 1 2 4 8 16] [--seconds 20]

For each N, a hub of ``course/jupyterhub_config.py`` (the trial's spawner:
one Unix user, a ROS domain per learner) starts N learners' servers.  Each
learner's kernel runs what notebook 03 runs: the Step 2 simulation and the
Step 3 viewer in the kernel (``BackgroundApp``), their two live views shown,
the tank driven by ``rtt-joy --demo``.  The benchmark's step clock and
viewer probe (``benchmarks/probes.py``) ride along.  A learner's browser is
on their laptop, so here each learner's views are a client that does not
draw: it opens the kernel's WebSocket through the hub's proxy, says hello
to each view as widget.js does, and answers the frames with ``drawn`` as
widget.js does (four at a time) as they arrive.  Its CPU is this machine's
too, and is stated apart.

Measured in a window common to every learner (after each has applied its
first states and a warm-up, until the first simulation ends):

- each learner's **real-time factor**: simulated seconds per wall second
  over the window, from the step clock;
- the viewer's **state age when applied**, p99: a step's start -> its joint
  state applied on the viewer's main thread (both in the kernel);
- the **frames per second** each learner's client receives from its views;
- **memory per learner**: the proportional set size (PSS: shared pages split
  among their users) of the learner's server and everything it started;
- **CPU**: the machine's cores busy over the window, and the client's share.

The runs go in the order given, one hub after another; nothing else should
run on the machine meanwhile.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import random
import sys
import tempfile
import time
import uuid
from pathlib import Path

import numpy as np
import psutil

from benchmarks.stats import pct
from tutorial.view.widget.flow import ANSWER_EVERY, LONE_WAIT_MS  # as widget.js answers (widget.py writes them in)

ROOT = Path(__file__).resolve().parents[2]
LEARNERS = (1, 2, 4, 8, 16)
# ROS domains for the hub to give out: one upper block (215-232) and 101, clear of the 1-100 that test
# sessions and the other benchmarks pick from.
DOMAINS = (101, *range(215, 233))
# The code path before the cuts of 2026-11-27 and 28, kept for a same-run baseline (--before; rtt-joy's own cut
# is not undone, and the kernel keeps today's window of eight frames): a view answered two frames at a time and
# a lone frame two animation frames later, and a class's simulation slept before every step (the hub's
# RTT_HUB_REALTIME_SLICE_MS).
BEFORE = {"answer_every": 2, "lone_wait_ms": 2000 / 60, "hub_env": {"RTT_HUB_REALTIME_SLICE_MS": "0.2"}}

# A learner's first cell: what notebook 03's set-up cell imports, and ROS 2 initialised.
PREPARE = """\
import os, subprocess, sys
sys.path.insert(0, {root!r})
os.environ["RTT_PROBE_FILE"] = {probe!r}
from tutorial.notebook import views
from tutorial.notebook.runs import BackgroundApp
from tutorial.notebook.session import init_ros
init_ros()
print("ready", os.environ["ROS_DOMAIN_ID"])
"""

# Their second: Step 3 as notebook 03 runs it (simulation and viewer in the kernel, both views shown), with
# a demo joystick, the simulation for ``duration`` simulated seconds.
RUN = """\
venv = os.path.dirname(sys.executable)
joy = subprocess.Popen([os.path.join(venv, "rtt-joy"), "--demo", "--duration", "{joy_s}"],
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
sim = BackgroundApp({sim!r}, node_name="rtt", label="simulation /rtt", duration={duration}).start()
viewer = BackgroundApp({view!r}, node_name="rtt_viewer", label="viewer /rtt_viewer").start()
views.show(sim.view, viewer.view, height=320)
"""

# Their third, once the simulation has ended: stop the viewer (its probe file is written then), and the
# simulation's summary.
FINISH = """\
import json
sim.wait(120)
viewer.stop()
joy.wait(30)
print(json.dumps({"real_time_factor": sim.summary["real_time_factor"], "error": str(sim.error or viewer.error or "")}))
"""


V1 = "v1.kernel.websocket.jupyter.org"  # the kernel WebSocket protocol JupyterLab 4 speaks: the server forwards


def _pack(obj) -> bytes:
    return json.dumps(obj).encode()


def _execute(code: str) -> tuple[str, dict]:
    msg_id = uuid.uuid4().hex
    return msg_id, {
        "header": {"msg_id": msg_id, "msg_type": "execute_request", "username": "", "session": uuid.uuid4().hex,
                   "version": "5.3"},
        "parent_header": {}, "metadata": {}, "channel": "shell",
        "content": {"code": code, "silent": False, "store_history": False, "user_expressions": {},
                    "allow_stdin": False, "stop_on_error": True},
    }  # fmt: skip


def _custom(comm_id: str, content: dict) -> dict:
    """A widget's custom message from the page to the kernel, as ipywidgets' frontend sends it."""
    return {
        "header": {"msg_id": uuid.uuid4().hex, "msg_type": "comm_msg", "username": "", "session": "client",
                   "version": "5.3"},
        "parent_header": {}, "metadata": {}, "channel": "shell",
        "content": {"comm_id": comm_id, "data": {"method": "custom", "content": content}},
    }  # fmt: skip


class ViewClient:
    """One learner's kernel WebSocket, through the hub's proxy: runs cells, and answers its live views.

    It acts as widget.js does without drawing: a view's ``hello`` on its
    comm's opening, then ``drawn`` for the frames as they arrive,
    ``answer_every`` at a time, or what is owed ``lone_wait_ms`` after the first.  Frames are counted with their
    arrival times (monotonic ns).  One asyncio task.
    """

    def __init__(self, url: str, token: str, lone_wait_ms: float = LONE_WAIT_MS, answer_every: int = ANSWER_EVERY):
        self.url, self.token, self.lone_wait_ms, self.answer_every = url, token, lone_wait_ms, answer_every
        self.frames: list[tuple[int, int]] = []  # (arrival, ns; its buffers' bytes)
        self.scenes = 0
        self.views: list[str] = []
        self._waiting: dict[str, asyncio.Future] = {}
        self._out: dict[str, list[str]] = {}
        self._errors: dict[str, str] = {}
        self._owed: dict[str, int] = {}  # comm id -> frames arrived and not answered yet
        self._settling: set[asyncio.Task] = set()  # the late answers' tasks, each kept until it is done
        self._answered: dict[str, int] = {}  # comm id -> answers sent: a late answer overtaken by one ends
        self._ws = None

    async def connect(self) -> None:
        from websockets.asyncio.client import connect

        headers = {"Authorization": f"token {self.token}"}
        self._ws = await connect(
            self.url, additional_headers=headers, subprotocols=[V1], open_timeout=120, max_size=2**28
        )
        if self._ws.subprotocol != V1:
            raise RuntimeError(f"the server did not take JupyterLab's protocol {V1}: {self._ws.subprotocol}")
        self._reader = asyncio.create_task(self._read())

    async def run(self, code: str, timeout: float) -> str:
        """Run ``code``; its output (stdout and stderr).  Raises RuntimeError if it raised."""
        msg_id, request = _execute(code)
        done = asyncio.get_running_loop().create_future()
        self._waiting[msg_id], self._out[msg_id] = done, []
        await self._send(request)
        await asyncio.wait_for(done, timeout)
        out, error = "".join(self._out.pop(msg_id)), self._errors.pop(msg_id, "")
        if error:
            raise RuntimeError(f"a learner's cell raised:\n{error}\n{out}")
        return out

    async def _send(self, msg: dict) -> None:
        from jupyter_server.services.kernels.connection.base import serialize_msg_to_ws_v1

        await self._ws.send(serialize_msg_to_ws_v1(msg, msg["channel"], _pack))

    async def _read(self) -> None:
        from jupyter_server.services.kernels.connection.base import deserialize_msg_from_ws_v1

        async for raw in self._ws:
            _, parts = deserialize_msg_from_ws_v1(raw)
            header, parent_header, _, content = (json.loads(p) for p in parts[:4])
            size = sum(len(b) for b in parts[4:])
            kind = header["msg_type"]
            parent = parent_header.get("msg_id")
            if kind == "comm_open" and content.get("target_name") == "jupyter.widget":
                state = content.get("data", {}).get("state", {})
                if state.get("_model_name") == "AnyModel" and "label" in state:  # a MeshcatWidget
                    self.views.append(content["comm_id"])
                    await self._send(_custom(content["comm_id"], {"type": "hello", "id": "bench"}))
            elif kind == "comm_msg" and content.get("data", {}).get("method") == "custom":
                body = content["data"].get("content", {})
                if body.get("type") in ("frame", "scene"):  # widget.js answers a scene as a frame drawn
                    if body.get("type") == "frame":
                        self.frames.append((time.monotonic_ns(), size))
                    else:
                        self.scenes += 1
                    comm = content["comm_id"]
                    self._owed[comm] = self._owed.get(comm, 0) + 1
                    if self._owed[comm] >= self.answer_every:
                        await self._settle(comm)
                    elif self._owed[comm] == 1:
                        self._settle_later(comm)
            elif parent in self._out and kind == "stream":
                self._out[parent].append(content["text"])
            elif parent in self._waiting and kind == "error":
                self._errors[parent] = "\n".join(content["traceback"])
            elif parent in self._waiting and kind == "status" and content["execution_state"] == "idle":
                future = self._waiting.pop(parent)
                if not future.done():
                    future.set_result(None)

    def _settle_later(self, comm: str) -> None:
        """Answer what is owed as widget.js does: ``lone_wait_ms`` after the first, unless an answer came first."""
        answered = self._answered.get(comm, 0)

        async def settle() -> None:
            await asyncio.sleep(self.lone_wait_ms / 1000)
            if self._answered.get(comm, 0) == answered:
                await self._settle(comm)

        task = asyncio.get_running_loop().create_task(settle())
        self._settling.add(task)
        task.add_done_callback(self._settling.discard)

    async def _settle(self, comm: str) -> None:
        from websockets.exceptions import ConnectionClosed

        owed, self._owed[comm] = self._owed.get(comm, 0), 0
        self._answered[comm] = self._answered.get(comm, 0) + 1
        if owed:
            try:
                await self._send(_custom(comm, {"type": "drawn", "frames": owed}))
            except ConnectionClosed:
                pass  # the learner's page closed: a browser's closing page answers nothing either

    async def close(self) -> None:
        for task in list(self._settling):
            task.cancel()  # lone frames' answers still due: the page is closing
        if self._ws is not None:
            await self._ws.close()
            self._reader.cancel()


def _learner_processes(name: str) -> list[psutil.Process]:
    """The learner's server (jupyterhub-singleuser, JUPYTERHUB_USER=name) and everything it started."""
    for p in psutil.process_iter(["cmdline"]):
        try:
            if "jupyterhub-singleuser" in " ".join(p.info["cmdline"] or []) and (
                p.environ().get("JUPYTERHUB_USER") == name
            ):
                return [p, *p.children(recursive=True)]
        except (psutil.NoSuchProcess, psutil.AccessDenied):
            continue
    return []


# What a process is, by a word of its command line (the first that matches).
ROLES = (
    ("ipykernel", "kernels"),
    ("jupyterhub-singleuser", "learners' servers"),
    ("rtt-joy", "joysticks"),
    ("configurable-http-proxy", "proxy"),
    ("jupyterhub", "hub"),
)


LEARNER_ROLES = ("kernels", "learners' servers", "joysticks")


def _role(p: psutil.Process) -> str:
    line = " ".join(p.cmdline())
    for key, role in ROLES:
        if key in line:
            return role
    return "other"


def _cpu_by_pid(hub, learners) -> dict[int, tuple[str, float]]:
    """pid -> (what it is, CPU seconds so far) of the hub's processes and every learner's."""
    out: dict[int, tuple[str, float]] = {}
    procs = [psutil.Process(hub.proc.pid), *psutil.Process(hub.proc.pid).children(recursive=True)]
    for learner in learners:
        procs += _learner_processes(learner.name)
    for p in procs:
        try:
            t = p.cpu_times()
            out[p.pid] = (_role(p), t.user + t.system)
        except (psutil.NoSuchProcess, psutil.AccessDenied):
            continue
    return out


def _cores_by_role(before: dict, after: dict, seconds: float) -> dict[str, float]:
    """CPU cores each kind of process used between two :func:`_cpu_by_pid`, over the processes in both."""
    out: dict[str, float] = {}
    for pid, (role, cpu) in after.items():
        if pid in before:
            out[role] = out.get(role, 0.0) + (cpu - before[pid][1]) / seconds
    return {k: round(v, 3) for k, v in out.items()}


def _pss_mb(procs: list[psutil.Process]) -> float:
    total = 0
    for p in procs:
        try:
            total += p.memory_full_info().pss
        except (psutil.NoSuchProcess, psutil.AccessDenied):
            pass
    return total / 2**20


def one_class(
    n: int,
    seconds: float,
    warmup: float,
    directory: Path,
    frame_rate: float | None = None,
    before: bool = False,
    answers: tuple[int, float] | None = None,
) -> dict:
    """N learners at once: each one's figures, and the machine's (``frame_rate``: the hub's, else its default).

    ``before``: the code path before the cuts of 2026-11-27 and 28 (:data:`BEFORE`).  ``answers``: the views'
    ``(answer_every, lone_wait_ms)`` (default widget.js's; an A/B of them).
    """
    from tests.hub import Hub, Learner

    names = [f"learner{i + 1:02d}" for i in range(n)]
    env = {} if frame_rate is None else {"RTT_HUB_FRAME_RATE": str(frame_rate)}
    if before:
        env.update(BEFORE["hub_env"])
    hub = Hub(directory / "hub", names, DOMAINS[:n], extra_env=env, timeout=120)
    try:
        learners = [Learner(hub, name) for name in names]
        for learner in learners:
            learner.log_in()
        for i in range(0, n, 4):  # four servers starting at a time: each is seconds of CPU
            batch = learners[i : i + 4]
            for learner in batch:
                learner.request_server()
            for learner in batch:
                learner.start_server(timeout=300)
        for learner in learners:
            r = learner.api("POST", "api/kernels", json={"name": "python3"})
            r.raise_for_status()
            learner.kernel_id = r.json()["id"]
        if answers is None:
            answers = (BEFORE["answer_every"], BEFORE["lone_wait_ms"]) if before else (ANSWER_EVERY, LONE_WAIT_MS)
        return asyncio.run(_measure(hub, learners, seconds, warmup, directory, answers))
    except BaseException:
        print(f"the hub's log, its end:\n{hub.log()[-3000:]}", file=sys.stderr)
        raise
    finally:
        hub.close()


async def _measure(hub, learners, seconds: float, warmup: float, directory: Path, answers: tuple[int, float]) -> dict:
    n = len(learners)
    clients = []
    for learner in learners:
        url = f"ws://127.0.0.1:{hub.port}/user/{learner.name}/api/kernels/{learner.kernel_id}/channels"
        client = ViewClient(url, learner.token, answers[1], answers[0])
        await client.connect()
        clients.append(client)
    probes = [directory / f"{learner.name}.json" for learner in learners]
    await asyncio.gather(
        *(c.run(PREPARE.format(root=str(ROOT), probe=str(probe)), timeout=300) for c, probe in zip(clients, probes))
    )
    # Every learner's run lasts long enough for the last one to start, warm up and be measured.
    duration = seconds + warmup + 4.0 + 0.5 * n
    sim, view = ROOT / "benchmarks" / "projects" / "tank_sim.yaml", ROOT / "benchmarks" / "projects" / "tank_view.yaml"
    run = RUN.format(joy_s=duration + 10.0, sim=str(sim), view=str(view), duration=duration)
    await asyncio.gather(*(c.run(run, timeout=120) for c in clients))  # every learner's cell at once
    started, started_ns = time.monotonic(), time.monotonic_ns()
    # The machine over the middle of the runs (the window is fixed from the probes afterwards).
    await asyncio.sleep(min(duration / 2, 4.0 + 0.5 * n + warmup))
    me = psutil.Process()
    roles0 = _cpu_by_pid(hub, learners)
    cpu0, own0, t0 = psutil.cpu_times(), me.cpu_times(), time.monotonic()
    await asyncio.sleep(min(seconds, duration - (time.monotonic() - started) - 2.0))
    cpu1, own1, t1 = psutil.cpu_times(), me.cpu_times(), time.monotonic()
    roles = _cores_by_role(roles0, _cpu_by_pid(hub, learners), t1 - t0)
    trees = [_learner_processes(learner.name) for learner in learners]
    memory = [_pss_mb(tree) for tree in trees]
    theirs = {p.pid for tree in trees for p in tree}
    hub_tree = [psutil.Process(hub.proc.pid), *psutil.Process(hub.proc.pid).children(recursive=True)]
    hub_mb = _pss_mb([p for p in hub_tree if p.pid not in theirs])  # the hub and its proxy
    finished = [
        json.loads(out.strip().splitlines()[-1])
        for out in await asyncio.gather(*(c.run(FINISH, timeout=240) for c in clients))
    ]
    for c in clients:
        await c.close()
    busy = (sum(cpu1) - sum(cpu0)) - (cpu1.idle - cpu0.idle) - (cpu1.iowait - cpu0.iowait)
    own = (own1.user + own1.system) - (own0.user + own0.system)
    per = [_analyse(p, c, warmup) for p, c in zip(probes, clients)]
    # The window common to every learner; when the machine is so overloaded that a viewer's first state came
    # after another learner's run had ended, each learner is measured over their own window, and it says so.
    window = (max(p["window"][0] for p in per), min(p["window"][1] for p in per))
    common = window[1] - window[0] >= 0.5 * seconds * 1e9
    figures = [_in_window(p, window if common else p["window"]) for p in per]
    if not common:
        window = (min(p["window"][0] for p in per), max(p["window"][1] for p in per))
    first_state_s = [round((p["applied"][0][2] - started_ns) / 1e9, 1) for p in per]
    ages = np.concatenate([f["ages_ms"] for f in figures])
    # A learner whose viewer applied no state inside the window has no age: the worst learner's is then
    # unknown (None, and its target fails as "n/a"), and how many that happened to is counted.
    ages_p99 = [f["age_ms_p99"] for f in figures]
    return {
        "learners": n,
        "window_s": round((window[1] - window[0]) / 1e9, 1),
        "common_window": common,
        "first_state_s": first_state_s,  # from every learner's run cell having returned to each viewer's first state
        "real_time_factor": [f["real_time_factor"] for f in figures],
        "real_time_factor_min": min(f["real_time_factor"] for f in figures),
        "age_ms_p99": ages_p99,
        "age_ms_p99_max": None if None in ages_p99 else max(ages_p99),
        "learners_with_no_state_in_window": sum(a is None for a in ages_p99),
        "age_ms_pooled": pct(ages),
        "frames_per_s": [f["frames_per_s"] for f in figures],
        "frames_per_s_min": min(f["frames_per_s"] for f in figures),
        "views_answered": [len(c.views) for c in clients],
        "frame_kb_per_s": round(sum(f["frame_kb_per_s"] for f in figures), 1),  # all learners' views together
        "memory_mb_per_learner": [round(m, 1) for m in memory],
        "memory_mb_per_learner_mean": round(sum(memory) / n, 1),
        "hub_and_proxy_mb": round(hub_mb, 1),
        "cores_busy": round(busy / (t1 - t0), 2),
        "client_cores": round(own / (t1 - t0), 2),
        "cores_by_role": roles,
        # what a learner costs the server: their kernel, their Jupyter server and their joystick (the hub, its
        # proxy and the stand-in browsers are the class's, or not the server's)
        "cores_per_learner": round(sum(roles.get(k, 0.0) for k in LEARNER_ROLES) / n, 3),
        "summary_real_time_factor": [f["real_time_factor"] for f in finished],
        "errors": [f["error"] for f in finished if f["error"]],
    }


def _analyse(probe: Path, client: ViewClient, warmup: float) -> dict:
    clock = json.loads(probe.read_text())
    view = json.loads(probe.with_name(probe.stem + ".Tank.json").read_text())
    if not view["applied"]:
        raise RuntimeError(f"{probe.stem}'s viewer applied no state")
    return {
        "clock": clock,
        "applied": view["applied"],
        "frames": client.frames,
        "window": (view["applied"][0][2] + int(warmup * 1e9), clock["wall_ns"][-1]),
    }


def _in_window(p: dict, window: tuple[int, int]) -> dict:
    lo, hi = window
    sim, wall = np.asarray(p["clock"]["sim_ns"]), np.asarray(p["clock"]["wall_ns"])
    inside = (wall >= lo) & (wall <= hi)
    s, w = sim[inside], wall[inside]
    step_wall = {round(t / 1000): x for t, x in zip(p["clock"]["sim_ns"], p["clock"]["wall_ns"])}
    ages = np.asarray(
        [
            (applied - step_wall[round(stamp / 1000)]) / 1e6
            for stamp, _, applied in p["applied"]
            if lo <= applied <= hi and round(stamp / 1000) in step_wall
        ]
    )
    frames = [size for t, size in p["frames"] if lo <= t <= hi]
    return {
        "real_time_factor": round(float((s[-1] - s[0]) / (w[-1] - w[0])), 3),
        "ages_ms": ages,
        "age_ms_p99": pct(ages)["p99"],
        "frames_per_s": round(len(frames) / ((hi - lo) / 1e9), 1),
        "frame_kb_per_s": sum(frames) / 1024 / ((hi - lo) / 1e9),
    }


def learners_per_server(
    counts,
    seconds: float,
    warmup: float,
    frame_rate: float | None = None,
    before: bool = False,
    answers: tuple[int, float] | None = None,
) -> dict:
    """The class sizes in turn; each one's figures.

    A class that fails (the machine too loaded for a learner's cell to
    finish in time, say) is kept as ``{"learners": n, "failed": "..."}``,
    and no larger class is tried: the smaller classes' figures stay, and the
    targets that read the failed size read n/a.
    """
    out = {}
    for n in counts:
        try:
            with tempfile.TemporaryDirectory() as d:
                out[str(n)] = one_class(n, seconds, warmup, Path(d), frame_rate, before, answers)
        except Exception as error:  # noqa: BLE001 - kept as this size's result, with what went wrong
            out[str(n)] = {"learners": n, "failed": f"{type(error).__name__}: {error}"[:500]}
            print(f"{n:3d} learners: the class failed ({out[str(n)]['failed']}); no larger class tried", flush=True)
            break
        r = out[str(n)]
        print(
            f"{n:3d} learners, frame rate {frame_rate or 'the hub default'}: "
            f"real-time factor min {r['real_time_factor_min']:.3f}, "
            + (
                f"age p99 max {r['age_ms_p99_max']:.1f} ms, "
                if r["age_ms_p99_max"] is not None
                else f"{r['learners_with_no_state_in_window']} learner(s) shown no state in the window, "
            )
            + f"frames/s min {r['frames_per_s_min']:.1f}, "
            f"{r['memory_mb_per_learner_mean']:.0f} MB/learner, {r['cores_per_learner']:.3f} cores/learner, "
            f"{r['cores_busy']:.2f} cores busy (client {r['client_cores']:.2f})"
            + (" [before the cuts of 2026-11-27 and 28]" if before else ""),
            flush=True,
        )
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--learners", type=int, nargs="+", default=list(LEARNERS))
    p.add_argument("--seconds", type=float, default=20.0, help="the measured window, s (default 20)")
    p.add_argument("--warmup", type=float, default=3.0)
    p.add_argument("--frame-rate", type=float, default=None, help="the live views' frames/s (default: the hub's)")
    p.add_argument("--output", default=None, help="a folder: learners.json and its plot, bench_learners.png")
    p.add_argument(
        "--before", action="store_true", help="also one learner before the cuts of 2026-11-27 and 28 (BEFORE)"
    )
    p.add_argument(
        "--answers",
        type=float,
        nargs=2,
        metavar=("EVERY", "WAIT_MS"),
        help="the views answer EVERY frames at once, or what they owe WAIT_MS after the first (default widget.js's)",
    )
    args = p.parse_args(argv)
    answers = None if args.answers is None else (int(args.answers[0]), args.answers[1])
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 100)))  # the hub gives each learner theirs
    from benchmarks.plots import plot_learners
    from benchmarks.run import _commit

    r = {
        "machine": {"cpus": os.cpu_count()},
        "source": "python -m benchmarks.experiments.learners",
        "when": time.strftime("%Y-%m-%d %H:%M"),
        "commit": _commit(),
        "frame_rate": args.frame_rate,
        "answers": answers,
        "learners": learners_per_server(args.learners, args.seconds, args.warmup, args.frame_rate, answers=answers),
    }
    if args.before:
        r["learners_before"] = learners_per_server([1], args.seconds, args.warmup, args.frame_rate, before=True)
    if args.output:
        out = Path(args.output)
        out.mkdir(parents=True, exist_ok=True)
        (out / "learners.json").write_text(json.dumps(r, indent=1))
        alone = r["learners"].get("1")
        if alone and "failed" not in alone:  # the plot's limits are one learner's figures times the targets'
            plot_learners(r, out / "bench_learners.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
