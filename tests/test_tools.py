"""rtt-plot and rtt-graph, the stand-ins for rqt_plot and rqt_graph, against a running Step 2."""

import json

from conftest import module_command


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
