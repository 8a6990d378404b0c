"""What the notebooks need beyond the library: ROS once per kernel, meshcat
inline, runs that keep the kernel free, teleop widgets and a live plot.

Threads in a notebook: the kernel's main thread runs the cells and the
widget callbacks.  A :class:`BackgroundApp` gives each running project its
own owner thread (the role the main thread plays in ``rtt-run``): it owns
that project's meshcat visualizer and bodies, so the kernel stays free for
widgets and the next cells.  Widgets talk to the simulation the ROS way, by
publishing on ``/joy``.

Every object that starts something registers itself; :func:`reset` stops
them all, so a section can be re-run from its first cell.

``RTT_TEST_MODE=1`` (set by the test suite) shortens the interactive runs.
"""

from __future__ import annotations

import io
import os
import threading
import time
from pathlib import Path
from typing import Callable

from tutorial import ros_env

TEST_MODE = os.environ.get("RTT_TEST_MODE") == "1"
ROOT = Path(__file__).resolve().parent.parent
PROJECT = ROOT / "project"

_active: list = []  # things with a .close() started from cells


def init_ros() -> None:
    """Initialise rclpy once per kernel, without its signal handlers.

    rclpy would otherwise take over SIGINT and shut ROS down when you press
    the notebook's "interrupt" button.  Call it from any cell; calling it again does nothing.
    """
    import rclpy
    from rclpy.signals import SignalHandlerOptions

    ros_env.use_localhost_by_default()
    if not rclpy.ok():
        rclpy.init(signal_handler_options=SignalHandlerOptions.NO)


def reset() -> None:
    """Stop every background run, server and widget started by earlier cells.

    Run it at the top of a section so the section can be re-run safely.
    """
    while _active:
        thing = _active.pop()
        try:
            thing.close()
        except Exception:  # noqa: BLE001 - keep closing the rest
            pass


def _register(thing):
    _active.append(thing)
    return thing


def iframe(url: str, height: int = 400):
    """An IPython ``IFrame`` showing a meshcat page (its URL) inline."""
    from IPython.display import IFrame

    return IFrame(src=url, width="100%", height=height)


class MeshcatPage:
    """A localhost meshcat server and a visualizer owned by the thread that creates it."""

    def __init__(self):
        from tutorial.meshcat_server import start_server

        self.server = start_server()
        self.vis = self.server.visualizer()
        self.url = self.server.web_url
        _register(self)

    def show(self, height: int = 400):
        return iframe(self.url, height)

    def close(self) -> None:
        self.server.close()


def run_project(project: str | Path, duration: float, node_name: str = "rtt", scripted: bool = True,
                fps: float = 30.0, realtime: bool = False):
    """Run a project to completion in this thread, headless, with scripted input.

    Args:
        project: project file (a name in ``project/`` or a path).
        duration: simulated seconds.
        node_name: the run's node name.
        scripted: feed the demo script to ``RttTankController`` by simulated time.
        fps: frame rate of the recorded states.
        realtime: keep simulated time with wall time (False: as fast as possible).

    Returns:
        ``(summary, app, recorder)``: the exit summary, the closed app (its
        bodies hold the final state) and the :class:`tutorial.recorder.StateRecorder`.

    Deterministic: the same arguments give the same numbers on every run.
    """
    from tutorial.app import App
    from tutorial.project import load_project
    from tutorial.recorder import StateRecorder
    from tutorial.scripted_input import ScriptedJoy

    init_ros()
    path = Path(project)
    if not path.exists():
        path = PROJECT / project
    proj = load_project(path)
    body = next(m.name for m in proj.models if m.controllers)
    recorder = StateRecorder(fps)
    app: App | None = None
    attach = [(body, "Recorder", recorder)]
    if scripted:
        attach.insert(0, (body, "ScriptedJoy", ScriptedJoy(lambda: app.controller("RttTankController"))))
    app = App(proj, node_name=node_name, headless=True, realtime_sync=realtime, duration=duration,
              output=lambda record: None, attach=attach)
    try:
        app.open()
        app.run()
    finally:
        app.close()
    return app.summary(), app, recorder


def animation_html(model, times, frames, fps: float = 30.0, camera=None) -> str:
    """A self-contained HTML page: the recorded frames as a looping meshcat animation.

    Args:
        model: the ``MjModel`` the frames belong to.
        times: frame times, s (unused beyond their count; frames are ``1/fps`` apart).
        frames: list of (nq,) ``qpos`` arrays.
        camera: optional ``(position, target)`` for the initial view, m.

    Opens a temporary localhost meshcat server in this thread and closes it.
    """
    import mujoco
    from meshcat.animation import Animation

    from tutorial.meshcat_server import start_server
    from tutorial.scene import Scene, _pose

    server = start_server()
    try:
        vis = server.visualizer()
        data = mujoco.MjData(model)
        data.qpos[:] = frames[0]
        mujoco.mj_kinematics(model, data)
        scene = Scene(vis, model)
        scene.build(data)
        if camera is not None:
            scene.set_camera(*camera)
        anim = Animation(default_framerate=fps)
        for i, q in enumerate(frames):
            data.qpos[:] = q
            mujoco.mj_kinematics(model, data)
            with anim.at_frame(vis, i) as frame:
                for b in scene.moving_bodies:
                    frame[scene.body_path(b)].set_transform(_pose(data.xpos[b], data.xmat[b]))
        vis.set_animation(anim, play=True, repetitions=0)
        return vis.static_html()
    finally:
        server.close()


