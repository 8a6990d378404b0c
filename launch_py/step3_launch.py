"""Step 3: the simulation publishing joint state, the joystick, and a second,
separately named viewer process (``rtt_viewer``) showing the joint state.

    python launch_py/step3_launch.py --demo
    python launch_py/step3_launch.py --demo --record drive.mcap   # also record /joy, /Tank/joint_state
    python launch_py/step3_launch.py --demo --record drive.mcap --tf   # and TF: Foxglove replays it in 3D
"""

import sys

from _common import PROJECT, joy_node, record_nodes, simulation_node

from tutorial.ros.launch import LaunchDescription, NodeProcess, launch_parser, run


def generate_launch_description(args) -> LaunchDescription:
    viewer_args = [str(PROJECT / "step3.yaml")] + (["--headless"] if args.headless else [])
    return LaunchDescription(
        [
            *record_nodes(args, ["/joy", "/Tank/joint_state"]),  # first: up before the publishers start
            joy_node(args),
            simulation_node(args, "reference/step2.yaml"),  # Step 2 as later steps run it: frozen
            NodeProcess("rtt_viewer", "tutorial.tools.rtt_run", viewer_args),
        ]
    )


if __name__ == "__main__":
    sys.exit(run(generate_launch_description(launch_parser(__doc__).parse_args())))
