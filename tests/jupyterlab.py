"""JupyterLab in headless Chromium, driven by Playwright, for the browser tests of the notebooks.

:class:`JupyterLab` starts ``jupyter lab`` on 127.0.0.1 with a free port,
no token, fresh settings and workspaces (the news prompt turned off), and
stops it at the end.  :func:`browser` launches Debian's Chromium through
Playwright (``executable_path``: no browser is ever downloaded) with the
flags that keep it off the network.  Everything stays on this machine.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CHROMIUM = "/usr/bin/chromium"
CHROMIUM_FLAGS = ["--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader", "--disable-background-networking",
                  "--disable-component-update", "--disable-sync", "--disable-quic", "--no-first-run"]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class JupyterLab:
    """A JupyterLab server on 127.0.0.1 serving ``root``; a context manager.

    Args:
        root: the folder JupyterLab shows (notebooks are opened relative to it).
        env: extra environment for the server and its kernels.
        timeout: how long it may take to answer, s.

    Raises:
        RuntimeError: it did not answer within ``timeout`` s.
    """

    def __init__(self, root: Path, env: dict | None = None, timeout: float = 60.0):
        self.root = Path(root)
        self.port = free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        self._tmp = tempfile.mkdtemp(prefix="rtt-jupyterlab-")
        settings = Path(self._tmp) / "settings" / "@jupyterlab"
        for extension, plugin, values in (
                ("apputils-extension", "notification", {"fetchNews": "false", "checkForUpdates": False}),
                # every cell rendered, on screen or not: each output's page loads, a locator finds every cell
                ("notebook-extension", "tracker", {"windowingMode": "none"})):
            (settings / extension).mkdir(parents=True)
            (settings / extension / f"{plugin}.jupyterlab-settings").write_text(json.dumps(values))
        full_env = dict(os.environ, **(env or {}),
                        JUPYTERLAB_SETTINGS_DIR=str(Path(self._tmp) / "settings"),
                        JUPYTERLAB_WORKSPACES_DIR=str(Path(self._tmp) / "workspaces"),
                        JUPYTER_RUNTIME_DIR=str(Path(self._tmp) / "runtime"))
        jupyter = str(Path(sys.executable).parent / "jupyter")
        self.proc = subprocess.Popen(
            [jupyter, "lab", "--allow-root", "--no-browser", "--ip=127.0.0.1", f"--port={self.port}",
             "--ServerApp.token=", "--ServerApp.password=", "--ServerApp.port_retries=0",
             "--LabApp.check_for_updates_class=jupyterlab.NeverCheckForUpdate",
             f"--ServerApp.root_dir={self.root}"],
            env=full_env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
        deadline = time.monotonic() + timeout
        while True:
            with contextlib.suppress(OSError):
                socket.create_connection(("127.0.0.1", self.port), 0.2).close()
                break
            if self.proc.poll() is not None or time.monotonic() > deadline:
                self.close()
                raise RuntimeError(f"jupyter lab did not start on port {self.port}")
            time.sleep(0.2)  # polling a port that is not open yet: nothing to wait on

    def notebook_url(self, path: str) -> str:
        return f"{self.url}/lab/tree/{path}"

    def close(self) -> None:
        """Stop the server and every kernel it started (its process group)."""
        if self.proc.poll() is None:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(self.proc.pid, 15)
            try:
                self.proc.wait(10)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, 9)
                self.proc.wait(10)
        shutil.rmtree(self._tmp, ignore_errors=True)

    def __enter__(self) -> "JupyterLab":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


@contextlib.contextmanager
def browser(width: int = 1280, height: int = 1000):
    """A Playwright page in headless Debian Chromium; closed at the end."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as pw:
        b = pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_FLAGS)
        try:
            yield b.new_page(viewport={"width": width, "height": height})
        finally:
            b.close()
