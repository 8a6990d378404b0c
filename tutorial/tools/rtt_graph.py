"""``rtt-graph``: the ROS 2 graph, nodes and topics (rqt_graph's stand-in).

    rtt-graph                       # text, after 4 s of discovery
    rtt-graph --output graph.png    # and a picture

Lists every node with the topics it publishes and subscribes, and draws the
graph (node ellipses, topic boxes, arrows publisher -> topic -> subscriber)
with networkx and matplotlib.  ROS 2's own ``/rosout`` and parameter-event
topics are hidden unless ``--all``; this node hides itself.
"""

from __future__ import annotations

import argparse
import sys
import time

from tutorial.ros import env as ros_env
from tutorial.ros import program as ros_program
from tutorial.ros.graph import draw_graph, read_graph

NODE_NAME = "rtt_graph"


def main(argv: list[str] | None = None) -> int:
    """``rtt-graph``: discover for ``--wait`` s, print the graph (and draw it); the exit status."""
    import json

    import rclpy

    argv = list(sys.argv if argv is None else argv)
    p = argparse.ArgumentParser(prog="rtt-graph", description="Show ROS 2 nodes and topics.")
    p.add_argument(
        "--wait",
        type=float,
        default=4.0,
        help="seconds of discovery before reading the graph (default 4: on localhost, Fast DDS "
        "may need one 3 s announcement period to see every node)",
    )
    p.add_argument("--output", default=None, help="also draw the graph into this PNG")
    p.add_argument("--all", action="store_true", help="show /rosout and /parameter_events too")
    p.add_argument("--json", action="store_true", help="print the graph as one JSON object")
    args = ros_program.parse_command_line(p, argv)
    ros_env.use_localhost_by_default()
    rclpy.init(args=argv)
    node = rclpy.create_node(NODE_NAME)
    try:
        end = time.monotonic() + args.wait
        while time.monotonic() < end:
            rclpy.spin_once(node, timeout_sec=min(0.1, max(0.0, end - time.monotonic())))
        graph = read_graph(node, show_all=args.all)
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    print(json.dumps(graph.as_dict()) if args.json else graph.text(), flush=True)
    if args.output:
        draw_graph(graph, args.output)
        print(f"graph drawn to {args.output}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
