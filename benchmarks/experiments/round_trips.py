"""A service's and a parameter set's round trip: notebook 10's tank against a bare rclpy node, in one run.

    python -m benchmarks.experiments.round_trips [--calls 300] [--rounds 3]

The tutorial: ``rtt-run project/step10.yaml --headless``, its ``/Tank/reset``
(``std_srvs/Trigger``, answered once the simulation thread has reset the
tank at its next step) and its parameter
``RttTunableTankController.max_track_speed`` (judged by the controller's
on-set callback and the App's, used by a post-set one).  The baseline: a
bare rclpy node in a process of its own (:mod:`benchmarks.bare_service`),
a ``Trigger`` service that answers at once and a parameter with no
callback.  The client is this process: each call is timed from
``call_async`` to its answer on a spinning ``SingleThreadedExecutor``, one
call at a time.  Rounds alternate the two, so a drift of the machine's
speed lands on both; figures are p50 and p99 in ms, and their ratios.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import threading
import time

from benchmarks.procs import py, start
from benchmarks.stats import pct

TUTORIAL = ("/Tank/reset", "/rtt", "RttTunableTankController.max_track_speed")
BARE = ("/bare/reset", "/bare_service", "max_track_speed")


def _wait(future, timeout: float = 10.0):
    """The future's result, completed by the client's spin thread."""
    import threading

    done = threading.Event()
    future.add_done_callback(lambda _: done.set())
    if not done.wait(timeout):
        raise RuntimeError(f"no answer within {timeout:g} s")
    return future.result()


def _clients(node, service: str, node_name: str, parameter: str) -> tuple:
    """``(Trigger client, parameter client, parameter name)`` of a target, made once: a client made per round
    stays in the node's wait set, and the round trips grew with each (4 ms to 25 ms over four rounds)."""
    from rclpy.parameter_client import AsyncParameterClient
    from std_srvs.srv import Trigger

    client = node.create_client(Trigger, service)
    parameters = AsyncParameterClient(node, node_name)
    if not client.wait_for_service(timeout_sec=30) or not parameters.wait_for_services(timeout_sec=30):
        raise RuntimeError(f"{service} or {node_name}'s parameter services never appeared")
    return client, parameters, parameter


def _calls(client, parameters, parameter: str, calls: int) -> tuple[list[float], list[float]]:
    """``calls`` service round trips and ``calls`` parameter sets, s each."""
    from rclpy.parameter import Parameter
    from std_srvs.srv import Trigger

    services, sets = [], []
    for k in range(calls):
        began = time.perf_counter()
        answer = _wait(client.call_async(Trigger.Request()))
        services.append(time.perf_counter() - began)
        if not answer.success:
            raise RuntimeError(f"{client.srv_name}: {answer.message}")
        value = 1.0 + (k % 2)  # a change every time
        began = time.perf_counter()
        result = _wait(parameters.set_parameters([Parameter(parameter, value=value)])).results[0]
        sets.append(time.perf_counter() - began)
        if not result.successful:
            raise RuntimeError(f"{parameter}: {result.reason}")
    return services, sets


def measure(calls: int = 300, rounds: int = 3) -> dict:
    """The round trips' p50 and p99 (ms), the tutorial's and the bare node's, and their ratios."""
    import rclpy

    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    os.environ.setdefault("ROS_DOMAIN_ID", str(random.randint(1, 100)))
    sim = start(py("tutorial.tools.rtt_run", "project/step10.yaml", "--headless"))
    bare = start(py("benchmarks.bare_service"))
    own = not rclpy.ok()
    if own:
        rclpy.init()
    from rclpy.executors import SingleThreadedExecutor

    node = rclpy.create_node("round_trip_client")
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    spinner = threading.Thread(target=executor.spin, daemon=True)
    spinner.start()
    samples = {"tutorial": ([], []), "bare": ([], [])}
    try:
        targets = {"tutorial": _clients(node, *TUTORIAL), "bare": _clients(node, *BARE)}
        for clients in targets.values():
            _calls(*clients, 20)  # warm-up: the first calls
        for _ in range(rounds):
            for name, clients in targets.items():
                services, sets = _calls(*clients, calls)
                samples[name][0].extend(services)
                samples[name][1].extend(sets)
    finally:
        executor.shutdown()
        spinner.join(timeout=5)
        node.destroy_node()
        if own:
            rclpy.try_shutdown()
        for proc in (sim, bare):
            proc.terminate()
            proc.communicate(timeout=20)
    out: dict = {"calls": calls * rounds}
    for kind, index in (("service", 0), ("parameter_set", 1)):
        tutorial, baseline = pct(samples["tutorial"][index], 1e3), pct(samples["bare"][index], 1e3)
        out[kind] = {
            "tutorial_ms": tutorial,
            "bare_ms": baseline,
            "p50_ratio": round(tutorial["p50"] / baseline["p50"], 2),
            "p99_ratio": round(tutorial["p99"] / baseline["p99"], 2),
        }
    return out


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--calls", type=int, default=300, help="calls of each kind per round and target")
    p.add_argument("--rounds", type=int, default=3)
    args = p.parse_args()
    print(json.dumps(measure(args.calls, args.rounds), indent=2))


if __name__ == "__main__":
    main()
