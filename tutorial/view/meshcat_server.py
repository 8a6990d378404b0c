"""Start a meshcat server that listens on 127.0.0.1 only.

meshcat-python's own server binds its ZeroMQ socket to 127.0.0.1 but serves
the web page on every interface.  This module runs that same server (its
``ZMQWebSocketBridge``) with the web server bound to 127.0.0.1, and makes it
exit when the process that started it goes away, so no server is left behind.

``python -m tutorial.view.meshcat_server`` prints ``zmq_url=...`` and
``web_url=...`` lines, as meshcat's own server does.
"""

from __future__ import annotations

import os
import subprocess
import sys
from dataclasses import dataclass

HOST = "127.0.0.1"


@dataclass
class MeshcatServer:
    """A running meshcat server process.

    Attributes:
        process: the server's ``subprocess.Popen``.
        zmq_url: where a ``meshcat.Visualizer`` connects, e.g. ``tcp://127.0.0.1:6000``.
        web_url: the page to open in a browser, e.g. ``http://127.0.0.1:7000/static/``.
    """

    process: subprocess.Popen
    zmq_url: str
    web_url: str

    def visualizer(self):
        """A ``meshcat.Visualizer`` connected to this server.

        Its zmq socket is not thread-safe: the thread that calls this owns it.
        """
        import meshcat

        return meshcat.Visualizer(window=_quiet_window(self.zmq_url))

    def close(self, timeout: float = 3.0) -> None:
        """Stop the server process (any thread)."""
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(timeout)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait(timeout)


def _quiet_window(zmq_url: str):
    """meshcat's ``ViewerWindow`` for an existing server, without its print of the URL.

    (Silencing it by swapping ``sys.stdout`` would swallow other threads'
    output too: in a notebook, the kernel's.)  The steps are meshcat's own:
    connect, ask the server for its page URL, connect again.
    """
    from meshcat.visualizer import ViewerWindow

    class QuietWindow(ViewerWindow):
        def __init__(self, url: str):  # noqa: D401 - mirrors ViewerWindow.__init__ with start_server=False
            self.server_proc = None
            self.zmq_url = url
            self.connect_zmq()
            self.web_url = self.request_web_url()
            self.connect_zmq()

    return QuietWindow(zmq_url)


def start_server(timeout: float = 20.0) -> MeshcatServer:
    """Start a localhost-only meshcat server in a child process.

    Returns:
        The running :class:`MeshcatServer`.

    Raises:
        RuntimeError: the server exited or printed no URLs within ``timeout`` s.
    """
    import selectors
    import time

    proc = subprocess.Popen(
        [sys.executable, "-u", "-m", "tutorial.view.meshcat_server", "--parent", str(os.getpid())],
        stdout=subprocess.PIPE,
        bufsize=0,  # unbuffered: select() must see every line that readline() has not taken yet
        stderr=subprocess.DEVNULL,
        start_new_session=True,  # a Ctrl-C in a notebook or terminal is not sent to it; we stop it
    )
    urls: dict[str, str] = {}
    sel = selectors.DefaultSelector()
    sel.register(proc.stdout, selectors.EVENT_READ)
    deadline = time.monotonic() + timeout
    while len(urls) < 2:
        left = deadline - time.monotonic()
        if left <= 0 or proc.poll() is not None:
            proc.kill()
            raise RuntimeError(f"the meshcat server did not start (no URLs within {timeout:.0f} s)")
        if sel.select(left):
            line = proc.stdout.readline().decode().strip()
            key, _, value = line.partition("=")
            if key in ("zmq_url", "web_url"):
                urls[key] = value
    sel.close()
    return MeshcatServer(proc, urls["zmq_url"], urls["web_url"])


def main(argv=None) -> None:
    """Run the server until its parent process ends (the child side of :func:`start_server`)."""
    import argparse

    import tornado.ioloop
    from meshcat.servers.zmqserver import ZMQWebSocketBridge

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--parent", type=int, default=0, help="exit when this process id is gone")
    args = parser.parse_args(argv)

    class LocalhostBridge(ZMQWebSocketBridge):
        def make_app(self):
            app = super().make_app()
            listen = app.listen
            app.listen = lambda port, **kw: listen(port, address=HOST, **kw)
            return app

    bridge = LocalhostBridge(host=HOST)
    print(f"zmq_url={bridge.zmq_url}", flush=True)
    print(f"web_url={bridge.web_url}", flush=True)

    if args.parent:

        def check_parent() -> None:
            if os.getppid() != args.parent:
                tornado.ioloop.IOLoop.current().stop()

        tornado.ioloop.PeriodicCallback(check_parent, 500).start()
    try:
        bridge.run()
    except KeyboardInterrupt:
        pass


if __name__ == "__main__":
    main()
