"""The controller lifecycle runs in Choreonoid's order, each method on its thread."""

import threading

from tests.fixtures import recording_controller as rec
from tutorial.app.app import App
from tutorial.core.project import load_project

from conftest import MODEL


def write_project(tmp_path, controller_class, simulate=True, parameters=""):
    text = f"""
name: lifecycle
models:
  - name: Tank
    file: {MODEL / "tank.xml"}
    controllers:
      - name: Rec
        class: {controller_class}
{parameters}
"""
    if simulate:
        text += "simulator:\n  time_step: 0.001\n  realtime_sync: false\n"
    path = tmp_path / "p.yaml"
    path.write_text(text)
    return load_project(path)


def run_app(project, node, duration):
    app = App(project, node=node, headless=True, duration=duration, output=lambda r: None)
    try:
        app.open()
        app.run()
    finally:
        app.close()
    return app


def test_lifecycle_order_and_threads(tmp_path, node):
    rec.CALLS.clear()
    project = write_project(tmp_path, "tests.fixtures.recording_controller:RecordingController")
    app = run_app(project, node, duration=0.010)
    names = [c for c, _ in rec.CALLS]
    assert names == ["configure", "initialize", "start"] + ["control"] * 10 + ["stop", "unconfigure"]
    main = threading.current_thread().name
    threads = dict((c, t) for c, t in rec.CALLS)
    assert threads["configure"] == threads["unconfigure"] == main
    assert threads["initialize"] == threads["start"] == threads["control"] == threads["stop"] == "simulation"
    assert app.sim.steps == 10


def test_project_without_simulator_only_configures(tmp_path, node):
    rec.CALLS.clear()
    project = write_project(tmp_path, "tests.fixtures.recording_controller:RecordingController", simulate=False)
    run_app(project, node, duration=0.05)
    assert [c for c, _ in rec.CALLS] == ["configure", "unconfigure"]


def test_parameters_reach_configure(tmp_path, node):
    rec.CALLS.clear()
    project = write_project(
        tmp_path,
        "tests.fixtures.recording_controller:RecordingController",
        simulate=False,
        parameters="        parameters: {gain: 3}",
    )
    app = App(project, node=node, headless=True, duration=0.01, output=lambda r: None)
    app.open()
    try:
        controller = app.controller("Rec")
        assert controller.params == {"gain": 3.0, "label": "x"}
    finally:
        app.close()


def test_a_controller_that_refuses_to_initialize_is_reported(tmp_path, node):
    project = write_project(tmp_path, "tests.fixtures.recording_controller:RefusingController")
    app = run_app(project, node, duration=1.0)
    summary = app.summary()
    assert "refused to initialize" in summary["error"]
    assert app.sim.steps == 0


def test_a_callback_that_raises_ends_the_run_and_is_reported(tmp_path, node):
    from std_msgs.msg import String

    from conftest import wait_until

    project = write_project(tmp_path, "tests.fixtures.recording_controller:BrokenCallbackController", simulate=False)
    app = App(project, node_name="broken_callback_app", headless=True, duration=60.0, output=lambda r: None)
    pub = node.create_publisher(String, "/broken_callback", 10)
    try:
        app.open()
        assert wait_until(lambda: pub.get_subscription_count() > 0, timeout=10)
        pub.publish(String(data="x"))
        assert app.loop.run_until(app.done, timeout=10)  # ended long before its 60 s duration
    finally:
        app.close()
    assert "a subscription callback raised" in app.summary()["error"]
    assert "cannot handle 'x'" in app.summary()["error"]


def test_the_base_controllers_steps_say_go_on():
    """A controller that overrides only ``configure`` runs: the base ``initialize``, ``start``, ``control`` say True."""
    from tutorial.core.controller import SimpleController

    c = SimpleController()
    assert c.initialize(None) is True and c.start() is True and c.control() is True
