"""Step 6: the joystick, the simulation, which now also publishes the turret camera's
pictures on ``/Tank/camera/image``, and ``rtt-image`` showing them (rqt_image_view's
stand-in: a window where a display exists, else a PNG file replaced once a second).

    python launch_py/step6_launch.py --demo
    python launch_py/step6_launch.py --demo --headless --image-output view.png
"""

import sys

from _common import joy_node, record_nodes, simulation_node

from tutorial.ros.launch import LaunchDescription, NodeProcess, launch_parser, run

TOPICS = ["/joy", "/Tank/joint_state", "/Tank/camera/image"]  # --record: pictures are 230 KB, 30 a second


def generate_launch_description(args) -> LaunchDescription:
    return LaunchDescription(
        [
            *record_nodes(args, TOPICS),
            joy_node(args),
            simulation_node(args, "step6.yaml"),
            NodeProcess("rtt_image", "tutorial.tools.rtt_image", ["/Tank/camera/image", "--output", args.image_output]),
        ]
    )


def parser():
    p = launch_parser(__doc__)
    p.add_argument(
        "--image-output",
        default="step6_image.png",
        metavar="FILE.png",
        help="the PNG rtt-image writes where there is no display (default step6_image.png)",
    )
    return p


if __name__ == "__main__":
    sys.exit(run(generate_launch_description(parser().parse_args())))
