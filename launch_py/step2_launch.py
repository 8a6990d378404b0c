"""Step 2: Step 1 plus the JointState publisher, and a plot of the turret joints.

python launch_py/step2_launch.py --demo
python launch_py/step2_launch.py --demo --record drive.mcap   # also record /joy, /Tank/joint_state
"""

import sys

from _common import joy_node, record_nodes, simulation_node

from tutorial.ros.launch import LaunchDescription, NodeProcess, launch_parser, run


def generate_launch_description(args) -> LaunchDescription:
    plot_args = ["--output", "step2_plot.png"] if args.headless else []
    return LaunchDescription(
        [
            *record_nodes(args, ["/joy", "/Tank/joint_state"]),  # first: up before the publishers start
            joy_node(args),
            simulation_node(args, "step2.yaml"),
            NodeProcess("rtt_plot", "tutorial.tools.rtt_plot", ["--body", "Tank", *plot_args]),
        ]
    )


if __name__ == "__main__":
    sys.exit(run(generate_launch_description(launch_parser(__doc__).parse_args())))
