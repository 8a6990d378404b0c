"""Running what is measured: child processes (start, finish, their CPU time) and a function on a thread of its own."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

from benchmarks.paths import ROOT


def py(*args: str) -> list[str]:
    """The command line of ``python -u -m *args`` with this interpreter."""
    return [sys.executable, "-u", "-m", *args]


def start(cmd: list[str], probe: Path | None = None, extra_env: dict | None = None) -> subprocess.Popen:
    """``cmd`` started in the repository, output piped; ``probe``: the file its probes write (``RTT_PROBE_FILE``)."""
    env = {**os.environ, **(extra_env or {})}
    if probe is not None:
        env["RTT_PROBE_FILE"] = str(probe)
    return subprocess.Popen(cmd, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def finish(proc: subprocess.Popen, timeout: float) -> str:
    """The standard output of ``proc`` once it has exited within ``timeout`` s; raises if it failed or hung."""
    try:
        out, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        proc.kill()
        out, err = proc.communicate()
        raise RuntimeError(f"{proc.args} did not finish:\n{out}\n{err}") from None
    if proc.returncode != 0:
        raise RuntimeError(f"{proc.args} exited {proc.returncode}:\n{out}\n{err}")
    return out


def cpu_seconds(pid: int) -> float:
    """User + system CPU time of a process and its children, s."""
    import psutil

    try:
        proc = psutil.Process(pid)
        total = sum(proc.cpu_times()[:2])
        for child in proc.children(recursive=True):
            try:
                total += sum(child.cpu_times()[:2])
            except psutil.NoSuchProcess:
                pass
        return total
    except psutil.NoSuchProcess:
        return float("nan")


def steady_cpu_cores(procs: dict[str, subprocess.Popen], seconds: float, warmup: float) -> dict[str, float]:
    """CPU cores each running process (with its children) uses over the steady part of a run.

    Waits out discovery and the warm-up first (not synchronisation: the
    sample simply starts later), then samples for the rest of the run.
    """
    time.sleep(warmup + 2.0)
    cpu0 = {k: cpu_seconds(p.pid) for k, p in procs.items()}
    t0 = time.monotonic()
    time.sleep(max(1.0, seconds - warmup - 3.0))
    cpu1 = {k: cpu_seconds(p.pid) for k, p in procs.items()}
    span = time.monotonic() - t0
    return {k: (cpu1[k] - cpu0[k]) / span for k in procs}


def in_thread(fn):
    """``fn()`` run on a new thread, as the simulation runs on its own; returns its result."""
    import threading

    out = []
    t = threading.Thread(target=lambda: out.append(fn()))
    t.start()
    t.join()
    return out[0]