class BackgroundApp:
    """Run a project on its own owner thread so the kernel stays free for widgets.

    Args:
        project: project file (a name in ``project/`` or a path).
        node_name: the run's node name (two runs need two names).
        headless: no meshcat page.
        duration: stop after this many seconds (simulated, or wall time without a simulator).

    The thread creates, opens, runs and closes the :class:`tutorial.app.App`;
    it owns everything the app's main thread owns.  ``start``, ``stop``,
    ``show`` and ``records`` may be called from any thread.
    """

    def __init__(self, project: str | Path, node_name: str, headless: bool = False,
                 duration: float | None = None):
        from tutorial.project import load_project

        path = Path(project)
        self.project = load_project(path if path.exists() else PROJECT / project)
        self.node_name = node_name
        self.headless = headless
        self.duration = duration
        self._records: list[dict] = []
        self._lock = threading.Lock()
        self._url = threading.Event()
        self._stop = threading.Event()
        self.thread: threading.Thread | None = None
        self.app = None
        self.summary: dict | None = None
        self.error: BaseException | None = None
        _register(self)

    def _output(self, record: dict) -> None:
        with self._lock:
            self._records.append(record)
        if record.get("event") == "meshcat":
            self._url.set()

    def records(self, event: str | None = None) -> list[dict]:
        """Status records so far (all, or those of one event)."""
        with self._lock:
            return [r for r in self._records if event is None or r.get("event") == event]

    def _run(self) -> None:
        from tutorial.app import App

        try:
            self.app = App(self.project, node_name=self.node_name, headless=self.headless,
                           duration=self.duration, output=self._output)
            try:
                self.app.open()
                while not self._stop.is_set() and self.app.step():
                    pass
            finally:
                self.app.close()
                self.summary = self.app.summary()
        except BaseException as exc:  # noqa: BLE001 - reported through .error
            self.error = exc
            self._url.set()

    def start(self) -> "BackgroundApp":
        """Start the run (nothing happens if it is running)."""
        init_ros()
        if self.thread is None or not self.thread.is_alive():
            self._stop.clear()
            self._url.clear()
            self.thread = threading.Thread(target=self._run, name=f"app-{self.node_name}", daemon=True)
            self.thread.start()
        return self

    @property
    def running(self) -> bool:
        return self.thread is not None and self.thread.is_alive()

    def url(self, timeout: float = 30.0) -> str:
        """The run's meshcat URL, once its page is up."""
        if not self._url.wait(timeout) or self.error is not None:
            raise RuntimeError(f"{self.node_name}: no meshcat page ({self.error!r})")
        return next(r["url"] for r in self.records("meshcat"))

    def show(self, height: int = 400):
        return iframe(self.url(), height)

    def stop(self, timeout: float = 10.0) -> dict | None:
        """Stop the run and wait for its summary (None if it did not end in ``timeout`` s)."""
        self._stop.set()  # also covers a stop asked for before the thread has built its App
        if self.app is not None:
            self.app.request_stop()
        if self.thread is not None:
            self.thread.join(timeout)
        return self.summary

    def wait(self, timeout: float) -> dict | None:
        """Wait for a run with a duration to end by itself; its summary."""
        if self.thread is not None:
            self.thread.join(timeout)
        return self.summary

    close = stop


