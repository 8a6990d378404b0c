"""``rtt-run PROJECT_FILE``: open a project and run it, as Choreonoid does.

    rtt-run project/step1.yaml                 # simulate in real time, show in meshcat
    rtt-run project/step1.yaml --headless --duration 5 --json
    rtt-run project/step3.yaml --ros-args -r __node:=rtt_viewer
    rtt-run project/step2.yaml --describe      # and the URDF and odometry, for Foxglove and RViz2

A project with a simulator simulates (real time unless ``--fast``); one
without only configures its controllers (Step 3's viewer).  The node is named
``rtt``; rename a second instance with ``--ros-args -r __node:=NAME``.
On exit it prints a summary (``--json``: one JSON object per line for every
status line and the summary).

Exit status: 0 on a clean end or Ctrl-C/SIGTERM, 1 when a controller or the
simulation failed, 2 for a bad command line (ROS arguments included), a bad
project file or a model file it names that MuJoCo cannot load: one line on
stderr names the file and, where it can, the key.
"""

from __future__ import annotations

import argparse
import json
import signal
import sys

from tutorial.app.app import DEFAULT_NODE_NAME, App, ControllerError
from tutorial.core.project import ProjectError, load_project
from tutorial.core.world import ModelError
from tutorial.ros import env as ros_env
from tutorial.ros import program as ros_program
from tutorial.tools.standalone.app import StandaloneApp
from tutorial.view.status import format_status


def _brief(value) -> str:
    """A value of a summary's dict as text; a dict in it (an arrow's length and visibility) in parentheses."""
    if isinstance(value, dict):
        return "(" + ", ".join(f"{k}={v}" for k, v in value.items()) + ")"
    return str(value)


def format_record(record: dict) -> str:
    """One status record as a human-readable line (or a few, for the summary)."""
    event = record.get("event")
    if event in ("status", "stale", "recovered", "first_state", "publishers"):
        return format_status(record, record.get("node", ""))
    if event == "imu_status":
        age = "no reading yet" if record["age_ms"] is None else f"newest {record['age_ms']:.0f} ms old"
        arrows = ", ".join(
            f"{k.replace('_', ' ')} {a['length']:.3f} m{'' if a['visible'] else ' (hidden)'}"
            for k, a in record["arrows"].items()
        )
        rejected = ", ".join(f"{k} {v}" for k, v in record["rejected"].items()) or "none"
        shaking = " [SHAKING]" if record["shaking"] else ""
        return (
            f"[{record['node']}] {record['topic']}: {record['rate_hz']:.1f} msg/s, {age}, arrows: {arrows}, "
            f"shakes {record['shakes']}, rejected: {rejected}{shaking}"
        )
    if event == "shake":
        return (
            f"[{record['node']}] {record['body']}: collision, {record['horizontal_acceleration']:.1f} m/s^2 "
            "horizontal: shaking the view"
        )
    if event == "shake_end":
        return f"[{record['node']}] {record['body']}: shake over, back at its position"
    if event == "meshcat":
        via = record.get("through_jupyter")
        if via and via.startswith("/"):  # a hub that does not know its public address
            return f"[{record['node']}] meshcat: open this JupyterHub's address followed by {via} in a browser"
        line = f"[{record['node']}] meshcat: open {record['url']} in a browser"
        return f"{line}, or through Jupyter: {via}" if via else line
    if event == "warning":
        return f"[{record.get('node', '')}] WARNING: {record['message']}"
    if event == "summary":
        lines = [f"--- summary: project {record['project']}, node {record['node']} ---"]
        if "simulated_time" in record:
            lines.append(
                f"simulated {record['simulated_time']:.3f} s in {record['wall_time']:.3f} s wall "
                f"(real-time factor {record['real_time_factor']:.3f}, {record['steps']} steps)"
            )
        for name, b in record.get("bodies", {}).items():
            x, y, z = b["root_position"]
            lines.append(f"{name}: root at ({x:.3f}, {y:.3f}, {z:.3f}) m, yaw {b['root_yaw']:.3f} rad")
            joints = "  ".join(f"{k}={v:.4f}" for k, v in b["joint_positions"].items())
            lines.append(f"{name}: joints  {joints}")
        for name, s in record.get("controllers", {}).items():
            lines.append(f"{name}: " + ", ".join(f"{k}={v}" for k, v in s.items() if not isinstance(v, dict)))
            for k, v in s.items():
                if isinstance(v, dict):
                    lines.append(f"{name}: {k}: " + (", ".join(f"{a}={_brief(b)}" for a, b in v.items()) or "none"))
        if record.get("error"):
            lines.append("ERROR:\n" + record["error"])
        return "\n".join(lines)
    if "line" in record:
        return record["line"]
    return " ".join(f"{k}={v}" for k, v in record.items())


def make_output(json_lines: bool):
    """A printer for status records: JSON lines, or :func:`format_record` text.

    Each record goes out in one write, newline included, so lines never mix.
    """

    def output(record: dict) -> None:
        text = json.dumps(record, sort_keys=False) if json_lines else format_record(record)
        sys.stdout.write(text + "\n")
        sys.stdout.flush()

    return output


