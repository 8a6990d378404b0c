"""Shared by the launch files: where the project files are, and the Step 2 pair of nodes."""

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PROJECT = ROOT / "project"
sys.path.insert(0, str(ROOT))  # run from a clone without installing, too

from tutorial.launch import Node  # noqa: E402


def joy_node(args) -> Node:
    """The joystick: scripted with --demo, else a gamepad or this terminal's keyboard."""
    return Node("rtt_joy", "tutorial.joy_node", ["--demo"] if args.demo else [])


def simulation_node(args, project: str) -> Node:
    """The simulation (``rtt``), required: when it ends, the launch ends."""
    extra = (["--headless"] if args.headless else []) + (["--duration", str(args.duration)] if args.duration else [])
    return Node("rtt", "tutorial.runner", [str(PROJECT / project), *extra], required=True)
