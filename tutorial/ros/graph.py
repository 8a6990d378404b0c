"""The ROS 2 graph: which nodes publish and subscribe which topics, and a picture of it.

:func:`read_graph` asks the middleware what a node sees; :func:`draw_graph`
draws it left to right, as rqt_graph does.  ``rtt-graph`` and the notebooks
(:mod:`tutorial.notebook.graph_picture`) use both.
"""

from __future__ import annotations

from dataclasses import dataclass, field

HIDDEN_TOPICS = {"/rosout", "/parameter_events"}  # ROS 2's own, hidden unless asked for


@dataclass
class Graph:
    """Nodes (fully qualified names) and, per topic, its type, publishers and subscribers."""

    nodes: list[str] = field(default_factory=list)
    topics: dict[str, dict] = field(default_factory=dict)

    def text(self) -> str:
        lines = ["nodes:"] + [f"  {n}" for n in self.nodes] + ["topics:"]
        for topic, t in sorted(self.topics.items()):
            lines.append(f"  {topic} [{t['type']}]")
            lines.append(f"    publishers:  {', '.join(sorted(t['publishers'])) or '-'}")
            lines.append(f"    subscribers: {', '.join(sorted(t['subscribers'])) or '-'}")
        return "\n".join(lines)

    def as_dict(self) -> dict:
        return {"nodes": self.nodes, "topics": self.topics}


def read_graph(node, show_all: bool = False) -> Graph:
    """The graph as ``node`` sees it now (the node's owner thread)."""
    me = node.get_fully_qualified_name()
    g = Graph()
    for name, ns in sorted(node.get_node_names_and_namespaces()):
        fq = (ns.rstrip("/") + "/" + name) if ns != "/" else "/" + name
        if fq == me:
            continue
        g.nodes.append(fq)
        for getter, role in (
            (node.get_publisher_names_and_types_by_node, "publishers"),
            (node.get_subscriber_names_and_types_by_node, "subscribers"),
        ):
            for topic, types in getter(name, ns):
                if not show_all and topic in HIDDEN_TOPICS:
                    continue
                t = g.topics.setdefault(topic, {"type": ", ".join(types), "publishers": [], "subscribers": []})
                t[role].append(fq)
    return g


def draw_graph(graph: Graph, path: str) -> None:
    """Save a picture of the graph, left to right as rqt_graph draws it (any thread; matplotlib Agg).

    Nodes are rounded green boxes, topics square yellow boxes, each sized to
    its name; arrows run publisher -> topic -> subscriber.  The figure is
    sized from the layout (columns of the graph, rows in the fullest column),
    so a small graph gives a small picture with no empty half.
    """
    import networkx as nx
    from matplotlib.figure import Figure

    g = nx.DiGraph()
    for n in graph.nodes:
        g.add_node(n, kind="node")
    for topic, t in graph.topics.items():
        g.add_node(topic, kind="topic")
        for p in t["publishers"]:
            g.add_edge(p, topic)
        for s in t["subscribers"]:
            g.add_edge(topic, s)
    if len(g) and nx.is_directed_acyclic_graph(g):
        columns = [sorted(names) for names in nx.topological_generations(g)]
    else:  # a cycle (a node that subscribes to what it publishes): one column per kind
        columns = [sorted(n for n, d in g.nodes(data=True) if d["kind"] == k) for k in ("node", "topic")]
    columns = [c for c in columns if c] or [[]]
    rows = max(len(c) for c in columns) or 1
    longest = max((len(n) for n in g), default=4)
    column_width = 0.4 + 0.1 * longest  # inches: wide enough for the longest name at 12 pt
    fig = Figure(figsize=(max(3.0, column_width * len(columns)), 0.4 + 0.8 * rows))
    ax = fig.add_axes((0, 0, 1, 1))
    ax.set_xlim(-0.5, len(columns) - 0.5)
    ax.set_ylim(-0.5, rows - 0.5)
    ax.axis("off")
    boxes = {}
    for x, names in enumerate(columns):
        top = (rows - 1 + len(names) - 1) / 2  # centre each column vertically
        for i, name in enumerate(names):
            topic = g.nodes[name]["kind"] == "topic"
            style = dict(
                boxstyle="square,pad=0.35" if topic else "round,pad=0.45",
                fc="#f2d49b" if topic else "#9fd3a8",
                ec="#666",
            )
            boxes[name] = ax.text(x, top - i, name, ha="center", va="center", fontsize=12, bbox=style)
    fig.canvas.draw()  # the boxes get their sizes, so the arrows can end at their edges
    for a, b in g.edges:
        ax.annotate(
            "",
            xy=boxes[b].get_position(),
            xytext=boxes[a].get_position(),
            arrowprops=dict(
                arrowstyle="-|>",
                color="#555",
                shrinkA=2,
                shrinkB=2,
                patchA=boxes[a].get_bbox_patch(),
                patchB=boxes[b].get_bbox_patch(),
            ),
        )
    fig.savefig(path, dpi=100)
