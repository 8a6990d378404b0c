"""A real robot's description to its first drawn frame: the Panda (Collada meshes), and every robot of
example-robot-data, cold and cached.

    python -m benchmarks.experiments.any_robot [--repeats 3]   (each repeat a fresh process)
    python -m benchmarks.experiments.any_robot --all           (every robot: the median and the slowest)

A publisher keeps the Franka Panda's description (``example-robot-data``,
``package://`` URIs as shipped) on ``/Panda/robot_description``; a monitor
(a :class:`tutorial.tools.standalone.app.StandaloneApp`, with its meshcat server,
as ``rtt-run`` runs it) opens on it and draws its first frame.  The figure is from the
description's arrival to the end of that frame: the meshes found, the
Collada files converted to STL (cold: an empty cache) or read from the
cache (warm), the MuJoCo model compiled, and the scene sent to meshcat;
beside it, the same from the App's start (node, discovery, reception).

``--all`` does the same for each of example-robot-data's 69 files whose
description the monitor accepts (68: one is an empty ``<robot>``), one
after another in one process with an empty cache (cold; the mesh readers
imported by the first), then in a second process with the cache full
(cached), and reports the median and the slowest robot of each.
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
ROBOTS = PREFIX / "share" / "example-robot-data" / "robots"
PANDA = ROBOTS / "panda_description" / "urdf" / "panda.urdf"


def first_frame_s(project: Path) -> tuple[float, float]:
    """``(seconds from the description's arrival, seconds from the App's start)`` to its first frame drawn.

    The description is already kept for the monitor (transient local): from
    the App's start, the time also holds the node's creation and its
    discovery of the publisher.  The arrival is when
    ``receive_robot_description`` hands the URDF it received to the monitor.
    """
    import tutorial.interfaces.robot_description as descriptions
    from tutorial.core.project import load_project
    from tutorial.tools.standalone.app import StandaloneApp

    arrived = []
    receive = descriptions.receive_robot_description

    def timed(node, topic, timeout, use=None, **kwargs):
        def use_timed(text):  # the description has arrived: what follows is the monitor's work on it
            arrived.append(time.perf_counter())
            return use(text)

        return receive(node, topic, timeout, use=use_timed, **kwargs)

    records = []
    descriptions.receive_robot_description = timed  # the App imports it when it opens: it finds this one
    t0 = time.perf_counter()
    app = StandaloneApp(load_project(project), node_name="any_robot_monitor", output=records.append)
    try:
        app.open()
        app._draw()  # the first frame: the scene as built, drawn once
        t1 = time.perf_counter()
        return t1 - arrived[0], t1 - t0
    finally:
        descriptions.receive_robot_description = receive
        app.close()


def one_process(cache: Path) -> dict:
    """One monitor's first frame, cold then warm, in this process: ``{"cold": (arrival, start), "warm": ...}``.

    Cold is the first in a fresh process with an empty ``cache``: it also
    imports the mesh readers (trimesh, pycollada), as a learner's first view
    does.  Warm is the next, with the conversions cached.
    """
    import rclpy
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from std_msgs.msg import String

    os.environ["AMENT_PREFIX_PATH"] = str(PREFIX)
    os.environ["RTT_MESH_CACHE"] = str(cache)
    rclpy.init()
    node = rclpy.create_node("any_robot_description")
    latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE)
    node.create_publisher(String, "/Panda/robot_description", latched).publish(String(data=PANDA.read_text()))
    from tutorial.ros.spin import SpinThread

    spin = SpinThread(node).start()  # serves the kept description
    try:
        project = cache.parent / "panda.yaml"
        project.write_text("name: panda\nmodels:\n  - name: Panda\n    description: /Panda/robot_description\n")
        return {"cold": first_frame_s(project), "warm": first_frame_s(project)}
    finally:
        spin.stop()
        node.destroy_node()
        rclpy.try_shutdown()


def all_robots(cache: Path) -> dict:
    """Each robot's first frame in this process, one after another: ``{file: seconds from arrival}``.

    A file whose description the monitor refuses (an empty ``<robot>``) is
    not published: a monitor would wait for a corrected one.
    """
    import rclpy
    from std_msgs.msg import String

    from tutorial.interfaces.robot_description import DescriptionError, check_robot_description, robot_description_qos
    from tutorial.ros.spin import SpinThread

    os.environ["AMENT_PREFIX_PATH"] = str(PREFIX)
    os.environ["RTT_MESH_CACHE"] = str(cache)
    rclpy.init()
    node = rclpy.create_node("any_robot_descriptions")
    files = {}
    for i, path in enumerate(sorted(ROBOTS.rglob("*.urdf"))):
        try:
            check_robot_description(path.read_text())
        except DescriptionError:
            continue
        files[str(path.relative_to(ROBOTS))] = i
        topic = f"/robot{i}/robot_description"
        node.create_publisher(String, topic, robot_description_qos()).publish(String(data=path.read_text()))
    spin = SpinThread(node).start()  # serves the kept descriptions
    try:
        out = {}
        for rel, i in files.items():
            project = cache.parent / f"robot{i}.yaml"
            project.write_text(f"name: r{i}\nmodels:\n  - name: R{i}\n    description: /robot{i}/robot_description\n")
            out[rel] = round(first_frame_s(project)[0], 3)
        return out
    finally:
        spin.stop()
        node.destroy_node()
        rclpy.try_shutdown()


def _child(*args: str, timeout: float = 120) -> dict:
    import subprocess

    done = subprocess.run(
        [sys.executable, "-m", "benchmarks.experiments.any_robot", *args],
        capture_output=True,
        text=True,
        timeout=timeout,
    )
    if done.returncode != 0:
        raise RuntimeError(f"a run failed: {done.stderr[-2000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def measure_all() -> dict:
    """:func:`all_robots` in a fresh process with an empty cache (cold), then in another with it full (cached).

    Returns the robots' count, and per case the median (s, from each
    description's arrival to its first frame), the slowest robot and its
    time, and every robot's time.
    """
    out = {}
    with tempfile.TemporaryDirectory() as d:
        cache = Path(d) / "meshes"
        for case in ("cold", "cached"):
            times = _child("--all-one", str(cache), timeout=1800)
            slowest = max(times, key=times.get)
            out["robots"] = len(times)
            out[f"{case}_median_s"] = round(statistics.median(times.values()), 3)
            out[f"{case}_slowest"] = {"file": slowest, "s": times[slowest]}
            out[f"{case}_s"] = times
    return out


def measure(repeats: int = 3) -> dict:
    """``repeats`` times: :func:`one_process` in a fresh process, then again in another with its cache full.

    Returns each figure's runs (s, from the description's arrival) and
    medians: ``cold``, ``warm`` (the same process's second monitor) and
    ``restart`` (a new process whose conversions are cached: a monitor
    started again); ``*_from_start_median_s`` from the App's start.
    """

    def child(cache: Path) -> dict:
        return _child("--one", str(cache))

    # cold: a fresh process, an empty cache; warm: the same process again; restart: a fresh process, the cache full
    runs: dict[str, list] = {"cold": [], "warm": [], "restart": []}
    with tempfile.TemporaryDirectory() as d:
        for i in range(repeats):
            cache = Path(d) / f"run{i}" / "meshes"
            cache.parent.mkdir()
            first = child(cache)
            runs["cold"].append(first["cold"])
            runs["warm"].append(first["warm"])
            runs["restart"].append(child(cache)["cold"])
    out = {}
    for case, pairs in runs.items():
        out[f"{case}_s"] = [round(a, 3) for a, _ in pairs]
        out[f"{case}_median_s"] = round(statistics.median(a for a, _ in pairs), 3)
        out[f"{case}_from_start_median_s"] = round(statistics.median(b for _, b in pairs), 3)
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--all", action="store_true", help="every robot of example-robot-data, cold and cached")
    p.add_argument("--one", type=Path, help=argparse.SUPPRESS)  # a child process: one run, into this cache
    p.add_argument("--all-one", type=Path, help=argparse.SUPPRESS)  # a child process: every robot, this cache
    args = p.parse_args(argv)
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    os.environ.setdefault("ROS_DOMAIN_ID", str(60 + os.getpid() % 40))  # the children inherit it
    if args.one is not None:
        print(json.dumps(one_process(args.one)))
        return 0
    if args.all_one is not None:
        print(json.dumps(all_robots(args.all_one)))
        return 0
    print(json.dumps(measure_all() if args.all else measure(args.repeats), indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
