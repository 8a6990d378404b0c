"""A learner's Jupyter proxies only the ports their own processes serve.

jupyter-server-proxy opens ``/user/<name>/proxy/<port>/`` onto any port of the server's machine (its
``host_allowlist`` is not consulted for this machine's ports): on a shared server, learner A could open
learner B's meshcat page, or any other learner's server on 127.0.0.1, through A's own Jupyter.  This module is
a Jupyter server extension the hub turns on in every learner's server (``course/jupyterhub_config.py``): its
handler comes before jupyter-server-proxy's for ``/proxy/<port>/`` and ``/proxy/absolute/<port>/`` and refuses
(403) a port unless a socket listening on 127.0.0.1 (or on every IPv4 address) at that port belongs to a process
of this learner's server: those in its memory cgroup (``rtt-learner-<name>``, ``course/limits.py``) or, without
one, those of its Unix user.  Then it proxies to 127.0.0.1 (not "localhost", which may be another address),
as jupyter-server-proxy does.  The hub also empties the proxy's ``host_allowlist``, so ``/proxy/HOST:PORT/``
reaches nothing.  The check runs on the Jupyter server's thread, per request.

What it does not stop: a learner's own processes (a terminal, a notebook) reaching another learner's port on
127.0.0.1 directly; a network namespace per learner (containers) does.
"""

from __future__ import annotations

import os
from pathlib import Path

LISTEN = "0A"  # /proc/net/tcp's state of a listening socket
LOOPBACK = "127.0.0.1"
# /proc/net/tcp's local addresses (hex, in the kernel's byte order) a proxied connection to 127.0.0.1 reaches
REACHED = {"0100007F", "00000000"}  # 127.0.0.1, 0.0.0.0


def _jupyter_server_extension_points():
    return [{"module": "own_ports"}]


def _load_jupyter_server_extension(server_app):
    from jupyter_server.utils import url_path_join
    from jupyter_server_proxy.handlers import LocalProxyHandler, ProxyHandler
    from tornado import web

    class OwnPortsProxyHandler(LocalProxyHandler):
        async def prepare(self, *args, **kwargs):
            await super().prepare(*args, **kwargs)  # authentication first: a stranger learns nothing of ports
            port = int(self.path_args[0])
            if not served_by_own_process(port):
                self.log.warning("proxy to port %d refused: no process of this learner's serves it", port)
                raise web.HTTPError(403, f"port {port} is not served by a process of yours")

        def proxy(self, port, proxied_path):
            return ProxyHandler.proxy(self, LOOPBACK, port, proxied_path)  # the address checked, not "localhost"

        async def open(self, port, proxied_path):
            return await self.proxy_open(LOOPBACK, port, proxied_path)

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
    """``socket:[inode]`` of each socket listening on TCP ``port`` that a connection to 127.0.0.1 reaches
    (bound to 127.0.0.1 or to every IPv4 address; an IPv6 socket on every address takes IPv4 too)."""
    found = set()
    for table, reached in (("/proc/net/tcp", REACHED), ("/proc/net/tcp6", {"0" * 32})):
        try:
            lines = Path(table).read_text().splitlines()[1:]
        except OSError:
            continue
        for line in lines:
            fields = line.split()
            address, hex_port = fields[1].rsplit(":", 1)
            if int(hex_port, 16) == port and fields[3] == LISTEN and address in reached:
                found.add(f"socket:[{fields[9]}]")
    return found


def own_processes() -> list[int]:
    """The processes of this learner's memory cgroup (``rtt-learner-<name>``); without it, those of this user."""
    own = f"/rtt-learner-{os.environ.get('JUPYTERHUB_USER', '')}"
    for line in Path("/proc/self/cgroup").read_text().splitlines():
        _, controllers, path = line.split(":", 2)
        if "memory" in controllers.split(",") and path == own:
            procs = Path("/sys/fs/cgroup/memory") / path.lstrip("/") / "cgroup.procs"
            return [int(p) for p in procs.read_text().split()]
    uid = os.getuid()
    return [int(p) for p in os.listdir("/proc") if p.isdigit() and _owner(p) == uid]


def _owner(pid: str) -> int | None:
    try:
        return os.stat(f"/proc/{pid}").st_uid
    except OSError:
        return None
