"""The operator's side of ``benchmarks.experiments.network``: what arrived, when, and how big.

    python -m benchmarks.net_probe camera --transport compressed --duration S --out FILE
    python -m benchmarks.net_probe bytes --duration S --out FILE TOPIC:TYPE [TOPIC:TYPE ...]

``camera``: an :class:`tutorial.view.images.ImageReceiver` (what ``rtt-image``
uses: every picture checked and decoded) that also notes each accepted
picture's stamp, the ``time.monotonic_ns()`` its callback ended (the clock
every process of the machine shares, namespaces too) and its size.
``bytes``: serialized subscriptions (nothing decoded) to each topic, noting
every message's size and arrival: a topic's bandwidth.  Both write JSON to
``--out`` when ``--duration`` s of wall-clock time are over, or on Ctrl-C.
"""

from __future__ import annotations

import argparse
import importlib
import json
import signal
import sys
import threading
import time

import rclpy
from rclpy.signals import SignalHandlerOptions

from tutorial.ros import env as ros_env
from tutorial.ros import spin as ros_spin
from tutorial.view.images import ImageReceiver


class TimedReceiver(ImageReceiver):
    """An ImageReceiver that notes ``(stamp ns, arrival ns, bytes)`` of every picture it accepts."""

    def __init__(self, node, topic, transport):
        self.log: list[tuple[int, int, int]] = []  # spin thread appends; read after it stopped
        super().__init__(node, topic, transport)

    def on_image(self, msg) -> None:
        before = self.counts()["accepted"]
        super().on_image(msg)
        if self.counts()["accepted"] > before:
            stamp = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
            self.log.append((stamp, time.monotonic_ns(), len(msg.data)))


def message_type(name: str):
    """``sensor_msgs/msg/JointState`` -> the class."""
    package, _, cls = name.split("/")
    return getattr(importlib.import_module(f"{package}.msg"), cls)


def main(argv=None) -> int:
    p = argparse.ArgumentParser()
    p.add_argument("mode", choices=("camera", "bytes"))
    p.add_argument("topics", nargs="*")
    p.add_argument("--transport", default="compressed")
    p.add_argument("--topic", default="/Tank/camera/image")
    p.add_argument("--duration", type=float, required=True)
    p.add_argument("--out", required=True)
    args = p.parse_intermixed_args(argv)
    ros_env.use_localhost_by_default()
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node("bench_net_probe")
    result: dict = {}
    if args.mode == "camera":
        receiver = TimedReceiver(node, args.topic, args.transport)
    else:
        from tutorial.interfaces.compressed_image import compressed_image_qos

        lock = threading.Lock()
        sizes: dict[str, list[tuple[int, int]]] = {}
        for spec in args.topics:
            topic, kind = spec.split(":")
            sizes[topic] = []
            qos = compressed_image_qos() if "Image" in kind else 10  # best effort for the camera, else reliable

            def on_message(data, topic=topic):
                with lock:
                    sizes[topic].append((time.monotonic_ns(), len(data)))

            node.create_subscription(message_type(kind), topic, on_message, qos, raw=True)
    spin = ros_spin.SpinThread(node).start()
    stop = threading.Event()  # Ctrl-C (the benchmark's SIGINT) ends listening early; the file is still written
    signal.signal(signal.SIGINT, lambda signum, frame: stop.set())
    print("probe: subscribed", flush=True)
    stop.wait(args.duration)
    spin.stop()
    if args.mode == "camera":
        result = {"pictures": receiver.log, "counts": receiver.counts(), "topic": receiver.topic}
    else:
        result = {"sizes": sizes}
    with open(args.out, "w") as f:
        json.dump(result, f)
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())


def _best_effort_monitor():
    from rclpy.qos import ReliabilityPolicy

    import tutorial.controllers.joint_state_subscriber as step3
    from benchmarks.probes import ProbedJointStateSubscriber

    class BestEffortMonitor(ProbedJointStateSubscriber):
        """The probed monitor, its live subscription best effort, keep last 1, volatile."""

        def configure(self, config) -> bool:
            viewer_qos = step3.joint_state_viewer_qos

            def best_effort():
                qos = viewer_qos()
                qos.reliability = ReliabilityPolicy.BEST_EFFORT
                return qos

            step3.joint_state_viewer_qos = best_effort  # this process only: the benchmark's own monitor
            try:
                return super().configure(config)
            finally:
                step3.joint_state_viewer_qos = viewer_qos

    return BestEffortMonitor


def __getattr__(name: str):
    if name == "BestEffortMonitor":
        return _best_effort_monitor()
    raise AttributeError(name)
