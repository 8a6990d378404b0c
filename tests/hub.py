"""A class's JupyterHub for tests (``course/jupyterhub_config.py``), and learners who log in and run code.

:class:`Hub` starts ``jupyterhub`` on a port of 127.0.0.1 with a state
folder of its own; :class:`Learner` logs in through the hub's login form
(its session cookie, as a browser has), starts their server, and runs code
in a kernel of it over the kernel's WebSocket, as a notebook's cell does.
Every wait has a deadline.  One thread per object.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import signal
import socket
import subprocess
import sys
import time
import uuid
from pathlib import Path

import psutil
import requests

from tests.jupyterlab import stop_left

ROOT = Path(__file__).resolve().parent.parent
PASSWORD = "tanktutorial-test"


def free_port_block(size: int = 3) -> int:
    """A port p with p .. p+size-1 free on 127.0.0.1 (the hub, its proxy's API, its own API)."""
    for _ in range(50):
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        if port + size < 65535 and all(_free(port + i) for i in range(size)):
            return port
    raise RuntimeError("no block of free ports")


def _free(port: int) -> bool:
    with socket.socket() as s:
        try:
            s.bind(("127.0.0.1", port))
        except OSError:
            return False
    return True


class KernelDied(RuntimeError):
    """A learner's kernel died while it ran a test's code."""


class Hub:
    """``jupyterhub -f course/jupyterhub_config.py`` on 127.0.0.1, its state in ``state``.

    Args:
        state: the hub's state folder (database, learners' homes, the book of ROS domains).
        learners: the accounts allowed in.
        domains: the ROS domains to give out.
        extra_env: more of the hub's environment (``RTT_HUB_SPAWNER``, ``RTT_HUB_PYTHON``, ...).
        jupyterhub: the hub's program, if not this environment's (another JupyterHub version).
    """

    def __init__(
        self,
        state: Path,
        learners,
        domains,
        extra_env: dict | None = None,
        timeout: float = 60.0,
        jupyterhub: str | None = None,
    ):
        self.port = free_port_block()
        self.learners = list(learners)
        self.cgroups_left: list[str] = []  # learners' cgroups the hub's own stop did not remove (close)
        self.url = f"http://127.0.0.1:{self.port}"
        env = dict(
            os.environ,
            RTT_HUB_URL=self.url,
            RTT_HUB_STATE=str(state),
            RTT_HUB_LEARNERS=",".join(learners),
            RTT_HUB_PASSWORD=PASSWORD,
            RTT_HUB_DOMAINS=",".join(str(d) for d in domains),
            **(extra_env or {}),
        )
        env.pop("ROS_DOMAIN_ID", None)  # the learners' servers get theirs from the hub, nothing else
        self.log_path = Path(state) / "hub.log"
        Path(state).mkdir(parents=True, exist_ok=True)
        self._log = open(self.log_path, "w")  # noqa: SIM115 - closed in close()
        self.proc = subprocess.Popen(
            [
                jupyterhub or str(Path(sys.executable).with_name("jupyterhub")),
                "-f",
                str(ROOT / "course" / "jupyterhub_config.py"),
            ],
            cwd=state,
            env=env,
            stdout=self._log,
            stderr=subprocess.STDOUT,
            start_new_session=True,  # its proxy and the learners' servers stop with it (close)
        )
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                log = self.log()
                errors = [line for line in log.splitlines() if line.startswith(("[E ", "[C "))]  # its reasons
                raise RuntimeError("the hub exited: " + "\n".join(errors) + f"\n...\n{log[-2000:]}")
            try:
                if requests.get(self.url + "/hub/login", timeout=2).status_code == 200:
                    return
            except requests.ConnectionError:
                pass
            time.sleep(0.2)  # polling the hub's page, within the deadline
        self.close()
        raise RuntimeError(f"the hub did not answer within {timeout} s: {self.log()[-2000:]}")

    def log(self) -> str:
        self._log.flush()
        return self.log_path.read_text(errors="replace")

    def close(self) -> None:
        """Stop the hub, its proxy, every learner's server and every kernel those started."""
        # The kernels run in sessions of their own, out of reach of the hub's group: noted now,
        # while they are still the servers' children, and stopped by their ids at the end.
        descendants: list[psutil.Process] = []
        with contextlib.suppress(psutil.Error):
            descendants = psutil.Process(self.proc.pid).children(recursive=True)
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGTERM)
            try:
                self.proc.wait(20)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait(10)
        try:
            os.killpg(self.proc.pid, signal.SIGKILL)  # a learner's server or kernel left in the session
        except ProcessLookupError:
            pass
        stop_left(descendants)
        self._log.close()
        # The learners' cgroups (course/limits.py): each server's stop removes its own; one left is a fault,
        # noted for the test and removed here, with whatever still ran in it.
        for name in self.learners:
            for group in Path("/sys/fs/cgroup").glob(f"*/rtt-learner-{name}"):
                self.cgroups_left.append(str(group))
                deadline = time.monotonic() + 10
                while (pids := (group / "cgroup.procs").read_text().split()) and time.monotonic() < deadline:
                    for pid in pids:
                        with contextlib.suppress(ProcessLookupError):
                            os.kill(int(pid), signal.SIGKILL)
                    time.sleep(0.05)  # the killed processes leave the group as they are reaped, within the deadline
                with contextlib.suppress(OSError):
                    group.rmdir()


