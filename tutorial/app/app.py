"""Run a project: build the world, attach controllers, simulate and show it.

This is what Choreonoid does when it opens a ``.cnoid`` project, and what
``rtt-run`` and the notebooks use.  Threads:

* **main thread** (the one that creates the :class:`App`): owns the project's
  bodies (over ``App.data``), the meshcat scene and the :class:`MainLoop`;
  runs ``configure``/``unconfigure`` and every ``call_later`` call.
* **spin thread** (:class:`tutorial.ros.spin.SpinThread`): runs the node's
  subscription callbacks.
* **simulation thread** (:class:`tutorial.core.simulator.Simulator`, only when the
  project has a simulator): owns the simulation's ``MjData``; the main thread
  copies a snapshot of it once per frame to draw.

It does one job, a project's run, over 400 lines because it wires those three
threads together in one place (and says, for each method, which may call it).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable

import mujoco

from tutorial.app.frame_clock import FRAME_RATE, FramePacer
from tutorial.app.summary import app_summary
from tutorial.core.body import Body
from tutorial.core.controller import ControllerConfig
from tutorial.core.hand_over import HandOverLoop
from tutorial.core.overlays import Overlays
from tutorial.core.project import Project, check_parameter
from tutorial.core.simulator import Attachment, Simulator
from tutorial.core.world import build_world
from tutorial.view.meshcat_overlays import MeshcatOverlays

DEFAULT_NODE_NAME = "rtt"
GRAPH_CHECK_PERIOD = 2.0  # s, how often the node graph is checked for a twin name


class ControllerError(RuntimeError):
    """A controller refused a lifecycle step or raised."""


class App:
    """One running project.

    Args:
        project: the loaded project.
        node: the ``rclpy`` node to use (its callbacks must be spun by the
            caller), or None to create ``node_name`` and spin it here.
        node_name: name of the node created when ``node`` is None.
        headless: no scene, no view.
        realtime_sync: override the project's ``simulator.realtime_sync``.
        duration: stop after this many seconds: simulated time when the
            project simulates, wall-clock time otherwise (None: until stopped).
        output: called with one dict per status line or event (main thread).
        vis: the ``meshcat.Visualizer`` to draw in (a notebook's widget);
            the owner thread must own it.  Without it, only a subclass that
            opens a view of its own (:meth:`open_visualizer`) draws.
        attach: extra ``(body name, controller name, controller instance)``
            to attach in code, before the project's own (as adding a
            controller item in Choreonoid's GUI).
        record_timing: keep each step's lateness in ``sim.lateness`` (benchmarks).

    Two things are a program's, not the lessons': a model that names a robot
    description topic instead of a file, or an odometry topic, and a meshcat
    server of its own for the view.  :class:`tutorial.tools.standalone.app.StandaloneApp`
    (what ``rtt-run`` runs) does both; this class refuses such a model, and
    draws only in a view it is given (``vis``) unless ``headless``.

    Create, :meth:`open`, :meth:`run` and :meth:`close` on the same thread: it
    becomes the owner of everything the main thread owns.
    """

    def __init__(
        self,
        project: Project,
        node=None,
        node_name: str = DEFAULT_NODE_NAME,
        headless: bool = False,
        realtime_sync: bool | None = None,
        duration: float | None = None,
        output: Callable[[dict], None] | None = None,
        vis=None,
        attach=(),
        record_timing: bool = False,
    ):
        self.project = project
        self.node = node
        self.node_name = node_name
        self.headless = headless
        self.realtime_sync = realtime_sync
        self.duration = duration
        self.output = output or (lambda record: print(record, flush=True))
        self.vis = vis
        self.attach = list(attach)
        self.record_timing = record_timing
        self.loop = HandOverLoop()  # call_later's loop, and its spin thread steps aside for it
        self.log = logging.getLogger("rtt")
        self.server = None  # a meshcat server a subclass started for its view (StandaloneApp): closed with the App
        self.scene = None
        self.camera = None  # (position, target) of the view's camera, m, once the view is open
        self.overlays = Overlays()  # what controllers draw over the view (main thread)
        self.overlay_view = None
        self.sim: Simulator | None = None
        self.spin = None
        self._own_node = node is None
        self.controllers: list[tuple[str, object, str]] = []  # (name, controller, body name), configured
        self._unconfigured = False
        self.warned_duplicate = False
        self.started_at = None
        self.frames = FramePacer()  # when the view draws (owner thread)
        self._drawn_step = -1
        self.stop_requested = False
        self._refusing = False  # our parameter callback is on the node (open), to be taken off a lent node (close)

    # ---- lifecycle (owner thread) -------------------------------------------------
    def open(self) -> App:
        """Build the world, configure the controllers, start simulation and view.

        Raises:
            ValueError: a model does not load, or names a robot description
                or odometry topic (:meth:`prepare_project`).
            ControllerError: a controller refused to configure or to start.
        """
        settings = self.project.simulator
        kwargs = {} if settings is None else {"time_step": settings.time_step, "gravity": settings.gravity}
        if self.node is None:
            from rclpy.node import Node

            self.node = Node(self.node_name)
        self.project = self.prepare_project(self.project)
        self.model = build_world(self.project.models, **kwargs)
        self.data = mujoco.MjData(self.model)
        mujoco.mj_forward(self.model, self.data)
        # a robot drawn from its description: its mimic joints follow their leaders (Body's mimic)
        self.bodies = {
            m.name: Body(self.model, self.data, m.name, mimic=m.description is not None) for m in self.project.models
        }
        if self._own_node:
            from tutorial.ros.spin import SpinThread

            self.spin = SpinThread(self.node, hand_over_to=self.loop)
        for body_name, name, controller in self.attach:
            self._configure_instance(body_name, name, controller, {})
        for entry in self.project.models:
            for c in entry.controllers:
                self._configure_instance(entry.name, c.name, c.cls(), self._ros_parameters(c))
        self.node_fqn = self.node.get_fully_qualified_name()
        # registered before the spin thread starts, which runs it (a parameter service's callback)
        self.node.add_on_set_parameters_callback(self._refuse_controller_parameters)
        self._refusing = True
        if self.spin is not None:
            self.spin.start()
        self.loop.call_every(GRAPH_CHECK_PERIOD, self.check_node_name)
        if not self.headless:
            self._open_view()
        if settings is not None:
            realtime = settings.realtime_sync if self.realtime_sync is None else self.realtime_sync
            sim_data = mujoco.MjData(self.model)
            mujoco.mj_forward(self.model, sim_data)
            attachments = [Attachment(n, c, b) for n, c, b in self.controllers]
            self.sim = Simulator(
                self.model,
                sim_data,
                attachments,
                node=self.node,
                realtime_sync=realtime,
                duration=self.duration,
                record_timing=self.record_timing,
            ).start()
        self.started_at = time.monotonic()
        return self

    def controller(self, name: str):
        """A configured controller by name (any thread, after :meth:`open` has configured it).

        Raises:
            KeyError: no controller of that name.
        """
        for n, c, _ in self.controllers:
            if n == name:
                return c
        raise KeyError(f"no controller named {name!r}")

    def prepare_project(self, project: Project) -> Project:
        """The project the world is built from: ``project`` itself (owner thread, in :meth:`open`).

        A subclass may fill models in, and add to ``self.attach``, here: the
        node exists, its spin thread has not started
        (:class:`tutorial.tools.standalone.app.StandaloneApp` takes models from robot descriptions).

        Raises:
            ValueError: a model takes a robot description or odometry from a topic.
        """
        for m in project.models:
            unreceived = m.description is not None and m.text is None
            if unreceived or m.odometry is not None:
                topic = m.description if unreceived else m.odometry
                raise ValueError(f"model {m.name} takes {topic} from ROS: rtt-run draws it (or StandaloneApp)")
        return project

    def open_visualizer(self):
        """The ``meshcat.Visualizer`` to draw in when none was given (owner thread, in :meth:`open`).

        :class:`tutorial.tools.standalone.app.StandaloneApp` starts a meshcat server of its own here.

        Raises:
            ValueError: always, here: give ``vis``, or open it ``headless``.
        """
        raise ValueError("no view to draw in: give the App a vis (a notebook's widget), or headless=True")

    def view_address(self) -> tuple[str, str | None]:
        """``(url, url through Jupyter or None)`` of the view, for the ``meshcat`` record (owner thread)."""
        return self.vis.url(), None

    def _configure_instance(self, body_name: str, name: str, controller, params: dict) -> None:
        config = ControllerConfig(
            name=name,
            body=self.bodies[body_name],
            node=self.node,
            parameters=params,
            call_later=self.loop.call_later,
            call_every=self.loop.call_every,
            output=self.output,
            log=logging.getLogger(f"rtt.{name}"),
            overlays=self.overlays,
        )
        try:
            ok = controller.configure(config)
        except Exception as exc:
            raise ControllerError(f"controller {name} failed to configure: {exc!r}") from exc
        if not ok:
            raise ControllerError(f"controller {name} refused to configure")
        self.controllers.append((name, controller, body_name))

    def _ros_parameters(self, entry) -> dict:
        """Declare the controller's parameters on the node: ``<controller>.<parameter>``.

        The project's value is the default; ``--ros-args -p RttJointStatePublisher.rate:=100``
        overrides it.  A wrong type is a ControllerError naming the parameter.
        """
        from rcl_interfaces.msg import ParameterDescriptor

        values = dict(entry.parameters)
        for name, (typ, _default, description) in entry.cls.PARAMETERS.items():
            full = f"{entry.name}.{name}"
            if not self.node.has_parameter(full):
                self.node.declare_parameter(
                    full, values[name], ParameterDescriptor(description=description), ignore_override=False
                )
            value = self.node.get_parameter(full).value

            def fail(msg, full=full):
                return ControllerError(f"parameter {full}: {msg}")

            values[name] = check_parameter(typ, value, fail)
        return values

    def _refuse_controller_parameters(self, parameters):
        """A controller's parameter set while it runs (``rtt-ros2 param set``): refused, saying when it is read.

        The controllers read their parameters when they are configured, so a
        later value would be accepted and change nothing.  Any other
        parameter (``use_sim_time``) is left to rclpy.  The spin thread runs it.
        """
        from rcl_interfaces.msg import SetParametersResult

        ours = {f"{c.name}.{n}" for m in self.project.models for c in m.controllers for n in c.cls.PARAMETERS}
        read = [p for p in parameters if p.name in ours]
        if not read:
            return SetParametersResult(successful=True)
        import shlex

        example = shlex.quote(f"{read[0].name}:={read[0].value}")
        return SetParametersResult(
            successful=False,
            reason=f"{', '.join(p.name for p in read)}: read when the controller is configured, not while it "
            f"runs: start the program again with --ros-args -p {example}",
        )

    def _open_view(self) -> None:
        from tutorial.view.scene import Scene, look_at_geoms

        if self.vis is None:
            self.vis = self.open_visualizer()
        # A robot drawn from its description, with no world around it: meshcat's grid is its ground, and the
        # camera frames the robot whatever its size (the tank's close-up assumes the tank's).
        described = self.project.simulator is None and any(m.description for m in self.project.models)
        self.scene = Scene(self.vis, self.model, sink=self.frame_sink())  # the fastest way its view takes
        self.scene.build(self.data, grid=described)
        self.overlay_view = MeshcatOverlays(self.vis, self.overlays)
        robot = self.bodies[self.project.models[-1].name]
        root = robot.root_pose()[0]
        framed = look_at_geoms(self.model, self.data, robot.geom_ids) if described else None
        if self.project.simulator is not None:
            self.camera = (root + [-1.4, -2.2, 1.6], root + [1.0, 0.2, 0.0])  # the robot in its room
        elif framed is not None:
            self.camera = framed
        else:
            self.camera = (root + [-1.1, -1.2, 0.8], root)  # the robot, close up
        self.scene.set_camera(*self.camera)  # (position, target), m: a notebook's recording reuses it
        url, via = self.view_address()
        self.output({"event": "meshcat", "node": self.node_fqn, "url": url, "through_jupyter": via})

    def frame_sink(self):
        """Where the scene sends each frame's transforms (owner thread, in :meth:`open`): a notebook's widget
        window takes a frame as one message (:class:`tutorial.view.widget.widget.WidgetWindow`); any other
        window gets meshcat's own way, one ``set_transform`` a body (:class:`tutorial.view.scene.VisualizerSink`)."""
        from tutorial.view.scene import VisualizerSink

        window = self.vis.window
        return window if getattr(window, "send_transforms", None) is not None else VisualizerSink(self.vis)

    def step(self, timeout: float = 1.0 / FRAME_RATE) -> bool:
        """Run posted calls, and draw a frame when there is something new to show (owner thread).

        Waits for posted calls at most ``timeout`` s, and never past the time
        the next frame is due (:meth:`next_frame_due`, :mod:`tutorial.app.frame_clock`).

        Returns:
            False when the app is done (duration reached, simulation ended or stop requested).
        """
        self.loop.run_once(max(0.0, min(timeout, self.next_frame_due() - time.monotonic())))
        now = time.monotonic()
        self.frames.note(now, self.changes())
        if now >= self.next_frame_due():
            self.frames.drawn(now, self._burst_members())
            self._draw()
        return not self.done()

    def next_frame_due(self) -> float:
        """The ``time.monotonic()`` at which the next frame is due, ``inf`` if none (owner thread)."""
        simulating = self.sim is not None and not self.sim.finished.is_set()
        return self.frames.next_frame_due(simulating, self._burst_members())

    def burst_complete(self) -> bool:
        """Whether every body and arrow that ever changed has changed since the last frame (owner thread)."""
        return self.frames.burst_complete(self._burst_members())

    def _burst_members(self):
        """((kind, name), change count) of every body and overlay arrow (owner thread)."""
        for name, b in self.bodies.items():
            yield ("body", name), b.kinematic_state_changes
        for name, a in self.overlays.arrows.items():
            yield ("arrow", name), a.version

    def changes(self) -> int:
        """Counts what changed the view (owner thread): bodies' kinematic-state changes and arrows.

        A controller that moves a body calls ``body.notify_kinematic_state_change()``,
        as in Choreonoid, and that is what makes the view redraw.
        """
        return sum(count for _, count in self._burst_members())

    def _sync_from_simulation(self) -> None:
        """Copy the simulation's newest snapshot into the main thread's data (owner thread)."""
        if self.sim is not None:
            snap = self.sim.snapshot()
            if snap.step != self._drawn_step:
                self._drawn_step = snap.step
                self.data.qpos[:] = snap.qpos
                self.data.time = snap.time
                mujoco.mj_kinematics(self.model, self.data)

    def _draw(self) -> None:
        self._sync_from_simulation()
        if self.scene is not None:
            self.scene.update(self.data)
            self.overlay_view.update()

    def request_stop(self) -> None:
        """Ask the app to finish its current step and end (any thread, or a signal handler)."""
        self.stop_requested = True
        self.loop.wake()

    def done(self) -> bool:
        if self.stop_requested:
            return True
        if self.spin is not None and self.spin.error is not None:
            return True  # a subscription callback raised and spinning ended: summary() reports it
        if self.sim is not None:
            return self.sim.finished.is_set()
        return self.duration is not None and time.monotonic() - self.started_at >= self.duration

    def run(self) -> None:
        """Step until done (owner thread); Ctrl-C propagates as KeyboardInterrupt."""
        while self.step():
            pass
        self._draw()  # show the final state

    def close(self) -> None:
        """Stop the simulation, unconfigure the controllers, stop ROS and meshcat (owner thread)."""
        if self.sim is not None:
            self.sim.request_stop()
            self.sim.join(5.0)
            self._sync_from_simulation()  # the bodies end in the simulation's final state
        if self.spin is not None:
            self.spin.stop()
        # Work handed over before the spin thread stopped still runs, so the
        # last state received is the last state shown.
        self.loop.process_pending()
        if not self._unconfigured:
            self._unconfigured = True
            for name, controller, _ in reversed(self.controllers):
                try:
                    controller.unconfigure()
                except Exception as exc:  # noqa: BLE001 - close the rest anyway
                    self.log.error("controller %s failed to unconfigure: %r", name, exc)
        if self._own_node and self.node is not None:
            self.node.destroy_node()
        elif self._refusing:  # a node lent to us goes on: it stops asking this App about its parameters
            self.node.remove_on_set_parameters_callback(self._refuse_controller_parameters)
        self._refusing = False
        if self.scene is not None:
            self.scene.close()
        if self.server is not None:
            self.server.close()

    # ---- monitoring ---------------------------------------------------------------
    def check_node_name(self) -> None:
        """Warn when another node on the graph has this node's name (main thread).

        ROS 2 lets two nodes share a name, but tools cannot tell them apart and
        their parameters collide: rename one with ``--ros-args -r __node:=NAME``.
        """
        me = (self.node.get_name(), self.node.get_namespace())
        count = sum(1 for n in self.node.get_node_names_and_namespaces() if n == me)
        if count > 1 and not self.warned_duplicate:
            self.warned_duplicate = True
            self.output(
                {
                    "event": "warning",
                    "node": self.node_fqn,
                    "message": f"{count} nodes are named {self.node_fqn}; "
                    "rename this one with --ros-args -r __node:=NAME",
                }
            )
        elif count <= 1:
            self.warned_duplicate = False

    def summary(self) -> dict:
        """Exit summary: times, root poses and joint positions (owner thread, after run).

        See :func:`tutorial.app.summary.app_summary`.
        """
        return app_summary(self)
