"""The views' kernel subshell: a live view's messages, and a reloaded page's questions, answered while a cell runs.

A view's messages to the kernel, and what a page asks when it is
(re)loaded, travel on the kernel's shell channel, where the main shell
reads them only between cells.  ipykernel 7 runs *subshells* (Jupyter's
kernel subshells, JEP 91): :class:`ViewSubshell` makes one for every view
of the kernel, and sends those messages to it.  It leans on ipykernel
7.4's routing (``BaseComm._reply_subshell_for``, the shell channel's
thread); ``tests/test_widget_subshell.py`` holds it to that, with a real
kernel, and where a kernel has none of it the views wait for the kernel
to be idle, as before.
"""

from __future__ import annotations

import inspect
import logging
import threading
from collections.abc import Callable


def current_kernel():
    """The ipykernel kernel of this process, or None (a script, another kernel)."""
    try:
        from ipykernel.kernelbase import Kernel
    except ImportError:
        return None
    return Kernel.instance() if Kernel.initialized() else None


# What a page sends to restore its widgets (ViewSubshell._restore_there); their handlers give output back
_RESTORING = ("kernel_info_request", "comm_info_request", "comm_open", "comm_msg")


class ViewSubshell:
    """One kernel subshell that hears every live view's messages, so a busy kernel still answers its views.

    A view's messages to the kernel (its hello, ``drawn``, the viewer script
    it asks for) are comm messages on the kernel's shell channel.  The main
    shell reads them only between cells: with Run All, behind every cell
    already sent.  ipykernel 7 runs *subshells* (Jupyter's kernel subshells,
    JEP 91), each a thread with its own queue, and sends a comm's messages to
    the subshell the comm names (``BaseComm._reply_subshell_for``).  Every
    view's comm names this one subshell, created once per kernel: a view
    draws its first picture, and keeps drawing at its own rate, while a cell
    runs.

    What it costs: each view message makes the kernel say "busy" then "idle"
    on its own (Jupyter's kernel indicator may show idle while a cell
    runs); and ipykernel makes each message it handles the parent of
    output from threads, so each handler, on this subshell, gives that back
    to the running cell afterwards (:attr:`after_handled`: all but what a
    thread prints while the message is being handled).

    Where ipykernel has no subshells (before 7) or no comm routing (before
    7.4), or outside a kernel, :meth:`id` is None and views wait for the
    kernel to be idle, as before.  Any thread.
    """

    _id: str | None = None
    _tried = False
    _lock = threading.Lock()  # one subshell however many views are made, from whichever threads

    @classmethod
    def id(cls) -> str | None:
        with cls._lock:
            if not cls._tried:
                cls._tried = True
                cls._id = cls._create()
            return cls._id

    @staticmethod
    def _create() -> str | None:
        kernel = current_kernel()
        try:
            from ipykernel.comm.comm import BaseComm
        except ImportError:
            return None
        thread = getattr(kernel, "shell_channel_thread", None)
        if not getattr(kernel, "_supports_kernel_subshells", False) or thread is None:
            return None
        if not hasattr(BaseComm, "_reply_subshell_for"):
            return None
        made: dict = {}
        done = threading.Event()

        def create() -> None:  # on the shell channel's thread, as ipykernel's own create_subshell_request
            try:
                made["id"] = thread.manager._create_subshell()
                # ipykernel makes the message it handles the parent of output from threads: after one handled on
                # the views' subshell (a view's, a reloaded page's) while a cell may run, the cell gets it back.
                for kind in _RESTORING:
                    kernel.shell_handlers[kind] = ViewSubshell._then_output_back(kernel.shell_handlers[kind])
                try:
                    ViewSubshell._restore_there(kernel, made["id"])
                except Exception:  # noqa: BLE001 - an ipykernel whose shell channel is made otherwise: said, not fatal
                    logging.getLogger("rtt.views").warning(
                        "a page reloaded while a cell runs will show its views when the cell ends", exc_info=True
                    )
            finally:
                done.set()

        thread.io_loop.add_callback(create)
        if not done.wait(5.0) or "id" not in made:
            logging.getLogger("rtt.views").warning(
                "no kernel subshell for the live views: they draw only while no cell runs"
            )
            return None
        return made["id"]

    @staticmethod
    def _restore_there(kernel, subshell: str) -> None:
        """Send the messages with which a page restores its widgets to ``subshell`` too.  Shell channel's thread.

        A page (re)loaded while a cell runs first asks the kernel who it is
        (``kernel_info_request``: JupyterLab went on without the answer after
        3 s, measured), then for its widgets: ipywidgets' widget manager
        (JupyterLab's, Notebook 7's) opens a ``jupyter.widget.control`` comm
        and asks it for every widget's state, or, if no answer comes within
        4 s, asks for the kernel's comms (``comm_info_request``) and then each
        widget's state.  A view's own comm messages already come to this
        subshell; these would go to the main shell, behind the running cell,
        and the page would show no view until the cell ends.  The shell
        channel's thread takes every shell message first (ipykernel's
        ``shell_channel_thread_main``, which picks the subshell a message
        names): this step, before it, makes each of these messages that names
        no subshell name the views' one, signed anew with the kernel's own
        key.  Every other message passes unchanged, and so does one whose
        signature is wrong (ipykernel refuses it).

        Raises:
            RuntimeError: the shell channel is not as ipykernel 7.4 makes it.
        """
        import zmq

        session, pick_subshell, stream = kernel.session, kernel.shell_channel_thread_main, kernel.shell_stream
        if getattr(stream, "_recv_callback", None) != pick_subshell:
            raise RuntimeError("the kernel's shell stream does not go to shell_channel_thread_main")
        controls: set = set()  # control comms opened, until their request; only this thread uses it
        asked = tuple(f'"{kind}"'.encode() for kind in _RESTORING if kind != "comm_msg")  # comm_msg: controls
        failed: list = []  # said once

        def restoring(frames) -> bool:
            # Most messages (a view's answers, cells) pass at once, on their header's bytes alone: reading them
            # can only decide to leave a message as it came.  The others are read as ipykernel reads them.
            header = frames[1].bytes
            if not any(kind in header for kind in asked) and not (controls and b'"comm_msg"' in header):
                return False
            peeked = session.deserialize(frames, content=False, copy=False)  # signature checked, not yet recorded
            kind = peeked["header"]["msg_type"]
            if peeked["header"].get("subshell_id") or kind not in _RESTORING or (kind == "comm_msg" and not controls):
                return False
            if kind in ("kernel_info_request", "comm_info_request"):
                return True
            content = session.unpack(peeked["content"])
            if kind == "comm_open" and content.get("target_name") == "jupyter.widget.control":
                controls.add(content.get("comm_id"))  # its request for the states comes next
                return True
            if kind == "comm_msg" and content.get("comm_id") in controls:  # its answer then names the subshell
                controls.discard(content.get("comm_id"))
                return True
            return False

        async def on_shell_message(msg) -> None:
            try:
                idents, frames = session.feed_identities(msg, copy=False)
                if restoring(frames):
                    whole = session.deserialize(frames, content=True, copy=False)  # (records the signature)
                    whole["header"]["subshell_id"] = subshell
                    parts = session.serialize(whole, ident=idents) + list(whole.get("buffers", []))
                    msg = [zmq.Frame(part) for part in parts]  # as the stream gives them (copy=False)
            except Exception:  # noqa: BLE001 - passed on as it came: ipykernel's routing says what is wrong with it
                if not failed:
                    failed.append(True)
                    logging.getLogger("rtt.views").debug("a shell message kept its route", exc_info=True)
            await pick_subshell(msg)

        stream.on_recv(on_shell_message, copy=False)

    # What gives a running cell its threads' output back (tutorial/view/widget/widget.py sets it); any thread.
    after_handled: Callable[[], None] = staticmethod(lambda: None)

    @staticmethod
    def _then_output_back(handler):
        """``handler`` (a kernel's shell handler), then, off the kernel's main thread, :attr:`after_handled`."""

        async def handled(*args, **kwargs):
            try:
                result = handler(*args, **kwargs)
                if inspect.isawaitable(result):
                    await result
            finally:
                if threading.current_thread() is not threading.main_thread():
                    ViewSubshell.after_handled()

        return handled

    @classmethod
    def route(cls, comm) -> bool:
        """Send ``comm``'s messages from the browser to the views' subshell; whether it could.

        There, they call the comm's callback without IPython's ``pre_execute``
        and ``post_execute`` events, which ipykernel's comms fire around each
        message: those belong to the cell on the main shell (matplotlib's
        inline backend shows and closes the running cell's figures on
        ``post_execute``)."""
        subshell = cls.id()
        if subshell is None or comm is None or not hasattr(comm, "_reply_subshell_for"):
            return False
        comm._reply_subshell_for = lambda _data, _default: subshell
        comm.handle_msg = lambda msg: comm._msg_callback and comm._msg_callback(msg)
        return True