class Learner:
    """One learner: a browser's cookies, their server, and a kernel in it."""

    def __init__(self, hub: Hub, name: str):
        self.hub, self.name = hub, name
        self.http = requests.Session()
        self.kernel_id: str | None = None
        self.token: str | None = None

    def _xsrf(self) -> str:
        return self.http.cookies.get("_xsrf", path="/hub/") or self.http.cookies.get("_xsrf") or ""

    def log_in(self, password: str = PASSWORD) -> requests.Response:
        """Log in through the form; the response after the redirects (the spawn page, or the form again)."""
        page = self.http.get(self.hub.url + "/hub/login", timeout=10)
        xsrf = re.search(r'name="_xsrf" value="([^"]+)"', page.text)
        data = {"username": self.name, "password": password, "_xsrf": xsrf.group(1) if xsrf else self._xsrf()}
        return self.http.post(self.hub.url + "/hub/login?next=", data=data, timeout=30, allow_redirects=False)

    def request_server(self) -> requests.Response:
        """Ask the hub to start this learner's server; the hub's answer (201, 202, or 400 if already running)."""
        headers = {"X-XSRFToken": self._xsrf(), "Referer": self.hub.url + "/hub/home"}
        return self.http.post(f"{self.hub.url}/hub/api/users/{self.name}/server", headers=headers, timeout=60)

    def start_server(self, timeout: float = 120.0) -> str:
        """Ask the hub for this learner's server and wait until it answers; its URL.

        Raises:
            RuntimeError: the hub refused (the message it gave) or the server did not start in time.
        """
        headers = {"X-XSRFToken": self._xsrf(), "Referer": self.hub.url + "/hub/home"}
        r = self.request_server()
        if r.status_code not in (201, 202, 400):  # 400: already running
            raise RuntimeError(f"the hub refused {self.name}'s server: {r.status_code} {r.text[:500]}")
        base = f"{self.hub.url}/user/{self.name}/"
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            progress = self.http.get(f"{self.hub.url}/hub/api/users/{self.name}", headers=headers, timeout=10)
            if progress.ok:
                server = progress.json().get("servers", {}).get("", {})
                if server.get("ready"):
                    # A token of this learner's, as a notebook's own requests would carry, for their server's API.
                    t = self.http.post(
                        f"{self.hub.url}/hub/api/users/{self.name}/tokens",
                        headers=headers,
                        json={"note": "test", "expires_in": 3600},
                        timeout=30,
                    )
                    t.raise_for_status()
                    self.token = t.json()["token"]
                    return base
                if not server and time.monotonic() > deadline - timeout + 5:
                    raise RuntimeError(f"{self.name}'s server stopped: {self.server_error()}")
            time.sleep(0.5)  # polling the hub's record of the server, within the deadline
        raise RuntimeError(f"{self.name}'s server did not start within {timeout} s")

    def server(self) -> dict:
        """The hub's record of this learner's server (``started``, ``ready``, ...); {} if none."""
        headers = {"X-XSRFToken": self._xsrf(), "Referer": self.hub.url + "/hub/home"}
        r = self.http.get(f"{self.hub.url}/hub/api/users/{self.name}", headers=headers, timeout=10)
        r.raise_for_status()
        return r.json().get("servers", {}).get("", {})

    def server_error(self) -> str:
        """What the spawn page's event log tells the learner went wrong (the hub's progress events), or ""."""
        headers = {"X-XSRFToken": self._xsrf(), "Referer": self.hub.url + "/hub/home"}
        url = f"{self.hub.url}/hub/api/users/{self.name}/server/progress"
        with self.http.get(url, headers=headers, stream=True, timeout=(10, 10)) as r:
            for line in r.iter_lines(decode_unicode=True):
                if line and line.startswith("data:"):
                    event = json.loads(line[5:])
                    if event.get("failed") or event.get("ready"):
                        return event.get("message", "")
        return ""

    def api(self, method: str, path: str, **kw) -> requests.Response:
        """A request to this learner's server's REST API, with their token."""
        headers = {"Authorization": f"token {self.token}"}
        return requests.request(method, f"{self.hub.url}/user/{self.name}/{path}", headers=headers, timeout=30, **kw)

    def terminal(self, command: str, until: str, timeout: float = 60.0) -> str:
        """Type ``command`` into a new terminal of this learner's JupyterLab; what it printed once ``until`` showed.

        The terminal is closed afterwards.

        Raises:
            RuntimeError: ``until`` did not show within ``timeout`` s (the message holds what did).
        """
        from websockets.sync.client import connect

        r = self.api("POST", "api/terminals")
        r.raise_for_status()
        name = r.json()["name"]
        url = f"ws://127.0.0.1:{self.hub.port}/user/{self.name}/terminals/websocket/{name}"
        out = ""
        deadline = time.monotonic() + timeout
        try:
            with connect(url, additional_headers={"Authorization": f"token {self.token}"}, open_timeout=30) as ws:
                ws.send(json.dumps(["stdin", command + "\r"]))
                while until not in out:
                    left = deadline - time.monotonic()
                    if left <= 0:
                        raise RuntimeError(f"{self.name}'s terminal did not print {until!r} in {timeout} s: {out!r}")
                    kind, *text = json.loads(ws.recv(timeout=left))
                    if kind == "stdout":
                        out += text[0]
        finally:
            self.api("DELETE", f"api/terminals/{name}")
        return out

    def _kernel_answers(self, ws, deadline: float) -> None:
        """Ask the kernel for its info until it answers, as JupyterLab does on connecting (after a death,
        Jupyter restarts it, and what is sent to it meanwhile can be lost).

        Raises:
            RuntimeError: no answer before the monotonic time ``deadline``.
        """
        while time.monotonic() < deadline:
            ask = uuid.uuid4().hex
            header = {"msg_id": ask, "msg_type": "kernel_info_request", "username": self.name,
                      "session": uuid.uuid4().hex, "version": "5.3"}  # fmt: skip
            ws.send(json.dumps({"header": header, "parent_header": {}, "metadata": {}, "content": {},
                                "channel": "shell"}))  # fmt: skip
            again = min(deadline, time.monotonic() + 10.0)
            while (left := again - time.monotonic()) > 0:
                try:
                    msg = json.loads(ws.recv(timeout=left))
                except TimeoutError:
                    break
                if msg["header"]["msg_type"] == "kernel_info_reply" and msg["parent_header"].get("msg_id") == ask:
                    return
        raise RuntimeError(f"{self.name}'s kernel did not answer")

    def run(self, code: str, timeout: float = 120.0) -> str:
        """Run ``code`` in this learner's kernel (started on first use); its stdout and stderr as text.

        Raises:
            KernelDied: the kernel died meanwhile (Jupyter restarts it; its state is gone).
            RuntimeError: the code raised (its traceback), or it did not finish in ``timeout`` s.
        """
        from websockets.sync.client import connect

        if self.kernel_id is None:
            r = self.api("POST", "api/kernels", json={"name": "python3"})
            r.raise_for_status()
            self.kernel_id = r.json()["id"]
        url = f"ws://127.0.0.1:{self.hub.port}/user/{self.name}/api/kernels/{self.kernel_id}/channels"
        msg_id = uuid.uuid4().hex
        request = {
            "header": {"msg_id": msg_id, "msg_type": "execute_request", "username": self.name,
                       "session": uuid.uuid4().hex, "version": "5.3"},
            "parent_header": {}, "metadata": {}, "channel": "shell",
            "content": {"code": code, "silent": False, "store_history": False, "user_expressions": {},
                        "allow_stdin": False, "stop_on_error": True},
        }  # fmt: skip
        out, error = [], None
        deadline = time.monotonic() + timeout
        with connect(url, additional_headers={"Authorization": f"token {self.token}"}, open_timeout=30) as ws:
            self._kernel_answers(ws, deadline)
            ws.send(json.dumps(request))
            while True:
                left = deadline - time.monotonic()
                if left <= 0:
                    raise RuntimeError(f"code in {self.name}'s kernel did not finish in {timeout} s: {''.join(out)}")
                msg = json.loads(ws.recv(timeout=left))
                state = msg["content"].get("execution_state") if msg["header"]["msg_type"] == "status" else None
                if state in ("restarting", "dead"):  # the server's word: the kernel died (the OOM killer, ...)
                    raise KernelDied(f"{self.name}'s kernel died ({state}) running the code: {''.join(out)}")
                if msg.get("parent_header", {}).get("msg_id") != msg_id:
                    continue
                kind = msg["header"]["msg_type"]
                if kind == "stream":
                    out.append(msg["content"]["text"])
                elif kind == "error":
                    error = "\n".join(msg["content"]["traceback"])
                elif kind == "status" and msg["content"]["execution_state"] == "idle":
                    break
        if error is not None:
            raise RuntimeError(f"code in {self.name}'s kernel raised:\n{error}\n{''.join(out)}")
        return "".join(out)


