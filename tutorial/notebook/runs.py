"""Running projects from a notebook: deterministic runs, and live runs that keep the kernel free.

:func:`run_project` runs a project to its end on the kernel thread, with
the demo script fed by *simulated* time: the same numbers every run.

:class:`BackgroundApp` runs a project the way ``rtt-run`` does, over real
ROS 2, on an owner thread of its own (the role the main thread plays in
``rtt-run``), so the kernel stays free for the next cells and the widgets.
Its 3D view (:class:`tutorial.notebook.views.LiveView`) and its Start/Stop
panel (:meth:`BackgroundApp.controls`) always say what the run is doing.

A notebook builds a controller class in its cells and adds it to a project
the way a controller item is added in Choreonoid::

    project = load("tank_world.yaml").with_controller("Tank", "RttTankController", RttTankController)
    sim = BackgroundApp(project, node_name="rtt").start()
"""

from __future__ import annotations

import threading
from pathlib import Path

from tutorial.core.project import Project, load_project
from tutorial.notebook import session


def load(project: str | Path | Project) -> Project:
    """A project: a file name in ``project/``, a path, or an already loaded :class:`Project`.

    Raises:
        tutorial.core.project.ProjectError: the file is missing or wrong (the message names it).
    """
    if isinstance(project, Project):
        return project
    path = Path(project)
    return load_project(path if path.exists() else session.PROJECT / path)


def _headless_app(project, duration: float, node_name: str, realtime: bool, output, attach, node=None):
    """An unopened headless :class:`tutorial.app.app.App` on a node that is never spun, and that node.

    Nothing spins the node, so no subscription callback ever runs: no message
    from the network (a teleop panel, an ``rtt-joy`` in a terminal) can
    change the run.  Publishing still works.
    """
    import rclpy

    from tutorial.app.app import App

    session.init_ros()
    node = node if node is not None else rclpy.create_node(node_name)
    app = App(
        load(project),
        node=node,
        headless=True,
        realtime_sync=realtime,
        duration=duration,
        output=output or (lambda record: None),
        attach=attach,
    )
    return app, node


def _run_to_end(app, node) -> dict:
    """Open, run and close ``app`` on this thread; its summary."""
    try:
        app.open()
        app.run()
    finally:
        app.close()
        node.destroy_node()
    return app.summary()


def run_headless(
    project, duration: float, attach=(), output=None, node_name: str = "rtt_headless", realtime: bool = False, node=None
):
    """Run a project to its end on this thread, headless, deaf to the network: deterministic.

    Args:
        project: a project (see :func:`load`).
        duration: simulated seconds.
        attach: extra ``(body name, controller name, controller instance)`` to
            attach first (as :class:`tutorial.app.app.App` takes them).
        output: called with each status record (default: dropped).
        node_name: the run's node name.
        realtime: keep simulated time with wall time (False: as fast as possible).
        node: a node to use instead of a new one (it is destroyed at the end).

    Returns:
        ``(summary, app)``: the exit summary and the closed app (its bodies
        hold the final state).

    Raises:
        tutorial.app.app.ControllerError: a controller refused to configure.

    Its node is never spun (no subscription callback runs), so the same
    arguments give the same numbers on every run.
    """
    app, node = _headless_app(project, duration, node_name, realtime, output, attach, node)
    return _run_to_end(app, node), app


def run_project(
    project,
    duration: float,
    node_name: str = "rtt_scripted",
    scripted: bool = True,
    fps: float = 30.0,
    realtime: bool = False,
    script: str = "drive",
):
    """Run a project to its end on this thread with the demo script: the same numbers every run.

    Args:
        project: a project (see :func:`load`).
        duration: simulated seconds.
        node_name: the run's node name (not ``rtt``: a live run may be using that one).
        scripted: feed the demo script (:mod:`tutorial.joystick.scripted`) to the
            project's ``RttTankController`` by simulated time, repeated at 20 Hz.
        fps: frame rate of the recorded states.
        realtime: keep simulated time with wall time (False: as fast as possible).
        script: which demo script, a key of :data:`tutorial.joystick.demo.SCRIPTS`
            (``"drive"``, or ``"wall"``: Step 5's wall ramming).

    Returns:
        ``(summary, app, trajectory)``: the exit summary, the closed app (its
        bodies hold the final state) and the :class:`tutorial.core.trajectory.TrajectoryLog`.

    Deaf to the network, as :func:`run_headless`; what it publishes still goes out.
    """
    from tutorial.core.trajectory import TrajectoryLog
    from tutorial.joystick.demo import SCRIPTS
    from tutorial.joystick.scripted import ScriptedJoy

    proj = load(project)
    body = next(m.name for m in proj.models if m.controllers)
    trajectory = TrajectoryLog(fps)
    attach = [(body, "Trajectory", trajectory)]
    if scripted:
        # The tank controller exists once the app has configured it: look it up then.
        joystick = ScriptedJoy(lambda: app.controller("RttTankController"), script=SCRIPTS[script])
        attach.insert(0, (body, "ScriptedJoy", joystick))
    app, node = _headless_app(proj, duration, node_name, realtime, None, attach)
    return _run_to_end(app, node), app, trajectory


