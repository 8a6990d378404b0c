"""Step 1: the joystick and the tank simulation, each its own process.

python launch_py/step1_launch.py --demo
python launch_py/step1_launch.py --demo --record drive.mcap   # also record /joy
"""

import sys

from _common import joy_node, record_nodes, simulation_node

from tutorial.ros.launch import LaunchDescription, launch_parser, run


def generate_launch_description(args) -> LaunchDescription:
    return LaunchDescription([*record_nodes(args, ["/joy"]), joy_node(args), simulation_node(args, "step1.yaml")])


if __name__ == "__main__":
    sys.exit(run(generate_launch_description(launch_parser(__doc__).parse_args())))