# ---- a learner in Chromium: what a browser of theirs does through the hub ----


# A learner's cell: fetch the released assignment "hello" and submit it, with nbgrader's own commands.
SUBMIT = """
import os, subprocess, sys
for args in (["fetch_assignment", "hello"], ["submit", "hello"]):
    done = subprocess.run([os.path.join(os.path.dirname(sys.executable), "nbgrader"), *args],
                          cwd=os.path.expanduser("~"), capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
print("submitted")
"""


def submit_as(name: str) -> str:
    """A learner's cell that submits "hello" (fetched already) under another learner's ``name``."""
    return SUBMIT.replace(
        '(["fetch_assignment", "hello"], ["submit", "hello"])', f'(["submit", "hello", "--student", "{name}"],)'
    )


def teacher_course(folder: Path, exchange_root: Path) -> Path:
    """``folder``, made: a teacher's nbgrader course of this class, whose exchange is ``exchange_root``."""
    folder.mkdir()
    (folder / "nbgrader_config.py").write_text(
        "c = get_config()\nc.CourseDirectory.course_id = 'ros-tank-tutorial'\n"
        f"c.Exchange.root = {str(exchange_root)!r}\n"
    )
    return folder


def grading_leaves_out_the_forgery(teacher: Path, exchange_root: Path, forger: str, named: str) -> None:
    """The teacher's grading (course/grade.py) stages ``forger``'s and ``named``'s own submissions and leaves
    out the one ``forger`` handed in under ``named``'s name."""
    if str(ROOT / "course") not in sys.path:
        sys.path.insert(0, str(ROOT / "course"))
    import grade  # course/ is not a package

    staged, refused, unchecked = grade.stage_submissions(teacher_course(teacher, exchange_root))
    assert len(refused) == 1 and refused[0].endswith(f": handed in by {forger}, not {named}"), refused
    assert unchecked == []
    inbound = staged / "ros-tank-tutorial" / "inbound"
    assert sorted(p.name.split("+")[0] for p in inbound.iterdir()) == sorted([forger, named])


