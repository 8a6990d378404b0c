"""Shared by the launch files: where the project files are, the Step 2 pair of nodes, the recorder."""

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PROJECT = ROOT / "project"
sys.path.insert(0, str(ROOT))  # run from a clone without installing, too

from tutorial.ros.launch import NodeProcess  # noqa: E402


def joy_node(args, script: str = "drive") -> NodeProcess:
    """The joystick: with --demo the demo ``script`` (``drive`` or ``wall``), else a gamepad or the keyboard."""
    return NodeProcess("rtt_joy", "tutorial.tools.rtt_joy", ["--demo", "--script", script] if args.demo else [])


def simulation_node(args, project: str) -> NodeProcess:
    """The simulation (``rtt``), required: when it ends, the launch ends.

    With ``--tf`` it also publishes the robot's URDF and odometry (``rtt-run --describe``), which the
    recorder computes TF from.
    """
    extra = (["--headless"] if args.headless else []) + (["--duration", str(args.duration)] if args.duration else [])
    extra += ["--describe"] if getattr(args, "tf", False) else []
    return NodeProcess("rtt", "tutorial.tools.rtt_run", [str(PROJECT / project), *extra], required=True)


def record_nodes(args, topics: list[str]) -> list[NodeProcess]:
    """With ``--record FILE.mcap``: ``rtt-bag record`` of the step's ``topics`` as node ``rtt_bag``; else none.

    With ``--tf`` too, it also records what Foxglove and RViz2 need to draw the
    robot (``rtt-bag record --tf``).

    Put it first in the launch description: started before the publishers,
    it has joined the ROS graph when they appear, and records from their
    first message (a recorder that joins later can take up to one of Fast
    DDS's 3 s discovery periods to see them).  Not required: when the
    simulation ends, the launch stops the recorder with SIGINT and it
    closes the file whole.
    """
    if not args.record:
        return []
    tf = ["--tf"] if getattr(args, "tf", False) else []  # and the robot description, odometry, /tf
    return [NodeProcess("rtt_bag", "tutorial.tools.rtt_bag", ["record", *topics, *tf, "-o", args.record])]
