"""A meshcat scene as a Jupyter widget: the live 3D view that travels over the notebook's own connection.

A view that is a page of a server the kernel starts (an ``<iframe
src="http://127.0.0.1:PORT/...">``) works only when the browser runs on
the kernel's machine.  A course's JupyterHub, Binder, Colab, VS Code's
remote notebooks and a machine behind ``ssh -L`` all give the browser one
way in: Jupyter's own port.  :class:`MeshcatWidget` goes that way.  It is an
`anywidget <https://anywidget.dev>`_ (no lab extension to install; it runs
in JupyterLab, Notebook 7, VS Code and Colab) whose view is meshcat's own
page, drawn by meshcat's own three.js viewer taken from the meshcat wheel
(``widget.js`` beside this file).  It takes meshcat's own commands:

>>> w = MeshcatWidget("a box")
>>> vis = w.visualizer()           # a meshcat.Visualizer, as with meshcat's server
>>> vis["box"].set_object(meshcat.geometry.Box([0.1, 0.2, 0.3]))
>>> w                               # the last expression of a cell shows it

What travels: each frame is one widget message whose binary buffers are
meshcat's commands, packed as meshcat packs them (a frame's transforms as
one ``set_transforms``: :mod:`tutorial.view.meshcat_batch`).  Coalescing,
at most eight frames in flight and the scene kept for a page that opens later are
:class:`tutorial.view.widget.flow.FrameFlow`'s.  meshcat's viewer script
(850 kB) goes once per browser page, when its first view asks.

Threads: the visualizer (:meth:`visualizer`, :class:`WidgetWindow`) belongs to
one thread, usually a run's owner thread; the browser's messages arrive on
the views' kernel subshell (:class:`ViewSubshell`), a thread of its own,
or on the kernel's thread where there is none.  Both end in a send, under
one lock (see ``MeshcatWidget._lock``).  The widget is shown, closed and displayed from
the kernel's thread.
"""

from __future__ import annotations

import contextvars
import json
import threading
import time
from pathlib import Path

import anywidget
import numpy as np
import traitlets

from tutorial.view import meshcat_batch
from tutorial.view.meshcat_page import PAGE_SCRIPT, viewer_script_gzip
from tutorial.view.widget.flow import ANSWER_EVERY, LONE_WAIT_MS, FrameFlow
from tutorial.view.widget.subshell import ViewSubshell, current_kernel

# What a view takes in one command (widget.js refuses more and says so): a mesh of a few hundred
# thousand triangles fits; a frame's transforms are held to the limits of the server's set_transforms.
LIMITS = {
    "max_command_bytes": 64 * 1024 * 1024,
    "max_commands": meshcat_batch.MAX_COMMANDS,
    "max_path_parts": meshcat_batch.MAX_PATH_PARTS,
    "max_path_chars": meshcat_batch.MAX_PATH_CHARS,
    "ping_ms": 5000,  # a view cut off its kernel asks it this long for an answer before it says "not live"
    "here_ms": 10000,  # a view on a visible page says so this often (a run no page shows pauses: runs.py)
}


def _esm() -> str:
    """widget.js with the page script, the limits and how a view answers the frames it draws written in
    (:data:`tutorial.view.widget.flow.ANSWER_EVERY`, :data:`~tutorial.view.widget.flow.LONE_WAIT_MS`), as
    JavaScript literals."""
    source = (Path(__file__).with_name("widget.js")).read_text(encoding="utf-8")
    source = source.replace("__ANSWER_EVERY__", str(ANSWER_EVERY)).replace("__LONE_WAIT_MS__", str(LONE_WAIT_MS))
    return source.replace("__PAGE_SCRIPT__", json.dumps(PAGE_SCRIPT)).replace("__LIMITS__", json.dumps(LIMITS))


