"""JupyterLab in headless Chromium, driven by Playwright, for the browser tests of the notebooks.

:class:`JupyterLab` starts ``jupyter lab`` on 127.0.0.1 with a free port,
no token, the Jupyter configuration ``make notebooks`` gives a learner
(:data:`LEARNER_CONFIG`), and a fresh Jupyter home of its own (configuration, data with
its own notebook-trust database, runtime, settings with the news prompt,
update checks, autosave and the extension manager turned off, workspaces,
IPython profile): the learner's files are never read or written.  It
stops the server, every kernel it started and their children at the end.
:func:`browser` launches Debian's Chromium through Playwright
(``executable_path``: no browser is ever downloaded) with the flags that
keep it off the network, and refuses (and lists) every request for
anything but 127.0.0.1.  Everything stays on this machine.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import psutil

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser") or "/usr/bin/chromium"
CHROMIUM_FLAGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--enable-unsafe-swiftshader",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-quic",
    "--no-first-run",
    "--disable-breakpad",
    "--disable-crash-reporter",
    # no name resolves to anything but 127.0.0.1: a stray lookup cannot leave the machine
    "--host-resolver-rules=MAP * ~NOTFOUND, EXCLUDE 127.0.0.1",
]
# Every URL the browser may load: this server's pages and meshcat's, all on 127.0.0.1, and in-page data.
_OFF_HOST = re.compile(r"^(?!(https?|wss?)://127\.0\.0\.1[:/]|data:|blob:|about:|chrome-error:)")


def _off(host: str) -> re.Pattern:
    """Every URL but ``host``'s (a test's own network host) and in-page data."""
    return re.compile(rf"^(?!(https?|wss?)://{re.escape(host)}[:/]|data:|blob:|about:|chrome-error:)")


# The Jupyter configuration `make notebooks` gives a learner's JupyterLab (nbgrader left out).
# The server as a plain `pip install` or Colab runs it: without the project's nodelay server extension
# (tutorial/view/widget/nodelay.py), so the kernel's WebSocket keeps Nagle's algorithm, and Jupyter's
# default IOPub limits.
WITHOUT_NODELAY = ("--ServerApp.jpserver_extensions=tutorial.view.widget.nodelay=False",)
LEARNER_CONFIG = Path(__file__).resolve().parents[1] / "jupyter-config" / "learner"

# Settings for the test's JupyterLab, by extension and plugin.
SETTINGS = {
    ("apputils-extension", "notification"): {"fetchNews": "false", "checkForUpdates": False},  # no news prompt
    # JupyterLab's default, what a learner has: every cell is in the page (a locator finds each one),
    # and the browser skips drawing the cells out of sight (their 3D pages wait, instead of taking the CPU)
    ("notebook-extension", "tracker"): {"windowingMode": "contentVisibility"},
    ("docmanager-extension", "plugin"): {"autosave": False},  # a notebook is saved when the test says so
    ("extensionmanager-extension", "plugin"): {"enabled": False},  # it would list extensions from PyPI
}


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class JupyterLab:
    """A JupyterLab server on 127.0.0.1 serving ``root``; a context manager.

    Args:
        root: the folder JupyterLab shows (notebooks are opened relative to it).
        env: extra environment for the server and its kernels; a value of
            None removes that variable (e.g. ``{"RTT_TEST_MODE": None}``).
        timeout: how long it may take to answer, s.
        ip: the address it listens on.
        prefix: a command it runs under (a test host's, tests/netns.py).
        server_args: more command-line options of the server (``--ServerApp.x=y``).
        app: ``"lab"`` (JupyterLab) or ``"notebook"`` (Notebook 7, the same server with its own pages).

    Raises:
        RuntimeError: it did not answer within ``timeout`` s.

    Owned by one thread.  :meth:`close` stops everything it started, even
    the kernels (each runs in a session of its own, out of the server's
    process group) and their children (e.g. meshcat servers).
    """

    def __init__(
        self,
        root: Path,
        env: dict | None = None,
        timeout: float = 60.0,
        ip: str = "127.0.0.1",
        prefix=(),
        server_args=(),
        app: str = "lab",
    ):
        if app not in ("lab", "notebook"):
            raise ValueError(f"app: 'lab' or 'notebook', not {app!r}")
        self.app = app
        self.root = Path(root)
        self.port = free_port()
        self.url = f"http://{ip}:{self.port}"
        self._tmp = Path(tempfile.mkdtemp(prefix="rtt-jupyterlab-"))
        for (extension, plugin), values in SETTINGS.items():
            folder = self._tmp / "settings" / "@jupyterlab" / extension
            folder.mkdir(parents=True, exist_ok=True)
            (folder / f"{plugin}.jupyterlab-settings").write_text(json.dumps(values))
        home = {
            "JUPYTERLAB_SETTINGS_DIR": "settings",
            "JUPYTERLAB_WORKSPACES_DIR": "workspaces",
            "JUPYTER_CONFIG_DIR": "config",
            "JUPYTER_DATA_DIR": "data",
            "JUPYTER_RUNTIME_DIR": "runtime",
            "IPYTHONDIR": "ipython",
        }
        self.env = dict(os.environ, **{k: str(self._tmp / v) for k, v in home.items()})
        self.env["JUPYTER_CONFIG_PATH"] = str(LEARNER_CONFIG)  # as make notebooks
        for key, value in (env or {}).items():
            if value is None:
                self.env.pop(key, None)
            else:
                self.env[key] = str(value)
        self._descendants: dict[int, object] = {}
        jupyter = str(Path(sys.executable).parent / "jupyter")
        self.proc = subprocess.Popen(
            [
                *prefix,  # e.g. a test host's command (tests/netns.py): the server runs on that host
                jupyter,
                app,
                "--allow-root",
                "--no-browser",
                f"--ip={ip}",
                f"--port={self.port}",
                "--ServerApp.token=",
                "--ServerApp.password=",
                "--ServerApp.port_retries=0",
                "--LabApp.check_for_updates_class=jupyterlab.NeverCheckForUpdate",
                f"--ServerApp.root_dir={self.root}",
                *server_args,
            ],
            env=self.env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )
        deadline = time.monotonic() + timeout
        while True:
            # Listening: the server writes its runtime file once its port is open (seen from any host).
            if list((self._tmp / "runtime").glob("jpserver-*.json")):
                break
            if self.proc.poll() is not None or time.monotonic() > deadline:
                self.close()
                raise RuntimeError(f"jupyter {app} did not start on port {self.port}")
            time.sleep(0.2)  # polling a port that is not open yet: nothing to wait on

    def notebook_url(self, path: str, workspace: str | None = None) -> str:
        """The page that opens ``path``; in a fresh named ``workspace`` (no other tab reopened) if given (lab)."""
        if self.app == "notebook":
            return f"{self.url}/notebooks/{path}"
        return f"{self.url}/lab/workspaces/{workspace}/tree/{path}" if workspace else f"{self.url}/lab/tree/{path}"

    def note_processes(self) -> None:
        """Remember every process the server has started so far (kernels, their meshcat servers) for :meth:`close`."""
        with contextlib.suppress(psutil.Error):
            for child in psutil.Process(self.proc.pid).children(recursive=True):
                self._descendants.setdefault(child.pid, child)

    def close(self) -> None:
        """Stop the server, every kernel it started and their children (any of them still running)."""
        if self.proc.poll() is None:
            self.note_processes()
            # SIGTERM: the server shuts its kernels down, then exits
            with contextlib.suppress(ProcessLookupError):
                os.killpg(self.proc.pid, signal.SIGTERM)
            try:
                self.proc.wait(15)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait(10)
        # The kernels run in sessions of their own: whatever outlived the server is stopped by its id.
        stop_left(self._descendants.values())
        shutil.rmtree(self._tmp, ignore_errors=True)

    def __enter__(self) -> JupyterLab:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def stop_left(processes) -> None:
    """Stop those of ``processes`` (``psutil.Process``) still running: SIGTERM, then SIGKILL after 5 s.

    For processes that outlive the process group they were started in (a
    kernel runs in a session of its own).  ``psutil.Process`` checks the
    start time too, so an id the system has reused is never hit.
    """
    left = [p for p in processes if p.is_running()]
    for p in left:
        with contextlib.suppress(psutil.Error):
            p.terminate()
    _, alive = psutil.wait_procs(left, timeout=5)
    for p in alive:
        with contextlib.suppress(psutil.Error):
            p.kill()
    psutil.wait_procs(alive, timeout=5)


@contextlib.contextmanager
def browser(width: int = 1280, height: int = 1000, refused: list | None = None, host: str = "127.0.0.1"):
    """A Playwright page in headless Debian Chromium; closed at the end.

    Args:
        width, height: the viewport, px.
        refused: if given, every request for anything but ``host`` is
            appended to it (and refused in any case).
        host: the one host the page may load from (a test's own network host, or 127.0.0.1).
    """
    from playwright.sync_api import sync_playwright

    def refuse(route) -> None:
        if refused is not None:
            refused.append(route.request.url)
        route.abort("blockedbyclient")

    with sync_playwright() as pw:
        flags = CHROMIUM_FLAGS
        if host != "127.0.0.1":  # the test's own host is the one more address that resolves
            flags = [f + f", EXCLUDE {host}" if f.startswith("--host-resolver-rules=") else f for f in flags]
        b = pw.chromium.launch(executable_path=CHROMIUM, args=flags)
        try:
            context = b.new_context(viewport={"width": width, "height": height})
            context.route(_OFF_HOST if host == "127.0.0.1" else _off(host), refuse)
            yield context.new_page()
        finally:
            b.close()
