"""The Choreonoid analog: what a project is and how it runs.

=================  ==============================================================
module             job
=================  ==============================================================
``controller``     the simple-controller lifecycle (``configure`` ... ``unconfigure``)
``body``           a body's links, numbered joints and actuators over an ``MjData``
``world``          one MuJoCo model from a project's model files
``project``        project files (``project/*.yaml``), the ``.cnoid`` analog
``simulator``      the simulation thread: steps, controllers, real-time pacing
``app``            a running project: world, controllers, simulation, view
``call_later``     hand work to the owner (main) thread, as Choreonoid's ``callLater``
``trajectory``     ``TrajectoryLog``: ``qpos`` at a fixed frame rate, for plots and replays
=================  ==============================================================

Nothing here imports a step module (:mod:`tutorial.controllers`): a project
file names the controllers, and :mod:`tutorial.core.project` loads them by name.
"""
