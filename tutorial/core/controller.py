"""The simple-controller lifecycle, after Choreonoid's ``SimpleController``.

A controller is attached to one body by a project file.  Its methods are
called in this order, each by the thread named here:

================  ===============  ===========================================
method            thread           when
================  ===============  ===========================================
``configure``     main             the controller is attached to its body,
                                   before any simulation (Step 3 does all
                                   its work from here: there is no simulation)
``initialize``    simulation       the simulation is about to start; the
                                   controller gets its :class:`ControllerIO`
``start``         simulation       just before the first step
``control``       simulation       every step (1 ms), before physics advances
``stop``          simulation       the simulation has ended
``unconfigure``   main             the controller is detached (program exit)
================  ===============  ===========================================

"Main" is Choreonoid's name for the thread that owns the project's model and
view (its GUI thread): a program's main thread, and in a notebook a run's
own owner thread (:class:`tutorial.notebook.runs.BackgroundApp`), so that the
kernel's thread stays free for the next cell.  This module, :mod:`tutorial.app`
and :mod:`tutorial.core.call_later` call it the main or the owner thread alike.

``configure``, ``initialize`` and ``start`` return False to refuse; the
runner then reports it and stops.  ``control`` returns False to drop out of
the simulation (the others go on).
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from tutorial.core.body import Body
from tutorial.core.overlays import Overlays


@dataclass
class ControllerConfig:
    """What a controller gets in ``configure`` (main thread).

    Attributes:
        name: the controller's name in the project (``RttTankController``).
        body: the body it is attached to, over the main thread's ``MjData``
            (Choreonoid's body item); only the main thread may use it.
        node: the process's ROS 2 node (``rclpy.node.Node``); its callbacks
            run on the spin thread.
        parameters: the controller's parameters, project values with ROS
            ``--ros-args -p`` overrides applied.
        call_later: post work to the main thread from any thread
            (see :mod:`tutorial.core.call_later`).
        call_every: ``call_every(period_s, func)`` runs ``func`` on the main
            thread periodically (main thread only).
        output: ``output(record: dict)`` prints a status line (text or JSON,
            as the program was asked); main thread only.
        log: a ``logging.Logger`` for the controller.
        overlays: arrows to draw over the App's 3D view (see
            :mod:`tutorial.view.meshcat_overlays`); main thread only.  Headless, they
            are numbers only.
    """

    name: str
    body: Body
    node: Any
    parameters: dict = field(default_factory=dict)
    call_later: Callable[..., None] = lambda func, *a, **k: func(*a, **k)
    call_every: Callable[[float, Callable[[], Any]], None] = lambda period, func: None
    output: Callable[[dict], None] = print
    log: logging.Logger = logging.getLogger("tutorial.core.controller")
    overlays: Overlays = field(default_factory=Overlays)

    @property
    def body_name(self) -> str:
        return self.body.name


@dataclass
class ControllerIO:
    """What a controller gets in ``initialize`` (simulation thread).

    Attributes:
        body: the simulated body, over the simulation's ``MjData``; only the
            simulation thread may use it (it owns that ``MjData``).
        time_step: the simulation step, s.
        node: the process's ROS 2 node.
        data: the simulation's ``MjData`` (read ``data.time`` for simulation time, s).
        log: a ``logging.Logger`` for the controller.
    """

    body: Body
    time_step: float
    node: Any
    data: Any
    log: logging.Logger = logging.getLogger("tutorial.core.controller")

    @property
    def current_time(self) -> float:
        """Simulation time, s."""
        return float(self.data.time)


class SimpleController:
    """Base class of the tutorial's controllers; override what you need.

    Class attribute ``PARAMETERS`` maps each parameter name to
    ``(type, default, description)``; the project file may set them and the
    runner declares them as ROS parameters ``<controller name>.<parameter>``.
    """

    PARAMETERS: dict[str, tuple[type, Any, str]] = {}

    def configure(self, config: ControllerConfig) -> bool:
        """Attached to a body, before any simulation (main thread). False refuses.

        Create subscriptions and publishers here; with no simulator, this is
        where the controller does its work (Step 3).
        """
        return True

    def initialize(self, io: ControllerIO) -> bool:
        """The simulation is about to start (simulation thread). False refuses.

        Take the joints and tracks from ``io.body``: they read and write the
        simulation's ``MjData``, which only this thread may touch.
        """
        return True

    def start(self) -> bool:
        """Just before the first step (simulation thread). False refuses."""
        return True

    def control(self) -> bool:
        """One simulation step, before physics advances (simulation thread, every ``time_step`` s).

        Read sensors and joints, write torques or track velocities. Return
        False to drop out of the simulation.
        """
        return True

    def stop(self) -> None:
        """The simulation has ended (simulation thread)."""

    def unconfigure(self) -> None:
        """Detached from the body, at program exit (main thread): undo ``configure``."""

    def summary(self) -> dict:
        """Figures for the program's exit summary (main thread, after ``stop``)."""
        return {}
