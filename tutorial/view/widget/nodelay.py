"""A Jupyter server extension for the live views: the kernel's WebSocket sends each message at once
(``TCP_NODELAY``), and a view's answers are not shown as the kernel's work.  (It is named for the first.)

**No delay.** jupyter_server leaves Nagle's algorithm on for the WebSocket
between the kernel and the browser, and tornado's documentation warns what
that costs a stream of small messages: a message waits until the browser
has acknowledged the one before, and a browser delays its acknowledgements
(40 ms on Linux).  A live view's frame is one small message every 20 ms, so
each waited about 40 ms (``make bench``'s widget experiment: the Benchmarks
page, "Live views in the notebook").  This extension turns the delay off on
every kernel WebSocket, as tornado advises (``set_nodelay(True)`` once the
connection is open).

**Answers are not activity.** A view answers the frames it has drawn with a
comm message, and the kernel publishes a busy and an idle status for each,
about 50 a second.  By default JupyterLab's page takes each one as a change
of the kernel's state and redraws its status displays for it, on the main
thread the view draws in (each busy lasts under a millisecond, so the
indicator itself still reads Idle).  The extension adds ``comm_msg`` to the
server's ``untracked_message_types`` (and to the list JupyterLab's page is
given), which the server uses for exactly this: the statuses a comm message
causes no longer change the kernel's state (the server's and the page's),
nor count as activity (an idle culler sees a kernel that only streams a view
as idle; this project's hub runs none).  Any widget's comm messages are
treated so, not only the views'.  Measured in ``benchmarks/RESULTS.md``,
*Where the view's tail is now*.

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


UNTRACKED = "comm_msg"  # the message type a view's answers (and any widget's messages) travel as


def _load_jupyter_server_extension(serverapp) -> None:
    _untrack_answers(serverapp)
    _no_delay(serverapp)


def _untrack_answers(serverapp) -> None:
    """Comm messages are not the kernel's activity, in the server and in JupyterLab's page (server's thread)."""
    manager = serverapp.kernel_manager
    untracked = list(manager.untracked_message_types)
    if UNTRACKED not in untracked:
        manager.untracked_message_types = [*untracked, UNTRACKED]
    # JupyterLab copies the list into its page's configuration when it loads, which may be before or after this.
    page = serverapp.web_app.settings.setdefault("page_config_data", {})
    page["untracked_message_types"] = list(manager.untracked_message_types)
    serverapp.log.info("ros-tank-tutorial: comm messages (a live view's answers) are not kernel activity")


def _no_delay(serverapp) -> None:
    """Every kernel WebSocket sends each message at once (server's thread; wraps the handler once)."""
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