class _CellWatch:
    """Whether the kernel is running a cell now (IPython's ``pre_run_cell`` and ``post_run_cell``).

    While a cell runs, the kernel's main shell reads no message from the
    browser.  Where the views have no subshell of their own (:class:`ViewSubshell`),
    no view can answer a frame then: :class:`FrameFlow` sends on a timer instead.
    Outside IPython (a script) no cell ever runs.
    """

    busy = False
    # The running cell's request and its context (ipykernel's parent of output), kept at its start on the
    # kernel's thread, where output from threads goes.  The lock keeps the views' subshell from putting back
    # a cell that has just ended (its read and its write of ipykernel's parent, against _begin and _end).
    cell_request = None
    cell_context = None
    _lock = threading.Lock()
    _installed = False

    @classmethod
    def install(cls) -> None:
        """Watch cells from now on; installed from inside a running cell (the first view's), that cell counts
        as begun (kernel thread)."""
        if cls._installed:
            return
        try:
            from IPython import get_ipython
        except ImportError:
            return
        shell = get_ipython()
        if shell is None:
            return
        shell.events.register("pre_run_cell", cls._begin)
        shell.events.register("post_run_cell", cls._end)
        cls._installed = True
        kernel = current_kernel()
        parent = getattr(kernel, "get_parent", lambda: {})() or {}
        asked = (parent.get("header") or {}).get("msg_type")
        if threading.current_thread() is threading.main_thread() and asked == "execute_request":
            cls._begin()  # the cell that made the first view: its pre_run_cell has passed

    @classmethod
    def _begin(cls, *_args) -> None:
        cls.busy = True
        kernel = current_kernel()
        get_parent = getattr(kernel, "get_parent", None)  # ipykernel 6 on; before, no views' subshell either
        if get_parent is None or getattr(kernel, "shell", None) is None:
            return
        with cls._lock:
            # On the kernel's thread, in the cell's own context: its parent, whatever a view's message
            # made ipykernel's since the cell began (put back at once).
            cls.cell_request, cls.cell_context = get_parent(), contextvars.copy_context()
            cls._put_back(kernel)

    @classmethod
    def _end(cls, *_args) -> None:
        with cls._lock:
            cls.busy = False
            cls.cell_request = cls.cell_context = None

    @classmethod
    def _put_back(cls, kernel) -> None:  # with cls._lock held
        if cls.cell_request and cls.cell_context is not None and hasattr(kernel, "_shell_context"):
            kernel._shell_context = cls.cell_context
            kernel.shell.set_parent(cls.cell_request)

    @classmethod
    def give_output_back(cls) -> None:
        """Make the running cell, if any, the parent of output from threads again (a view message's thread).

        ipykernel makes each message it handles the parent of all output
        from threads (``print`` in a thread a cell started goes to the last
        message's output).  A view's message handled while a cell runs would
        take that output from the cell; this gives it back once the message
        is handled.  Output from threads *while* ipykernel handles a view's
        message (well under a millisecond, more while it sends a whole
        scene) can still go to that message.  The message's own status
        messages keep their parent.
        """
        kernel = current_kernel()
        if kernel is None or getattr(kernel, "shell", None) is None:
            return
        with cls._lock:
            cls._put_back(kernel)


ViewSubshell.after_handled = _CellWatch.give_output_back  # after each message the views' subshell handles


def cell_running() -> bool:
    """Whether the kernel is running a cell now (False outside IPython); any thread."""
    return _CellWatch.busy


