"""The Step 3 viewer as ``rtt-run`` runs it, with its scene updates timed (benchmark use).

Every body's probe (``benchmarks.probes.ProbedJointStateSubscriber``) hears of each frame.

    python -m benchmarks.viewer_proc PROJECT --duration S [--headless]
"""

from __future__ import annotations

import argparse
import sys
import time

import rclpy
from rclpy.signals import SignalHandlerOptions

from tutorial.core.app import App
from tutorial.core.project import load_project
from tutorial.ros import env as ros_env


def main() -> int:
    p = argparse.ArgumentParser()
    p.add_argument("project")
    p.add_argument("--duration", type=float, required=True)
    p.add_argument("--headless", action="store_true")
    p.add_argument("--name", default="rtt_viewer")
    args = p.parse_args()
    ros_env.use_localhost_by_default()
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    app = App(
        load_project(args.project),
        node_name=args.name,
        headless=args.headless,
        duration=args.duration,
        output=lambda record: print(record, flush=True) if record.get("event") != "status" else None,
    )
    try:
        app.open()
        probes = [c for _, c, _ in app.controllers if hasattr(c, "frame_drawn")]

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
    return 0


if __name__ == "__main__":
    sys.exit(main())
