"""A real robot's description to its first drawn frame: the Panda (Collada meshes), cold and cached.

    python -m benchmarks.experiments.any_robot [--repeats 3]

A publisher keeps the Franka Panda's description (``example-robot-data``,
``package://`` URIs as shipped) on ``/Panda/robot_description``; a monitor
(an :class:`tutorial.app.app.App` with a meshcat server, as ``rtt-run``
runs it) opens on it and draws its first frame.  The figure is from the
description's arrival to the end of that frame: the meshes found, the
Collada files converted to STL (cold: an empty cache) or read from the
cache (warm), the MuJoCo model compiled, and the scene sent to meshcat.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import sysconfig
import tempfile
import time
from pathlib import Path

PREFIX = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix"
PANDA = PREFIX / "share" / "example-robot-data" / "robots" / "panda_description" / "urdf" / "panda.urdf"


def first_frame_s(project: Path) -> float:
    """Seconds from the App's start (the description is already kept for it) to its first frame drawn."""
    from tutorial.app.app import App
    from tutorial.core.project import load_project

    records = []
    t0 = time.perf_counter()
    app = App(load_project(project), node_name="any_robot_monitor", output=records.append)
    try:
        app.open()
        app._draw()  # the first frame: the scene as built, drawn once
        return time.perf_counter() - t0
    finally:
        app.close()


def measure(repeats: int = 3) -> dict:
    import rclpy
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from std_msgs.msg import String

    os.environ["AMENT_PREFIX_PATH"] = str(PREFIX)
    rclpy.init()
    node = rclpy.create_node("any_robot_description")
    latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE)
    node.create_publisher(String, "/Panda/robot_description", latched).publish(String(data=PANDA.read_text()))
    from tutorial.ros.spin import SpinThread

    spin = SpinThread(node).start()  # serves the kept description
    cold, warm = [], []
    with tempfile.TemporaryDirectory() as d:
        project = Path(d) / "panda.yaml"
        project.write_text("name: panda\nmodels:\n  - name: Panda\n    description: /Panda/robot_description\n")
        for i in range(repeats):
            os.environ["RTT_MESH_CACHE"] = str(Path(d) / f"cache{i}")
            cold.append(first_frame_s(project))  # an empty cache: every Collada file converted
            warm.append(first_frame_s(project))  # the same cache again
    spin.stop()
    node.destroy_node()
    rclpy.try_shutdown()
    return {
        "cold_s": [round(x, 3) for x in cold],
        "warm_s": [round(x, 3) for x in warm],
        "cold_median_s": round(statistics.median(cold), 3),
        "warm_median_s": round(statistics.median(warm), 3),
    }


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeats", type=int, default=3)
    args = p.parse_args(argv)
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    os.environ.setdefault("ROS_DOMAIN_ID", str(60 + os.getpid() % 40))
    print(json.dumps(measure(args.repeats), indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
