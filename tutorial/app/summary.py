"""A run's exit summary: the record ``rtt-run`` prints last and a notebook's run returns.

One dict: simulated and wall time, the real-time factor, each body's root
pose and joint positions, any error, and each controller's own summary.
"""

from __future__ import annotations

import math
import time
from collections import Counter


def app_summary(app) -> dict:
    """``app``'s exit summary: times, root poses and joint positions (its owner thread, after its run).

    ``controllers`` holds each controller's own summary under its name, or
    under ``<body>/<name>`` when bodies share a controller's name (two
    tanks: ``Tank/RttJointStatePublisher``, ``Tank2/RttJointStatePublisher``).
    """
    record: dict = {"event": "summary", "project": app.project.name, "node": getattr(app, "node_fqn", None)}
    if app.sim is not None:
        record.update(
            simulated_time=round(app.sim.steps * app.sim.time_step, 6),
            wall_time=round(app.sim.wall_time, 3),
            real_time_factor=round(app.sim.real_time_factor, 3),
            steps=app.sim.steps,
        )
        if app.sim.error:
            record["error"] = app.sim.error
    else:
        record["wall_time"] = round(time.monotonic() - app.started_at, 3) if app.started_at else 0.0
    bodies = {}
    for entry in app.project.models:
        body = app.bodies[entry.name]
        if body.num_joints == 0 and not entry.controllers:
            continue  # the room: nothing to report
        pos, quat = body.root_pose()
        w, x, y, z = (float(v) for v in quat)
        bodies[entry.name] = {
            "root_position": [round(float(v), 6) for v in pos],
            "root_yaw": round(math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z)), 6),
            "joint_positions": {k: round(v, 9) for k, v in body.joint_positions().items()},
        }
    record["bodies"] = bodies
    if app.spin is not None and app.spin.error is not None:
        import traceback

        text = "a subscription callback raised; callbacks stopped:\n" + "".join(
            traceback.format_exception(app.spin.error)
        )
        record["error"] = record["error"] + "\n" + text if record.get("error") else text
    controllers = {}
    shared = Counter(name for name, _, _ in app.controllers)  # two tanks, two RttJointStatePublisher
    for name, controller, body_name in app.controllers:
        s = controller.summary()
        if s:
            controllers[f"{body_name}/{name}" if shared[name] > 1 else name] = s
    if controllers:
        record["controllers"] = controllers
    return record