class MeshcatWidget(anywidget.AnyWidget):
    """A live meshcat scene in a notebook output, over the kernel's connection.

    Args:
        label: what the view shows (its caption, its iframe's title, the console's messages).
        height: height of the view, px.

    The caption under the view reads "label (live): status"; once the
    kernel has gone, the page says the view is not live any more.

    Attributes:
        rejected: how many frames a browser refused (a bad command: the browser's console says
            which), and ``last_rejection``, its reason.
    """

    _esm = _esm()
    label = traitlets.Unicode("").tag(sync=True)
    height = traitlets.Int(380).tag(sync=True)
    status = traitlets.Unicode("").tag(sync=True)  # what the view shows now, in its caption (any thread)

    def __init__(self, label: str = "meshcat", height: int = 380):
        super().__init__(label=label, height=height)
        _CellWatch.install()
        # The flow is touched by the visualizer's thread (commands, frames) and the browser's messages' thread
        # (a view's hello and drawn): the lock keeps each change of the flow and the send that follows
        # it together, so the messages leave in the order the flow made them.
        self._lock = threading.Lock()
        self.flow = FrameFlow()
        self.rejected = 0
        self.last_rejection = ""
        self.hellos = 0
        self.last_heard = time.monotonic()  # when a page last said anything: a run unwatched pauses (runs.py)
        self.probe: list | None = None  # a benchmark's list: (frame number, monotonic ns when sent) of each frame
        self.on_msg(self._on_message)
        self.off_main = ViewSubshell.route(self.comm)  # the browser's messages come on the views' subshell

    def __repr__(self) -> str:  # the same text every run (a saved output's text/plain)
        return f"MeshcatWidget({self.label!r})"

    def window(self) -> WidgetWindow:
        """A meshcat "window" sending into this widget (for ``meshcat.Visualizer(window=...)``)."""
        return WidgetWindow(self)

    def visualizer(self):
        """A ``meshcat.Visualizer`` drawing into this widget, owned by the calling thread."""
        import meshcat

        return meshcat.Visualizer(window=self.window())

    # ---- the drawing thread -------------------------------------------------------------------
    def put(self, commands: list[dict]) -> None:
        """Take lowered meshcat commands, and send a frame if a view can draw one now (any thread).

        Raises:
            ValueError: a command is not one of meshcat's scene commands.
        """
        with self._lock:
            for command in commands:
                self.flow.put(command)
            self._send_frame()

    def _send_frame(self) -> None:  # with self._lock held
        buffers = self.flow.take(time.monotonic(), busy=_CellWatch.busy and not self.off_main)
        if buffers is not None:
            n = self.flow.frames_sent
            self.send({"type": "frame", "n": n}, buffers)
            if self.probe is not None:
                self.probe.append((n, time.monotonic_ns()))

    # ---- the views' subshell (else the kernel's thread): what the browser says ---------------------------
    def _on_message(self, _widget, content, buffers) -> None:
        self.last_heard = time.monotonic()
        kind = content.get("type") if isinstance(content, dict) else None
        if kind == "viewer_js":
            self.send({"type": "viewer_js"}, [viewer_script_gzip()])
        elif kind == "hello":
            with self._lock:
                self.hellos += 1
                self.send({"type": "scene", "to": str(content.get("id", ""))}, self.flow.scene(time.monotonic()))
        elif kind == "drawn":
            frames = content.get("frames", 1)
            # how many frames the view drew since its last answer (never trusted): not an int counts as one,
            # and the flow takes at least one and at most its window
            frames = frames if isinstance(frames, int) and not isinstance(frames, bool) else 1
            with self._lock:
                self.flow.drawn(frames)
                self._send_frame()
        elif kind == "ping":
            self.send({"type": "pong"})
        elif kind == "rejected":
            self.rejected += 1
            self.last_rejection = str(content.get("reason", ""))[:300]


class WidgetWindow:
    """The meshcat "window" of a :class:`MeshcatWidget`: where a ``meshcat.Visualizer`` sends.

    It stands in for meshcat's ``ViewerWindow`` (a connection to meshcat's
    server): ``send`` takes one command, and :meth:`send_transforms` a frame's
    transforms at once: the window is a scene's sink (``tutorial.app.app.App.frame_sink``).
    """

    zmq_url = None  # no server: everything goes through this window

    def __init__(self, widget: MeshcatWidget):
        self.widget = widget
        self.web_url = f"(a Jupyter widget in the notebook: {widget.label})"

    def send(self, command) -> None:
        """One meshcat command (``SetObject``, ``SetTransform``, ``SetProperty``, ``Delete``, ``SetAnimation``)."""
        self.widget.put([command.lower()])

    def send_transforms(self, transforms: list) -> None:
        """A frame: ``[(meshcat path, 4x4 pose), ...]`` (translation in m), sent as one message."""
        from meshcat.commands import SetTransform

        self.widget.put([SetTransform(np.asarray(matrix), path).lower() for path, matrix in transforms])
