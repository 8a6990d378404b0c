"""rtt-plot and rtt-graph, the stand-ins for rqt_plot and rqt_graph, against a running Step 2; every
program's answer to a bad ``--ros-args``."""

import contextlib
import importlib
import io
import json

import pytest

from conftest import module_command

PROGRAMS = {  # prog name: module whose main() it runs
    "rtt-run": "tutorial.tools.rtt_run",
    "rtt-joy": "tutorial.tools.rtt_joy",
    "rtt-plot": "tutorial.tools.rtt_plot",
    "rtt-graph": "tutorial.tools.rtt_graph",
    "rtt-image": "tutorial.tools.rtt_image",
    "rtt-foxglove": "tutorial.tools.rtt_foxglove",
    "rtt-bag": "tutorial.tools.rtt_bag",
}


def test_a_plot_draws_the_joints_in_the_messages_order():
    """rtt-plot's and the notebooks' live plot: each joint keeps the colour a plot in the model's joint order
    gives it (notebook 02 shows both, one above the other); sorted by name, TURRET_P and TURRET_Y swapped."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure
    from sensor_msgs.msg import JointState

    from tutorial.view.joint_plot import JointStateHistory, draw

    class Node:  # the subscription is recorded, never made
        def create_subscription(self, *args, **kw):
            return args

    history = JointStateHistory(Node(), "/Tank/joint_state")
    names = ["TURRET_Y", "TURRET_P"]  # the tank's order: the model's, the publisher's
    for t in range(3):
        history.on_message(JointState(name=names, position=[0.1 * t, -0.1 * t]))
    ax = Figure().add_subplot()
    draw(ax, history.series(), "/Tank/joint_state")
    assert [line.get_label() for line in ax.get_lines()] == names
    assert [text.get_text() for text in ax.get_legend().get_texts()] == names


@pytest.mark.parametrize("prog", sorted(PROGRAMS))
@pytest.mark.parametrize("ros_args", [["-r", "foo"], ["-r", "__node:=bad-name"], ["-p", "x"]])
def test_a_bad_ros_argument_is_one_line_and_status_2(prog, ros_args):
    """Before, every program but rtt-run and rtt-bag ended in rcl's traceback (RCLInvalidROSArgsError)."""
    main = importlib.import_module(PROGRAMS[prog]).main
    own = ["info", "x.mcap"] if prog == "rtt-bag" else ["project/step2.yaml"] if prog == "rtt-run" else []
    err = io.StringIO()
    with contextlib.redirect_stderr(err), pytest.raises(SystemExit) as exit_:
        main([prog, *own, "--ros-args", *ros_args])
    assert exit_.value.code == 2
    [line] = err.getvalue().splitlines()
    assert line.startswith(f"{prog}: bad ROS arguments after --ros-args: Failed to parse ROS arguments: "), line


@pytest.mark.more  # make test: the plot in-process (above), notebook 02's live plot and 03's graph (nbval); the
# programs' own command lines (--json, --output, --wait) only here
def test_plot_and_graph_of_a_running_step2(procs, tmp_path):
    png = tmp_path / "plot.png"
    graph_png = tmp_path / "graph.png"
    plot = procs(
        module_command(
            "tutorial.tools.rtt_plot", "--body", "Tank", "--duration", "9", "--output", str(png), "--no-window"
        )
    )
    joy = procs(module_command("tutorial.tools.rtt_joy", "--demo", "--duration", "10"))
    sim = procs(module_command("tutorial.tools.rtt_run", "project/step2.yaml", "--headless", "--duration", "10"))
    joy.wait_for_line(lambda line: "the demo starts" in line, timeout=30)
    graph = procs(module_command("tutorial.tools.rtt_graph", "--wait", "4", "--json", "--output", str(graph_png)))
    assert graph.wait(60) == 0, graph.err
    g = json.loads(graph.out.splitlines()[0])
    assert {"/rtt", "/rtt_joy", "/rtt_plot"} <= set(g["nodes"])
    assert g["topics"]["/joy"]["publishers"] == ["/rtt_joy"] and g["topics"]["/joy"]["subscribers"] == ["/rtt"]
    js = g["topics"]["/Tank/joint_state"]
    assert js["type"] == "sensor_msgs/msg/JointState" and js["publishers"] == ["/rtt"]
    assert js["subscribers"] == ["/rtt_plot"]
    assert graph_png.stat().st_size > 5000
    assert plot.wait(60) == 0, plot.err
    line = plot.wait_for_line(lambda line: "written to" in line, timeout=5)
    points = int(line.split("] ")[1].split()[0])
    assert points > 100  # two joints at 50 Hz for a few seconds
    import matplotlib.image

    image = matplotlib.image.imread(str(png))
    assert image.shape[0] > 300 and image.shape[1] > 600
    assert sim.wait(60) == 0


def test_an_unknown_ros_argument_is_named_and_the_syntax_recalled():
    from tutorial.ros.program import remove_ros_args_or_fail

    with pytest.raises(ValueError) as error:
        remove_ros_args_or_fail(["rtt-joy", "--ros-args", "--bogus", "-q"])
    text = str(error.value)
    assert text.startswith("bad ROS arguments after --ros-args: unknown: --bogus -q (they are -r FROM:=TO"), text


def test_a_stop_request_turns_ctrl_c_and_sigterm_into_a_flag():
    """The programs' stop (``tutorial.ros.program.StopRequest``): no KeyboardInterrupt raised mid-call."""
    import os
    import signal
    import time

    from tutorial.ros.program import StopRequest

    calls = []
    before = signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)
    try:
        stop = StopRequest(lambda: calls.append(1)).install()
        assert stop.requested is False
        for n, sig in enumerate((signal.SIGINT, signal.SIGTERM), start=1):
            os.kill(os.getpid(), sig)  # its handler runs on this (main) thread, between two bytecodes
            deadline = time.monotonic() + 5.0
            while len(calls) < n and time.monotonic() < deadline:
                time.sleep(0.001)
            assert len(calls) == n, f"{sig!r} did not reach the handler"
        assert stop.requested is True
    finally:
        signal.signal(signal.SIGINT, before[0])
        signal.signal(signal.SIGTERM, before[1])


@pytest.mark.parametrize("sig", ["SIGINT", "SIGTERM"])
def test_rtt_joy_ends_on_ctrl_c_or_sigterm_with_its_count_and_no_traceback(procs, sig):
    """Before, Ctrl-C raised KeyboardInterrupt inside rclpy's spin_once; now and then it left a task half
    made, whose clean-up printed a traceback (seen once in `make test`'s launch test)."""
    import signal

    joy = procs(module_command("tutorial.tools.rtt_joy", "--demo"))
    joy.wait_for_line(lambda line: "publishing /joy" in line, timeout=30)
    joy.p.send_signal(getattr(signal, sig))
    assert joy.wait(15) == 0, joy.err
    assert "[rtt_joy] published" in joy.out
    assert "Traceback" not in joy.out + joy.err, joy.out + joy.err


def test_rtt_image_says_one_file_written_over_or_numbered_files():
    """Without ``{n}`` one file holds the newest picture, written over and over: not "N files", as it said."""
    from tutorial.tools.rtt_image import _written

    assert _written(10, "camera_image.png") == "camera_image.png written 10 times, holding the newest picture"
    assert _written(1, "camera_image.png") == "camera_image.png written 1 time, holding the newest picture"
    assert _written(3, "frame_{n}.png") == "3 files written (frame_{n}.png)"
