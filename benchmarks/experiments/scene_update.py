"""meshcat's cost per frame: moving every body in one message (the library) against a round trip per body."""

from __future__ import annotations

import time

from benchmarks.paths import ROOT
from benchmarks.stats import pct


def scene_update_cost(model_file: str, frames: int) -> dict:
    """ms per frame to move every body of a model in meshcat: one message (the library) vs a round trip per body.

    The library sends a frame as one ``set_transforms`` command and waits
    for its one reply (:mod:`tutorial.view.meshcat_batch`).  The baseline is
    meshcat-python's own ``set_transform``, which waits for the server's
    reply after each command; both run against one server, interleaved.
    """
    import mujoco

    from tutorial.core.world import ModelEntry, build_world
    from tutorial.tools.standalone.meshcat_server import start_server
    from tutorial.tools.standalone.sinks import BatchSink
    from tutorial.view.scene import Scene, VisualizerSink

    model = build_world([ModelEntry("M", ROOT / model_file)])
    data = mujoco.MjData(model)
    server = start_server()
    try:
        vis = server.visualizer()
        batch, own = BatchSink(server.zmq_url), VisualizerSink(vis)
        scene = Scene(vis, model, sink=batch)
        scene.build(data)
        times = {"one_message": [], "round_trip_per_body": []}
        for i in range(frames):
            for label, sink in (("one_message", batch), ("round_trip_per_body", own)):
                scene.sink = sink
                data.qpos[:] = 0.001 * (2 * i + (sink is own))
                mujoco.mj_kinematics(model, data)
                t0 = time.perf_counter()
                scene.update(data)
                times[label].append(time.perf_counter() - t0)
        batch.close()
    finally:
        server.close()
    out = {k: pct(v, 1000.0) for k, v in times.items()}
    out["transforms"] = len(scene.moving_bodies)  # per frame, all moving (a tank: chassis, turret, barrel)
    out["speedup_p50"] = round(out["round_trip_per_body"]["p50"] / out["one_message"]["p50"], 2)
    return out
