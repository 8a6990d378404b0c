"""Where a frame's transforms go: the fast ways, and which one a view gets.

A :class:`tutorial.view.scene.Scene` sends each frame through one sink, an
object with ``send_transforms(transforms)``, ``transforms`` being
``[(meshcat path, 4x4 pose), ...]`` (translation in m).  Its default is
meshcat's own ``Visualizer`` (:class:`tutorial.view.scene.VisualizerSink`:
one ``set_transform`` each, and meshcat-python waits for its server's reply
after each).  :func:`frame_sink` picks the fastest a visualizer's window
can serve; ``rtt-run``'s :class:`tutorial.tools.standalone.app.StandaloneApp`, whose
view is a meshcat server of its own, asks it (the lessons' ``App`` tells a
widget from anything else itself, and never imports this module):

* a notebook's widget (:class:`tutorial.view.widget.widget.WidgetWindow`) is a
  sink itself: a frame goes to the browser as one message;
* a meshcat server (``zmq_url``) gets :class:`BatchSink`: the frame as one
  ``set_transforms`` command (:mod:`tutorial.view.meshcat_batch`) on a socket
  of its own, and one wait for the one reply.  A server that does not know
  the command (meshcat's own) gets single commands, all in flight at once;
* anything else (a recording's window) gets meshcat's own way.
"""

from __future__ import annotations

import msgpack

from tutorial.view.meshcat_batch import SET_TRANSFORMS, pack_batch


def frame_sink(vis):
    """The fastest sink ``vis`` (a ``meshcat.Visualizer``) can serve; its owner thread must own the sink too."""
    from tutorial.view.scene import VisualizerSink

    window = vis.window
    if getattr(window, "send_transforms", None) is not None:
        return window
    if getattr(window, "zmq_url", None):
        return BatchSink(window.zmq_url)
    return VisualizerSink(vis)


def pack_command(command: dict) -> bytes:
    """A lowered meshcat command (``SetTransform(...).lower()``) as the bytes the server forwards.

    msgpack's C packer makes byte for byte what meshcat-python's pure-Python
    umsgpack makes (tests/test_scene.py checks it), many times faster
    (``benchmarks/RESULTS.md``, *What closed the gaps*).  Any thread.
    """
    return msgpack.packb(command)


class BatchSink:
    """A frame's ``set_transform`` commands sent at once to a meshcat server, then one wait for it.

    The server's socket is REP: a DEALER talks to it by putting an empty
    frame before each request, and gets ``[b"", reply]`` back, in order.
    ``batch`` says whether the server takes ``set_transforms``: True until
    it answers one with meshcat's ``error: unrecognized comand``.
    Owned by the thread that owns the Scene.

    Args:
        zmq_url: the server's, e.g. ``tcp://127.0.0.1:6000``.
    """

    UNKNOWN_COMMAND = b"error: unrecognized"  # how meshcat's own server answers a command it does not know

    def __init__(self, zmq_url: str):
        self.zmq_url = zmq_url
        self.socket = None
        self._connect()
        self.batch = True
        self.messages = 0  # sent to the server (a frame is one while batch holds)

    def _connect(self) -> None:
        import zmq

        if self.socket is not None:
            self.socket.close()
        self.socket = zmq.Context.instance().socket(zmq.DEALER)
        self.socket.setsockopt(zmq.LINGER, 0)
        self.socket.connect(self.zmq_url)

    def send_transforms(self, transforms: list, timeout_ms: int = 5000) -> None:
        """Send ``[(meshcat path, 4x4 pose in m), ...]`` and wait until the server has applied them all.

        Raises:
            RuntimeError: the server did not answer within ``timeout_ms`` (the socket is then made
                anew, so a late reply is never taken for a later frame's), or it refused a command.
        """
        from meshcat.commands import SetTransform

        if not transforms:
            return
        commands = [SetTransform(matrix, path).lower() for path, matrix in transforms]
        if self.batch:
            self.socket.send_multipart([b"", SET_TRANSFORMS.encode(), b"", pack_batch(commands)])
            self.messages += 1
            [reply] = self._replies(1, timeout_ms)
            if reply == b"ok":
                return
            if not reply.startswith(self.UNKNOWN_COMMAND):  # the project's server refused it: a bug, said aloud
                raise RuntimeError(f"the meshcat server refused a frame: {reply[:200]!r}")
            self.batch = False  # meshcat's own server: it applied nothing; single commands from now on
        for command in commands:
            self.socket.send_multipart([b"", b"set_transform", command["path"].encode(), pack_command(command)])
        self.messages += len(commands)
        refused = [r for r in self._replies(len(commands), timeout_ms) if r != b"ok"]
        if refused:
            raise RuntimeError(f"the meshcat server refused a transform: {refused[0][:200]!r}")

    def _replies(self, n: int, timeout_ms: int) -> list[bytes]:
        out = []
        while len(out) < n:
            if not self.socket.poll(timeout_ms):
                self._connect()  # the replies still owed would come late and be read as the next frame's
                raise RuntimeError(f"the meshcat server did not answer within {timeout_ms:d} ms")
            out.append(self.socket.recv_multipart()[-1])
        return out

    def close(self) -> None:
        """Close the sink's own zmq socket (the owner thread, once drawing is over)."""
        self.socket.close()
