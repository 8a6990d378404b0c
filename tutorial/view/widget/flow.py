"""What a live view still owes the browser, and when it may send it: coalescing and flow control.

A run draws a frame whenever its model moves (up to the frame rate of
:mod:`tutorial.app.frame_clock`); a browser draws at most one frame per
animation frame of its own, and less on a slow machine or a slow link.
:class:`FrameFlow` sits between the two:

- **it coalesces.**  Commands wait in a pending set keyed by what they
  change: a new ``set_transform`` of a path replaces the one still waiting
  for that path, a new ``set_property`` the same property's, a new
  ``set_object`` the same path's.  So the pending set never holds more
  than one command per path and property however long the browser is
  away, and what goes out is always the newest state, never a queue of
  old ones.
- **it sends only what the browser can draw.**  A view answers the frames
  it has drawn with ``drawn`` (four at a time, or what it owes 0.25 s after
  the first: each message to the kernel costs it a busy and an idle status
  on its connection, each relayed by the Jupyter server).  The flow keeps
  at most :data:`WINDOW` frames in flight: four drawn and not answered yet,
  and four more on their way, so that neither the answer's trip back to
  the kernel cuts the frame rate nor a state waits here for it (with room
  for one on its way, not two, one tank's view had a p99 1.23x to 1.31x the
  meshcat page's, against 1.12x to 1.22x, when a view answered two at a
  time: the Benchmarks page, *Live views in the notebook*).  A
  slow browser or link therefore gets fewer frames, each the newest
  state; a tab that closed, or hid, gets nothing more until a view says
  ``hello`` again.
- **it keeps the scene** (meshcat's server's tree,
  ``meshcat.servers.tree``) so that a view that opens later (a page reload,
  a second tab) is sent the whole current scene at once: :meth:`scene`.
  Unlike meshcat's server, a node keeps one value per property name (the
  newest), so a property set every frame does not grow the tree.

Where the views have no kernel subshell of their own
(``subshell.ViewSubshell``: ipykernel before 7.4), the kernel reads no
message from the browser while it runs a cell: a view's ``drawn`` waits
until the cell ends.  So while a cell runs there (:meth:`take`'s
``busy``), the flow sends without waiting for answers, at most
:data:`BUSY_RATE` frames a second and at most :data:`BUSY_UNANSWERED`
frames in a row: a run a cell waits on stays live in the page, and a page
that closed meanwhile costs a bounded number of messages.

Not thread-safe: its owner (:class:`tutorial.view.widget.widget.MeshcatWidget`)
holds a lock around every call and the send that follows it.
"""

from __future__ import annotations

import msgpack
import umsgpack

from tutorial.view.meshcat_batch import pack_batch

WINDOW = 8  # frames sent and not yet answered, at most (a view answers four frames at a time: widget.js)
# How a view answers (widget.js, where widget.py writes both in): the frames drawn it answers at once, half the
# window (as many more are on their way meanwhile), and how long the first frame owed waits for the others, ms.
ANSWER_EVERY = WINDOW // 2
LONE_WAIT_MS = 250
BUSY_RATE = 10.0  # frames/s sent while the kernel runs a cell (no answers can arrive then)
BUSY_UNANSWERED = 600  # frames sent in a row with no answer, while busy, before the flow stops (a minute)
KINDS = ("set_transform", "set_object", "set_property", "delete", "set_animation")