class BackgroundApp:
    """A project run over real ROS 2 on its own owner thread, with a live 3D view.

    Args:
        project: a project (see :func:`load`).
        node_name: the run's node name (two runs need two names).
        headless: no 3D view.
        duration: stop after this many seconds (simulated, or wall time without a simulator).
        label: what the view's caption calls this run (default: the node name).

    The owner thread creates, opens, runs and closes the :class:`tutorial.app.app.App`;
    it owns everything the app's main thread owns.  Every method may be called
    from any thread.  :meth:`close` (what ``reset()`` calls) stops the run and
    turns its view into a recording.

    Raises:
        tutorial.core.project.ProjectError: the project cannot be loaded.
    """

    def __init__(
        self, project, node_name: str, headless: bool = False, duration: float | None = None, label: str | None = None
    ):
        from tutorial.notebook.views import LiveView

        self.project = load(project)
        self.node_name = node_name
        self.headless = headless
        self.duration = duration
        self._records: list[dict] = []
        self._lock = threading.Lock()  # guards _records: the owner thread appends, any thread reads
        self._stop = threading.Event()
        self._opened = threading.Event()
        self.thread: threading.Thread | None = None
        self.app = None
        self.summary: dict | None = None
        self.error: BaseException | None = None
        self.status = "not started"
        self.closed = False
        self._panels: list = []
        self.view = None if headless else LiveView(label or f"/{node_name}")
        session.register(self)

    # ---- status ---------------------------------------------------------------------
    def _set_status(self, status: str) -> None:
        self.status = status
        if self.view is not None:
            self.view.set_status(status)
        for panel in self._panels:
            panel.refresh()

    def _output(self, record: dict) -> None:
        with self._lock:
            self._records.append(record)

    def records(self, event: str | None = None) -> list[dict]:
        """Status records so far (all, or those of one ``event``), oldest first."""
        with self._lock:
            return [r for r in self._records if event is None or r.get("event") == event]

    # ---- the owner thread ---------------------------------------------------------------
    def _run(self) -> None:
        from tutorial.app.app import App

        app = None
        try:
            vis = self.view.visualizer() if self.view is not None else None
            app = App(
                self.project,
                node_name=self.node_name,
                headless=self.headless,
                vis=vis,
                duration=self.duration,
                output=self._output,
            )
            self.app = app
            app.open()
            self._opened.set()
            if self.view is not None:
                self.view.begin(app.model, app.camera, app.overlays)
            self._set_status("running")
            while not self._stop.is_set() and app.step():
                if self.view is not None:
                    self.view.record(app.data)
                    paused_or_not = self.view.pause_while_unwatched(app.sim)  # a run nobody watches costs nothing
                    if paused_or_not:
                        self._set_status(paused_or_not)
        except BaseException as exc:  # noqa: BLE001 - reported through .error and the status
            self.error = exc
        finally:
            if app is not None:
                try:
                    app.close()
                    self.summary = app.summary()
                except BaseException as exc:  # noqa: BLE001
                    self.error = self.error or exc
            self._opened.set()
            self._set_status(self._ended_status())

    def _ended_status(self) -> str:
        if self.error is not None:
            return f"failed: {type(self.error).__name__}: {self.error}"
        summary = self.summary or {}
        if summary.get("error"):
            return "failed: " + summary["error"].strip().splitlines()[-1]
        sim_time = summary.get("simulated_time")
        at = f" at t = {sim_time:.2f} s" if sim_time is not None else ""
        if self._stop.is_set():
            return f"stopped{at}: press Start to run it again"
        return f"finished{at} (its duration was reached): press Start to run it again"

    # ---- any thread ---------------------------------------------------------------------
    def start(self) -> BackgroundApp:
        """Start the run (nothing happens if it is running).

        Raises:
            RuntimeError: the run was closed by ``reset()``: create a new one.
        """
        if self.closed:
            raise RuntimeError(f"/{self.node_name} was closed by reset(): run its cell again to create a new run")
        session.init_ros()
        if self.thread is None or not self.thread.is_alive():
            self._stop.clear()
            self._opened.clear()
            self.error = None
            self._set_status("starting")
            self.thread = threading.Thread(target=self._run, name=f"app-{self.node_name}", daemon=True)
            self.thread.start()
        return self

    @property
    def running(self) -> bool:
        return self.thread is not None and self.thread.is_alive()

    def wait_started(self, timeout: float = 30.0) -> bool:
        """Wait until the run has opened (or failed to); True when it runs."""
        return self._opened.wait(timeout) and self.error is None and self.running

    def sim_time(self) -> float:
        """Simulated time of the run now, s (0 before it starts or without a simulator)."""
        app = self.app
        return app.sim.sim_time if app is not None and app.sim is not None else 0.0

    def root_position(self, body: str) -> list[float]:
        """Where ``body``'s root is now, (3,) m, from the simulation's newest snapshot (any thread).

        The simulation thread alone owns its ``MjData``; the snapshot is a copy
        it makes under a lock, so reading it here is safe.

        Raises:
            RuntimeError: the run has not started, or has no simulator.
            ValueError: the body's root has no free joint (it is fixed in the world).
        """
        app = self.app
        if app is None or app.sim is None:
            raise RuntimeError(f"/{self.node_name} is not simulating")
        adr = app.bodies[body].root_qpos_address
        if adr is None:
            raise ValueError(f"{body}'s root has no free joint: it does not move in the world")
        return [float(v) for v in app.sim.snapshot().qpos[adr : adr + 3]]

    def controller(self, name: str):
        """A configured controller of the running app, by name.

        Raises:
            RuntimeError: the run has not opened.
            KeyError: no controller of that name.
        """
        if self.app is None or not self._opened.is_set():
            raise RuntimeError(f"/{self.node_name} has not started")
        return self.app.controller(name)

    def on_owner_thread(self, func, timeout: float = 10.0):
        """Run ``func(app)`` on the run's owner thread and return its result (any thread).

        The owner thread alone may touch the app's model and its controllers'
        main-thread state; this hands ``func`` to it with ``call_later``, as a
        subscription callback hands over a message, and waits for the answer.

        Raises:
            RuntimeError: the run is not running.
            TimeoutError: no answer within ``timeout`` s.
            Exception: whatever ``func`` raised.
        """
        import concurrent.futures

        app = self.app
        if app is None or not self.running:
            raise RuntimeError(f"/{self.node_name} is not running")
        answer: concurrent.futures.Future = concurrent.futures.Future()

        def call() -> None:
            try:
                answer.set_result(func(app))
            except BaseException as exc:  # noqa: BLE001 - handed back to the caller
                answer.set_exception(exc)

        app.loop.call_later(call, key=answer)  # a key of its own: never coalesced with another question
        try:
            return answer.result(timeout)
        except concurrent.futures.TimeoutError:
            raise TimeoutError(f"/{self.node_name} did not answer within {timeout} s") from None

    def show(self, height: int | None = None) -> None:
        """Display this run's 3D view in the cell's output (kernel thread)."""
        from tutorial.notebook import views

        if self.view is None:
            raise RuntimeError(f"/{self.node_name} is headless: it has no view")
        views.show(self.view, height=height)

    def controls(self):
        """A Start/Stop panel for this run, with a line saying what it is doing (kernel thread)."""
        from tutorial.notebook.panels import RunControls

        panel = RunControls(self)
        # Listed first, then drawn: a status the owner thread sets from here on reaches the panel, and
        # one it set before is what refresh() reads (the panel's lock orders the two writes).
        self._panels.append(panel)
        panel.refresh()
        return panel

    def stop(self, timeout: float = 10.0) -> dict | None:
        """Stop the run and wait for its summary (None if it did not end in ``timeout`` s)."""
        self._stop.set()  # also covers a stop asked for before the thread has built its App
        if self.app is not None:
            self.app.request_stop()
        if self.thread is not None:
            self.thread.join(timeout)
        return self.summary

    def wait(self, timeout: float) -> dict | None:
        """Wait for a run with a duration to end by itself; its summary (None if still running)."""
        if self.thread is not None:
            self.thread.join(timeout)
        return None if self.running else self.summary

    def close(self) -> None:
        """Stop the run, turn its view into a recording, disable its panels (kernel thread)."""
        if self.closed:
            return
        self.stop()
        self.closed = True
        self._set_status("closed by reset(): run the section again for a new run")
        for panel in self._panels:
            panel.close()
        if self.view is not None:
            self.view.close()
        session.forget(self)