class TeleopPanel:
    """On-screen sticks (sliders) and a real gamepad (ipywidgets ``Controller``) that publish ``/joy``.

    Args:
        node_name: the panel's node name.

    Widget callbacks run on the kernel's thread and publish at once
    (publishing is thread-safe); the ROS side is the same as ``rtt-joy``'s.
    """

    AXES = ("left H", "left V", "right H", "right V")

    def __init__(self, node_name: str = "rtt_teleop"):
        import ipywidgets as w
        import rclpy
        from sensor_msgs.msg import Joy

        init_ros()
        self.node = rclpy.create_node(node_name)
        self.publisher = self.node.create_publisher(Joy, "/joy", 10)
        self.msg_type = Joy
        self.published = 0
        self.sliders = [w.FloatSlider(value=0.0, min=-1.0, max=1.0, step=0.05, description=d,
                                      continuous_update=True) for d in self.AXES]
        for s in self.sliders:
            s.observe(lambda change: self.publish(), names="value")
        self.center = w.Button(description="release sticks")
        self.center.on_click(lambda _: self.release())
        self.gamepad = w.Controller(index=0)
        self.gamepad.observe(self._on_gamepad, names="axes")
        self.widget = w.VBox([w.HBox(self.sliders[:2]), w.HBox(self.sliders[2:]), self.center, self.gamepad])
        _register(self)

    def _on_gamepad(self, change) -> None:
        # The browser's standard mapping: axes 0/1 left stick, 2/3 right stick, right and down positive.
        axes = [a.value for a in self.gamepad.axes]
        for i, slider in enumerate(self.sliders):
            if i < len(axes):
                slider.value = round(-axes[i], 2)

    def axes(self) -> list[float]:
        """The current stick values in the ROS joy convention (8 axes)."""
        return [s.value for s in self.sliders] + [0.0] * 4

    def publish(self) -> None:
        msg = self.msg_type()
        msg.header.stamp = self.node.get_clock().now().to_msg()
        msg.axes = self.axes()
        msg.buttons = [0] * 8
        self.publisher.publish(msg)
        self.published += 1

    def release(self) -> None:
        for s in self.sliders:
            s.value = 0.0
        self.publish()

    def close(self) -> None:
        self.node.destroy_node()


class LivePlot:
    """Joint positions from ``/<body>/joint_state``, redrawn into an image widget twice a second.

    Args:
        body: body name; the topic is ``/<body>/joint_state``.
        window: seconds of history shown.
    """

    def __init__(self, body: str = "Tank", window: float = 10.0, node_name: str = "rtt_live_plot"):
        import ipywidgets as w
        import rclpy

        from tutorial.plot_node import JointStateRecorder

        init_ros()
        self.node = rclpy.create_node(node_name)
        self.topic = f"/{body}/joint_state"
        self.recorder = JointStateRecorder(self.node, self.topic)
        self.spin = ros_env.SpinThread(self.node).start()
        self.window = window
        self.image = w.Image(format="png", width=640)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._refresh, name="live-plot", daemon=True)
        self._thread.start()
        _register(self)

    def render(self) -> bytes:
        """The current plot as PNG bytes (any thread: it uses its own Agg figure)."""
        from matplotlib.figure import Figure

        from tutorial.plot_node import draw

        series = self.recorder.series()
        latest = max((ts[-1] for ts, _ in series.values() if ts), default=0.0)
        trimmed = {n: ([t for t in ts if t >= latest - self.window],
                       [q for t, q in zip(ts, qs) if t >= latest - self.window]) for n, (ts, qs) in series.items()}
        fig = Figure(figsize=(7, 3))
        draw(fig.add_subplot(), trimmed, self.topic)
        fig.tight_layout()
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=80)
        return buf.getvalue()

    def _refresh(self) -> None:
        while not self._stop.wait(0.5):
            self.image.value = self.render()

    def close(self) -> None:
        self._stop.set()
        self._thread.join(2.0)
        self.spin.stop()
        self.node.destroy_node()


def start_stop_buttons(run: BackgroundApp):
    """Start and Stop buttons for a background run, with a status label."""
    import ipywidgets as w

    start, stop = w.Button(description="Start", button_style="success"), w.Button(description="Stop")
    label = w.Label(value="running" if run.running else "stopped")

    def on_start(_):
        run.start()
        label.value = "running"

    def on_stop(_):
        run.stop()
        label.value = "stopped"

    start.on_click(on_start)
    stop.on_click(on_stop)
    return w.HBox([start, stop, label])


def graph_picture(ready: Callable[["object"], bool] = lambda graph: True, timeout: float = 20.0,
                  node_name: str = "rtt_notebook_graph"):
    """The ROS graph as seen from a new node: ``(Graph, PNG bytes)``.

    Args:
        ready: ``ready(graph)`` says whether everything expected has been
            discovered (that can take a few seconds); the graph is re-read until then.
        timeout: the longest wait, s; the graph is read then, complete or not.
    """
    import rclpy

    from tutorial.graph_node import draw_graph, read_graph

    init_ros()
    node = rclpy.create_node(node_name)
    try:
        deadline = time.monotonic() + timeout
        graph = read_graph(node)
        while not ready(graph) and time.monotonic() < deadline:
            rclpy.spin_once(node, timeout_sec=0.1)
            graph = read_graph(node)
    finally:
        node.destroy_node()
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "graph.png"
        draw_graph(graph, str(path))
        return graph, path.read_bytes()


def wait_until(predicate: Callable[[], bool], timeout: float, poll: float = 0.05) -> bool:
    """Poll ``predicate`` until it is true or ``timeout`` s pass; its last value."""
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() >= deadline:
            return bool(predicate())
        time.sleep(poll)
    return True
