"""Step 4: the joystick and the simulation, which now also publishes ``/Tank/imu``.

python launch_py/step4_launch.py --demo
python launch_py/step4_launch.py --demo --record drive.mcap   # also record the topics below
"""

import sys

from _common import joy_node, record_nodes, simulation_node

from tutorial.ros.launch import LaunchDescription, launch_parser, run

TOPICS = ["/joy", "/Tank/joint_state", "/Tank/imu"]  # what --record records


def generate_launch_description(args) -> LaunchDescription:
    return LaunchDescription(
        [
            *record_nodes(args, TOPICS),  # first: up before the publishers start
            joy_node(args),
            simulation_node(args, "step4.yaml"),
        ]
    )


if __name__ == "__main__":
    sys.exit(run(generate_launch_description(launch_parser(__doc__).parse_args())))
