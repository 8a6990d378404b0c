"""A learner's Jupyter proxies only the ports their own processes serve.

jupyter-server-proxy opens ``/user/<name>/proxy/<port>/`` onto any port of the server's machine (its
``host_allowlist`` is not consulted for this machine's ports): on a shared server, learner A could open
learner B's meshcat page, or any other learner's server on 127.0.0.1, through A's own Jupyter.  This module is
a Jupyter server extension the hub turns on in every learner's server (``course/jupyterhub_config.py``): its
handler comes before jupyter-server-proxy's for ``/proxy/<port>/`` and ``/proxy/absolute/<port>/`` and refuses
(403) a port unless the socket listening on it belongs to a process of this learner's server: those in its
memory cgroup (``course/limits.py``) or, without one, those of its Unix user.  Then it proxies as
jupyter-server-proxy does.  The check runs on the Jupyter server's thread, per request.
"""

from __future__ import annotations

import os
from pathlib import Path

LISTEN = "0A"  # /proc/net/tcp's state of a listening socket


def _jupyter_server_extension_points():
    return [{"module": "own_ports"}]


def _load_jupyter_server_extension(server_app):
    from jupyter_server.utils import url_path_join
    from jupyter_server_proxy.handlers import LocalProxyHandler
    from tornado import web

    class OwnPortsProxyHandler(LocalProxyHandler):
        async def prepare(self, *args, **kwargs):
            await super().prepare(*args, **kwargs)  # authentication first: a stranger learns nothing of ports
            port = int(self.path_args[0])
            if not served_by_own_process(port):
                self.log.warning("proxy to port %d refused: no process of this learner's serves it", port)
                raise web.HTTPError(403, f"port {port} is not served by a process of yours")

    base = server_app.web_app.settings["base_url"]
    handlers = [
        (url_path_join(base, r"/proxy/(\d+)(/.*|)"), OwnPortsProxyHandler, {"absolute_url": False}),
        (url_path_join(base, r"/proxy/absolute/(\d+)(/.*|)"), OwnPortsProxyHandler, {"absolute_url": True}),
    ]
    server_app.web_app.add_handlers(".*", handlers)
    # Tornado tries a host's rules in the order they were added, and puts a new one just before its last (the
    # wildcard); jupyter-server-proxy's came earlier: ours is moved first.
    rules = server_app.web_app.default_router.rules
    rules.insert(0, rules.pop(-2))


def served_by_own_process(port: int) -> bool:
    """Whether a socket listening on TCP ``port`` is held by one of this server's processes."""
    inodes = listening_inodes(port)
    if not inodes:
        return False
    for pid in own_processes():
        try:
            fds = os.listdir(f"/proc/{pid}/fd")
        except OSError:
            continue
        for fd in fds:
            try:
                if os.readlink(f"/proc/{pid}/fd/{fd}") in inodes:
                    return True
            except OSError:
                continue
    return False


def listening_inodes(port: int) -> set[str]:
    """``socket:[inode]`` of each socket listening on TCP ``port`` (IPv4 and IPv6)."""
    found = set()
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        try:
            lines = Path(table).read_text().splitlines()[1:]
        except OSError:
            continue
        for line in lines:
            fields = line.split()
            if int(fields[1].rsplit(":", 1)[1], 16) == port and fields[3] == LISTEN:
                found.add(f"socket:[{fields[9]}]")
    return found


def own_processes() -> list[int]:
    """The processes of this server's memory cgroup; without one (the root group), those of its user."""
    for line in Path("/proc/self/cgroup").read_text().splitlines():
        _, controllers, path = line.split(":", 2)
        if "memory" in controllers.split(",") and path != "/":
            procs = Path("/sys/fs/cgroup/memory") / path.lstrip("/") / "cgroup.procs"
            return [int(p) for p in procs.read_text().split()]
    uid = os.getuid()
    return [int(p) for p in os.listdir("/proc") if p.isdigit() and _owner(p) == uid]


def _owner(pid: str) -> int | None:
    try:
        return os.stat(f"/proc/{pid}").st_uid
    except OSError:
        return None
