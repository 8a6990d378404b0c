"""The Step 3 viewer as ``rtt-run`` runs it, with its scene updates timed (benchmark use).

Every body's probe (``benchmarks.probes.ProbedJointStateSubscriber``) hears of each frame.

    python -m benchmarks.viewer_proc PROJECT --duration S [--headless]
    python -m benchmarks.viewer_proc PROJECT --duration S --record-meshcat FILE.json

``--record-meshcat`` starts the meshcat server here (so the commands can be
tapped before the scene is built), prints ``{"event": "meshcat_url", ...}``
as a JSON line, and writes every command the viewer sent to meshcat to FILE:
each with its send time (``time.monotonic_ns()``), its type, path and bytes
(hex), and for a transform the body it moves and the stamp of the state the
body showed; for a frame sent as one ``set_transforms`` command, the list
of the bodies and the list of their stamps (``benchmarks.experiments.browser``
replays and joins them).  ``--meshcat-no-batch`` runs meshcat's own server
and page, so the viewer sends one command per transform (the fallback).
"""

from __future__ import annotations

import argparse
import json
import sys
import time

import msgpack
import rclpy
from rclpy.signals import SignalHandlerOptions

from tutorial.core.project import load_project
from tutorial.ros import env as ros_env
from tutorial.tools.standalone.app import StandaloneApp
from tutorial.view.meshcat_batch import SET_TRANSFORMS


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("project")
    p.add_argument("--duration", type=float, required=True)
    p.add_argument("--headless", action="store_true")
    p.add_argument("--name", default="rtt_viewer")
    p.add_argument("--record-meshcat", metavar="FILE", help="tap and record every command sent to meshcat")
    p.add_argument("--meshcat-no-batch", action="store_true", help="meshcat's own server: no set_transforms")
    args = p.parse_args()
    ros_env.use_localhost_by_default()
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    server = vis = tape = None
    if args.record_meshcat:
        from tutorial.tools.standalone.meshcat_server import start_server

        server = start_server(batch=not args.meshcat_no_batch)
        vis = server.visualizer()
        tape = CommandTape()
        vis.window.zmq_socket = tape.tap(vis.window.zmq_socket)
        print(json.dumps({"event": "meshcat_url", "url": server.web_url}), flush=True)
    app = StandaloneApp(
        load_project(args.project),
        node_name=args.name,
        headless=args.headless,
        duration=args.duration,
        vis=vis,
        output=lambda record: print(record, flush=True) if record.get("event") != "status" else None,
    )
    try:
        app.open()
        probes = [c for _, c, _ in app.controllers if hasattr(c, "frame_drawn")]
        sink = None if app.scene is None else app.scene.sink
        # a BatchSink (tutorial.tools.standalone.sinks): its frames' socket
        if tape is not None and hasattr(sink, "socket"):
            tape.probes = {probe.config.body_name: probe for probe in probes}
            sink.socket = tape.tap(sink.socket)

        def drawn(seconds: float) -> None:
            for probe in probes:  # every body's probe notes which of its states this frame shows
                probe.frame_drawn(seconds)

        if app.scene is not None:
            update = app.scene.update

            def timed_update(data):
                t0 = time.perf_counter()
                sent = update(data)
                drawn(time.perf_counter() - t0)
                return sent

            app.scene.update = timed_update
        else:
            app.loop.call_every(1 / 60, lambda: drawn(0.0))
        app.run()
    finally:
        app.close()
        rclpy.try_shutdown()
        if tape is not None:
            with open(args.record_meshcat, "w") as f:
                json.dump(tape.commands, f)
        if server is not None:
            server.close()
    return 0


class CommandTape:
    """Records every meshcat command a zmq socket sends, with its time (viewer's main thread only).

    A transform's record also names the body it moves (the first path part
    that is a probed body's name) and the stamp of the state that body's
    probe last applied: the state this frame shows.
    """

    def __init__(self):
        self.commands: list[list] = []  # [monotonic ns, type, path, data hex, body, stamp ns]
        self.probes: dict = {}

    def tap(self, socket):
        tape = self

        class Tapped:
            def send_multipart(self, frames, *a, **k):
                # A DEALER's frames start with an empty delimiter; a REQ's do not.
                kind, path, data = (frames[1:] if frames[0] == b"" else frames)[:3]
                sent_ns = time.monotonic_ns()
                result = socket.send_multipart(frames, *a, **k)
                tape.note(sent_ns, kind.decode(), path.decode(), data)  # after the send: no delay in its path
                return result

            def __getattr__(self, name):
                return getattr(socket, name)

        return Tapped()

    def body_of(self, path: str) -> str | None:
        return next((part for part in path.split("/") if part in self.probes), None)

    def note(self, sent_ns: int, kind: str, path: str, data: bytes) -> None:
        """Record one command sent at ``sent_ns`` (``time.monotonic_ns()``), with the states it shows."""
        if kind == SET_TRANSFORMS:  # a frame: each body it moves, and the stamp each shows
            bodies = [self.body_of(c["path"]) for c in msgpack.unpackb(data)["commands"]]
            bodies = [b for b in dict.fromkeys(bodies) if b is not None]
            stamps = [self.probes[b].latest_stamp for b in bodies]
            self.commands.append([sent_ns, kind, path, data.hex(), bodies, stamps])
            return
        body = self.body_of(path)
        stamp = self.probes[body].latest_stamp if body is not None else None
        self.commands.append([sent_ns, kind, path, data.hex(), body, stamp])


if __name__ == "__main__":
    sys.exit(main())