def open_live_notebook(browser, hub_url: str, name: str):
    """A page of a new browser context (cookies of its own): ``name`` logs in through the hub's form and runs
    the first cell of ``live.ipynb`` in their home (a live view: ``tests.lab_browser.step2_notebook``)."""
    from tests.lab_browser import run_first_cell

    page = browser.new_context(viewport={"width": 1000, "height": 800}).new_page()
    page.goto(hub_url + "/hub/login")
    page.fill("input[name=username]", name)
    page.fill("input[name=password]", PASSWORD)
    page.click("input[type=submit], button[type=submit]")
    page.wait_for_url(f"**/user/{name}/**", timeout=60_000)
    run_first_cell(page, f"{hub_url}/user/{name}/lab/workspaces/live/tree/live.ipynb")
    return page


def require_live_view_draws(page, name: str) -> None:
    """Wait until the page's live view has drawn its scene and frames; none dropped, and not blank."""
    from tests.lab_browser import STATS

    drawing = f"(() => {{ const s = ({STATS})(); return s && s.scenes >= 1 && s.frames > 5; }})()"
    page.wait_for_function(drawing, timeout=90_000)
    seen = page.evaluate(STATS)
    assert seen["dropped"] == 0, (name, seen)
    shot = page.locator("iframe.rtt-live-view").screenshot()
    assert len(shot) > 10_000, f"{name}'s live view is blank"  # a drawn scene, not an empty canvas
