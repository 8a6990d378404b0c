"""The baseline of a service's and a parameter set's round trip: a bare rclpy node.

    python -m benchmarks.bare_service        (until SIGTERM or Ctrl-C)

The node ``/bare_service`` offers ``/bare/reset`` (``std_srvs/Trigger``,
answered at once) and has the parameter ``max_track_speed`` (a float, no
callback), spun by rclpy's ``SingleThreadedExecutor`` as the tutorial's
spin thread is: the same calls as notebook 10's tank answers, with nothing
of the tutorial in between.
"""

from __future__ import annotations

import rclpy
from rclpy.executors import ExternalShutdownException
from std_srvs.srv import Trigger

from tutorial.ros import env as ros_env


def main() -> None:
    ros_env.use_localhost_by_default()
    rclpy.init()  # rclpy's own handlers: SIGINT and SIGTERM end the spin
    node = rclpy.create_node("bare_service")
    node.declare_parameter("max_track_speed", 3.0)

    def reset(request, response):
        response.success = True
        return response

    node.create_service(Trigger, "/bare/reset", reset)
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
