"""A Jupyter server extension: the kernel's WebSocket sends each message at once (``TCP_NODELAY``).

jupyter_server leaves Nagle's algorithm on for the WebSocket between the
kernel and the browser, and tornado's documentation warns what that costs
a stream of small messages: a message waits until the browser has
acknowledged the one before, and a browser delays its acknowledgements
(40 ms on Linux).  A live view's frame is one small message every 20 ms, so
each waited about 40 ms (``make bench``'s widget experiment: the Benchmarks
page, "Live views in the notebook").  This extension turns the delay off on
every kernel WebSocket, as tornado advises (``set_nodelay(True)`` once the
connection is open).

It is enabled by the file
``etc/jupyter/jupyter_server_config.d/ros_tank_tutorial.json`` of the
environment, so any Jupyter server of it (``make notebooks``, a hub's
learner servers) loads it.  ``pip install .`` puts the file there (the
package's data files); an editable install does not, so ``make`` (and a
server's image after ``pip install -e``) runs
``python -m tutorial.view.widget.nodelay``, which writes it.  The extension
runs once, in the server's process, when the server starts.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

SETTING = {"ServerApp": {"jpserver_extensions": {"tutorial.view.widget.nodelay": True}}}


def _jupyter_server_extension_points() -> list[dict]:
    return [{"module": "tutorial.view.widget.nodelay"}]


def _load_jupyter_server_extension(serverapp) -> None:
    from jupyter_server.services.kernels.websocket import KernelWebsocketHandler

    if getattr(KernelWebsocketHandler, "rtt_nodelay", False):
        return
    open_connection = KernelWebsocketHandler.open

    async def open_without_delay(self, *args, **kwargs):
        result = await open_connection(self, *args, **kwargs)
        self.set_nodelay(True)
        return result

    KernelWebsocketHandler.open = open_without_delay
    KernelWebsocketHandler.rtt_nodelay = True
    serverapp.log.info("ros-tank-tutorial: kernel WebSockets send each message at once (TCP_NODELAY)")


def enable(prefix: str = sys.prefix) -> Path:
    """Write the file that enables this extension in the environment at ``prefix``; its path."""
    path = Path(prefix) / "etc" / "jupyter" / "jupyter_server_config.d" / "ros_tank_tutorial.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(SETTING, indent=2) + "\n")
    return path


if __name__ == "__main__":
    print(f"enabled the kernel WebSockets' TCP_NODELAY: {enable()}")