class FrameFlow:
    """The pending commands of one live view, its scene, and its sending window.

    Attributes:
        frames_sent: frame messages sent.
        commands_replaced: commands dropped because a newer one for the same thing came first.
        answers: ``drawn`` answers received.
    """

    def __init__(self):
        from meshcat.servers.tree import SceneTree

        self.tree = SceneTree()
        self._pending: dict[tuple, tuple[dict | None, bytes]] = {}  # key -> (lowered command or None, packed)
        self._serial = 0  # keys of commands that replace nothing
        self._credit = 0  # frames that may be sent now: none until a view says hello
        self._viewed = False  # a view has said hello since the flow began
        self._unanswered = 0
        self._last_send = float("-inf")
        self.frames_sent = 0
        self.commands_replaced = 0
        self.answers = 0

    # ---- what the run draws -------------------------------------------------------------------
    def put(self, command: dict) -> None:
        """Take one lowered meshcat command (``SetTransform(...).lower()``, etc.).

        Raises:
            ValueError: ``command`` is not one of meshcat's scene commands (:data:`KINDS`),
                or has no string ``path``.
        """
        from meshcat.servers.tree import SceneTree, find_node

        kind, path_text = command.get("type"), command.get("path")
        if kind not in KINDS or not isinstance(path_text, str):
            raise ValueError(f"not a meshcat scene command: type {kind!r}, path {path_text!r}")
        path = tuple(p for p in path_text.split("/") if p)
        # A transform is packed by msgpack's C packer (the same bytes, 15x faster: tutorial/view/scene.py);
        # everything else by meshcat's own packer, which knows the arrays meshcat's geometry holds.
        packed = msgpack.packb(command) if kind == "set_transform" else umsgpack.packb(command)
        if kind == "delete":
            # What is still pending under the path is moot: it would be drawn and deleted at once.
            for key in [k for k in self._pending if k[1][: len(path)] == path]:
                del self._pending[key]
            if path:
                parent = find_node(self.tree, list(path[:-1]))
                parent.pop(path[-1], None)
            else:
                self.tree = SceneTree()
            self._add(("delete", path), None, packed)
            return
        node = find_node(self.tree, list(path))
        if kind == "set_object":
            node.object, node.properties = packed, {}
            for key in [k for k in self._pending if k[0] == "set_property" and k[1] == path]:
                del self._pending[key]  # meshcat's set_object clears the path's properties
            self._add((kind, path), None, packed)
        elif kind == "set_transform":
            node.transform = packed
            self._add((kind, path), command, packed)
        elif kind == "set_property":
            if not isinstance(node.properties, dict):
                node.properties = {}
            node.properties[command.get("property")] = packed
            self._add((kind, path, command.get("property")), None, packed)
        else:  # set_animation
            node.animation = packed
            self._add((kind, path), None, packed)

    def _add(self, key: tuple, command: dict | None, packed: bytes) -> None:
        if self._pending.pop(key, None) is not None:
            self.commands_replaced += 1
        self._pending[key] = (command, packed)  # at the end: the order the newest commands came in

    @property
    def pending(self) -> int:
        """Commands waiting to be sent."""
        return len(self._pending)

    # ---- what goes out ------------------------------------------------------------------------
    def take(self, now: float, busy: bool = False) -> list[bytes] | None:
        """The next frame's buffers if one may go now, else None (it stays pending).

        Args:
            now: a monotonic time, s.
            busy: the kernel is running a cell (no answer can arrive until it ends).

        Returns:
            The packed commands, in order; runs of ``set_transform`` go as one
            ``set_transforms`` (:mod:`tutorial.view.meshcat_batch`).
        """
        if not self._pending:
            return None
        if self._credit <= 0:
            may = (
                busy
                and self._viewed
                and self._unanswered < BUSY_UNANSWERED
                and now - self._last_send >= 1.0 / BUSY_RATE
            )
            if not may:
                return None
        else:
            self._credit -= 1
        out: list[bytes] = []
        run: list[dict] = []
        for command, packed in self._pending.values():
            if command is not None:
                run.append(command)
                continue
            if run:
                out.append(pack_batch(run) if len(run) > 1 else msgpack.packb(run[0]))
                run = []
            out.append(packed)
        if run:
            out.append(pack_batch(run) if len(run) > 1 else msgpack.packb(run[0]))
        self._pending.clear()
        self._unanswered += 1
        self._last_send = now
        self.frames_sent += 1
        return out

    def drawn(self, frames: int = 1) -> None:
        """A view has drawn ``frames`` frames it was sent (at least 1): as many more may go, up to the window."""
        self.answers += 1
        self._credit = min(self._credit + max(1, frames), WINDOW)
        self._unanswered = 0

    def scene(self, now: float) -> list[bytes]:
        """The whole scene for a view that has just opened, in meshcat's order; counts as a frame sent.

        Whatever was pending is in it, so nothing stays pending.
        """
        from meshcat.servers.tree import walk

        out: list[bytes] = []
        for node in walk(self.tree):
            if node.object is not None:
                out.append(node.object)
            out.extend(node.properties.values() if isinstance(node.properties, dict) else node.properties)
            if node.transform is not None:
                out.append(node.transform)
            if node.animation is not None:
                out.append(node.animation)
        self._pending.clear()
        self._viewed = True
        self._credit = WINDOW - 1  # the scene is a frame in flight: the view answers it when drawn
        self._unanswered = 1
        self._last_send = now
        return out
