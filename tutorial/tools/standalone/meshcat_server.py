"""Start a meshcat server that listens on 127.0.0.1 only and takes a frame's transforms as one message.

meshcat-python's own server binds its ZeroMQ socket to 127.0.0.1 but serves
the web page on every interface.  This module runs that same server (its
``ZMQWebSocketBridge``) with the web server bound to 127.0.0.1, and makes it
exit when the process that started it goes away, so no server is left behind.

It also knows one command meshcat's does not: ``set_transforms``, a frame's
transforms in one message (:mod:`tutorial.view.meshcat_batch`), and serves
a page that draws it (:mod:`tutorial.view.meshcat_page`; it also leaves out
multisampling where the browser renders without a GPU).  With
``batch=False`` it is meshcat's server and page as they ship, only bound to
127.0.0.1 and answering what meshcat's handler cannot take with an error
(the benchmark's bare baseline).

``python -m tutorial.tools.standalone.meshcat_server`` prints ``zmq_url=...`` and
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


def through_jupyter(web_url: str, environ=None) -> str | None:
    """The page at ``web_url`` through the Jupyter server this process runs under, if any; else None.

    On a JupyterHub, Binder, or a machine behind an SSH tunnel, a browser
    reaches only Jupyter's port, and 127.0.0.1 is its own machine, not the
    server's.  jupyter-server-proxy (installed with the project's
    ``notebook`` extra) serves ``<Jupyter's address>/proxy/PORT/`` from the
    server's own 127.0.0.1:PORT, for the user logged in to Jupyter alone; the
    page finds the server's WebSocket under that path
    (:mod:`tutorial.view.meshcat_page`).

    Args:
        web_url: the page on this machine, e.g. ``http://127.0.0.1:7000/static/``.
        environ: the environment to read (default ``os.environ``): a JupyterHub
            single-user server's (``JUPYTERHUB_SERVICE_PREFIX``, and
            ``JUPYTERHUB_PUBLIC_URL`` when the hub knows its public address)
            or a Jupyter terminal's (``JUPYTER_SERVER_URL``), inherited by
            every program started from it.

    Returns:
        A URL, or on a hub that does not know its public address, the path to
        put after it (``/user/NAME/proxy/7000/static/``); None outside Jupyter,
        or where jupyter-server-proxy is not installed.  Any thread.
    """
    import importlib.util
    from urllib.parse import urlsplit

    environ = os.environ if environ is None else environ
    if importlib.util.find_spec("jupyter_server_proxy") is None:
        return None
    tail = f"proxy/{urlsplit(web_url).port}/static/"
    if environ.get("JUPYTERHUB_SERVICE_PREFIX"):
        public = environ.get("JUPYTERHUB_PUBLIC_URL") or environ["JUPYTERHUB_SERVICE_PREFIX"]
        return public.rstrip("/") + "/" + tail
    if environ.get("JUPYTER_SERVER_URL"):
        return environ["JUPYTER_SERVER_URL"].rstrip("/") + "/" + tail
    return None


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


def start_server(timeout: float = 20.0, batch: bool = True) -> MeshcatServer:
    """Start a localhost-only meshcat server in a child process.

    Args:
        timeout: s to wait for the server's URLs.
        batch: take ``set_transforms`` and serve the page that draws it; False runs
            meshcat's own server and page unchanged (still bound to 127.0.0.1).

    Returns:
        The running :class:`MeshcatServer`.

    Raises:
        RuntimeError: the server exited or printed no URLs within ``timeout`` s.
    """
    import selectors
    import time

    proc = subprocess.Popen(
        [sys.executable, "-u", "-m", "tutorial.tools.standalone.meshcat_server", "--parent", str(os.getpid())]
        + ([] if batch else ["--no-batch"]),
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

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--parent", type=int, default=0, help="exit when this process id is gone")
    parser.add_argument("--no-batch", action="store_true", help="meshcat's own server and page (no set_transforms)")
    args = parser.parse_args(argv)

    LocalhostBridge, BatchingBridge = _bridge_classes()
    bridge = (LocalhostBridge if args.no_batch else BatchingBridge)(host=HOST)
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


def _bridge_classes():
    """The two server classes, made on first use (meshcat's server module starts zmq when imported)."""
    import tornado.web
    import tornado.websocket
    import zmq
    from meshcat.servers.zmqserver import VIEWER_HTML, VIEWER_ROOT, ZMQWebSocketBridge, find_node

    from tutorial.view import meshcat_batch, meshcat_page

    class LocalhostBridge(ZMQWebSocketBridge):
        """meshcat's server with its web server bound to 127.0.0.1 (the tornado IO loop's thread).

        A command meshcat's own handler cannot take (a frame that is not
        UTF-8, a path deeper than Python's recursion limit) would end its
        handler without a reply, and a REP socket that never replies never
        reads again: every later client would wait forever.  Here it is
        answered with ``error: ...`` instead, and the server goes on.
        """

        def make_app(self):
            app = super().make_app()
            listen = app.listen
            app.listen = lambda port, **kw: listen(port, address=HOST, **kw)
            return app

        def handle_zmq(self, frames):
            """One zmq request, taken by :meth:`take`; whatever it raises is answered, never left unanswered."""
            try:
                self.take(frames)
            except Exception as error:  # any input: one error reply, never a dead socket
                try:
                    self.zmq_socket.send(f"error: {type(error).__name__}".encode())
                except zmq.ZMQError:  # the handler had replied before it failed: nothing more to send
                    pass

        def take(self, frames):
            """One zmq request, as meshcat's server takes it."""
            ZMQWebSocketBridge.handle_zmq(self, frames)

        def forward_to_websockets(self, frames):
            """Send a command's bytes to every open page; a page that closed meanwhile is skipped.

            (Its ``on_close`` takes it out of the pool; until then, writing to it
            raises, which in meshcat's own loop would leave the request unanswered.)
            """
            for websocket in list(self.websocket_pool):
                try:
                    websocket.write_message(frames[2], binary=True)
                except tornado.websocket.WebSocketClosedError:
                    pass

    with open(f"{VIEWER_ROOT}/{VIEWER_HTML}", encoding="utf-8") as f:
        page = meshcat_page.with_page_script(f.read())  # made once: the files are the installed package's

    class PageHandler(tornado.web.RequestHandler):
        """``GET /static/``: meshcat's own ``index.html`` with the project's script added (:mod:`.meshcat_page`)."""

        def get(self):
            self.set_header("Content-Type", "text/html; charset=utf-8")
            self.set_header("Cache-Control", "no-store, no-cache, must-revalidate, max-age=0")
            self.write(page)

    class BatchingBridge(LocalhostBridge):
        """:class:`LocalhostBridge` that also takes ``set_transforms`` (the tornado IO loop's thread).

        Everything runs on the server's one IO loop thread, as meshcat's own
        handlers do, so the scene tree needs no lock.
        """

        def make_app(self):
            app = super().make_app()
            # Ahead of meshcat's own /static/ files (tornado takes the first rule that matches; the
            # Application has no public call to put a rule first): the page.  Every other file,
            # meshcat's script among them, is still meshcat's own.
            app.wildcard_router.rules.insert(0, tornado.web.url(r"/static/(?:index\.html)?", PageHandler))
            return app

        def take(self, frames):
            """One zmq request: ``set_transforms`` here, everything else as meshcat's server does."""
            if frames[0] != meshcat_batch.SET_TRANSFORMS.encode():
                return super().take(frames)
            try:
                if len(frames) != 3:
                    raise meshcat_batch.BadBatch("expected 3 frames")
                commands = meshcat_batch.split_batch(frames[2])
            except meshcat_batch.BadBatch as error:  # told to the sender; nothing stored, nothing forwarded
                self.zmq_socket.send(f"error: {error}".encode())
                return
            for path, data in commands:  # as meshcat's server stores a set_transform, for pages that open later
                find_node(self.tree, path).transform = data
            if commands:
                self.forward_to_websockets(frames)  # one WebSocket message for the whole frame
            self.zmq_socket.send(b"ok")

    return LocalhostBridge, BatchingBridge


if __name__ == "__main__":
    main()
