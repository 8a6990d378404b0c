"""Step 5: the simulation publishing joint state and IMU, the joystick, and the
viewer (``rtt_viewer``) showing both: the turret, an acceleration arrow (red),
an angular-velocity arrow (blue), and a shake when the simulated tank hits a wall.

    python launch_py/step5_launch.py --demo
    python launch_py/step5_launch.py --demo --record drive.mcap   # also record the topics below
"""

import sys

from _common import PROJECT, joy_node, record_nodes, simulation_node

from tutorial.ros.launch import LaunchDescription, NodeProcess, launch_parser, run

TOPICS = ["/joy", "/Tank/joint_state", "/Tank/imu"]  # what --record records


def generate_launch_description(args) -> LaunchDescription:
    viewer_args = [str(PROJECT / "step5.yaml")] + (["--headless"] if args.headless else [])
    return LaunchDescription(
        [
            *record_nodes(args, TOPICS),  # first: up before the publishers start
            joy_node(args, script="wall"),  # ram the wall ahead: the viewer shakes
            simulation_node(args, "reference/step4.yaml"),  # Step 4 as later steps run it: frozen
            NodeProcess("rtt_viewer", "tutorial.tools.rtt_run", viewer_args),
        ]
    )


if __name__ == "__main__":
    sys.exit(run(generate_launch_description(launch_parser(__doc__).parse_args())))
