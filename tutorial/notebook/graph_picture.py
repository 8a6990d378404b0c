"""The ROS 2 graph as a picture in a notebook (``rqt_graph``'s role; ``rtt-graph`` prints the same)."""

from __future__ import annotations

import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from tutorial.notebook import session


def graph_picture(
    ready: Callable[[object], bool] = lambda graph: True, timeout: float = 20.0, node_name: str = "rtt_notebook_graph"
):
    """The ROS graph as seen from a new node: ``(Graph, PNG bytes)`` (kernel thread).

    Args:
        ready: ``ready(graph)`` says whether everything expected has been
            discovered (that can take a few seconds); the graph is re-read until then.
        timeout: the longest wait, s; the graph is read then, complete or not.
        node_name: the name of the short-lived node that looks (it hides itself).
    """
    import rclpy

    from tutorial.ros.graph import draw_graph, read_graph

    session.init_ros()
    node = rclpy.create_node(node_name)
    try:
        deadline = time.monotonic() + timeout
        graph = read_graph(node)
        while not ready(graph) and time.monotonic() < deadline:
            rclpy.spin_once(node, timeout_sec=0.1)
            graph = read_graph(node)
    finally:
        node.destroy_node()
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "graph.png"
        draw_graph(graph, str(path))
        return graph, path.read_bytes()