def build_parser() -> argparse.ArgumentParser:
    """The command line of ``rtt-run`` (ROS arguments are removed before it parses)."""
    p = argparse.ArgumentParser(
        prog="rtt-run",
        description="Open a tutorial project file and run it.",
        epilog="ROS arguments go after --ros-args, e.g. --ros-args -r __node:=rtt_viewer",
    )
    p.add_argument("project", help="project file, e.g. project/step1.yaml")
    p.add_argument("--fast", action="store_true", help="simulate as fast as possible instead of in real time")
    p.add_argument(
        "--duration",
        type=float,
        default=None,
        metavar="SECONDS",
        help="stop after this much simulated time (wall time for a project without simulator)",
    )
    p.add_argument("--headless", action="store_true", help="no meshcat viewer")
    p.add_argument("--json", action="store_true", help="status lines and summary as JSON, one object per line")
    p.add_argument(
        "--describe",
        action="store_true",
        help="a simulation: also publish each robot's URDF (/<body>/robot_description) and odometry "
        "(/<body>/odom) for the stock ROS 2 tools (notebook 09's RttRobotModelPublisher)",
    )
    return p


def describe_robots(project):
    """``project`` with notebook 09's :class:`RttRobotModelPublisher` on each model that has controllers (a
    robot, not scenery) and no robot model publisher yet (the frozen one or the notebook's own, by its class's
    name): what ``--describe`` runs (any thread).

    Raises:
        ProjectError: the project does not simulate (a viewer: it would publish what it listens to).
    """
    from tutorial.app.reference.robot_model_publisher import RttRobotModelPublisher

    if project.simulator is None:
        raise ProjectError(
            f"{project.path}: --describe publishes a simulation's robots; this project does not simulate"
        )
    for entry in project.models:
        has_one = any(c.cls.__name__ == RttRobotModelPublisher.__name__ for c in entry.controllers)
        if entry.controllers and not has_one:
            project = project.with_controller(entry.name, "RttRobotModelPublisher", RttRobotModelPublisher)
    return project


def _stop_on_signal(app: App) -> None:
    """Ctrl-C or SIGTERM asks the app to stop at the end of its current step; a second one interrupts at once.

    A stop request instead of an exception raised at an arbitrary point keeps
    output lines and the meshcat connection whole.
    """

    def handler(signum, frame):
        if app.stop_requested:
            raise KeyboardInterrupt
        app.request_stop()

    signal.signal(signal.SIGINT, handler)
    signal.signal(signal.SIGTERM, handler)


def _fail(text: str, status: int) -> int:
    """One line on stderr (a line break in a name or a message is written as ``\\n``); the exit status."""
    print("rtt-run: " + " \\n ".join(text.splitlines()), file=sys.stderr, flush=True)
    return status


def _model_key(project, exc: ModelError) -> str:
    """``<project>: models[i].file: `` for the model at fault, or the project alone."""
    for i, entry in enumerate(project.models):
        if entry is exc.entry:
            return f"{project.path}: models[{i}].file: "
    return f"{project.path}: models: "


def main(argv: list[str] | None = None) -> int:
    """``rtt-run``: parse the command line, run the project, print the summary; the exit status (main thread)."""
    argv = list(sys.argv if argv is None else argv)
    args = ros_program.parse_command_line(build_parser(), argv)
    if args.duration is not None and not args.duration > 0:
        build_parser().error("--duration must be > 0")
    output = make_output(args.json)
    try:
        project = load_project(args.project)
        if args.describe:
            project = describe_robots(project)
    except ProjectError as exc:
        return _fail(str(exc), 2)
    import rclpy
    from rclpy.executors import ExternalShutdownException
    from rclpy.signals import SignalHandlerOptions

    ros_env.use_localhost_by_default()
    rclpy.init(args=argv, signal_handler_options=SignalHandlerOptions.NO)
    app = StandaloneApp(
        project,
        node_name=DEFAULT_NODE_NAME,
        headless=args.headless,
        realtime_sync=False if args.fast else None,
        duration=args.duration,
        output=output,
    )
    _stop_on_signal(app)  # SIGTERM (a launcher stopping us) ends the run like Ctrl-C: cleanly
    status = 0
    try:
        app.open()
        app.run()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except ModelError as exc:  # a bad model file: the project's fault, like a bad key
        status = _fail(_model_key(project, exc) + str(exc), 2)
    except (ControllerError, ValueError, RuntimeError) as exc:
        status = _fail(str(exc), 1)
    finally:
        ros_program.ignore_stop_signals()  # a second Ctrl-C must not break the clean-up
        try:
            app.close()
            if hasattr(app, "bodies"):
                record = app.summary()
                if record.get("error"):
                    status = 1
                output(record)
        finally:
            rclpy.try_shutdown()
    return status


if __name__ == "__main__":
    sys.exit(main())
