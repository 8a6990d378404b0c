"""The Choreonoid analog: what a project is and how it runs.

=================  ==============================================================
module             job
=================  ==============================================================
``controller``     the simple-controller lifecycle (``configure`` ... ``unconfigure``)
``body``           a body's links, numbered joints and actuators over an ``MjData``
``world``          one MuJoCo model from a project's model files
``project``        project files (``project/*.yaml``), the ``.cnoid`` analog
``simulator``      the simulation thread: steps, controllers, real-time pacing
``call_later``     hand work to the owner thread, as Choreonoid's ``callLater``
``hand_over``      a faster hand-over: the posting thread steps aside for the owner
``period``         when the next periodic output (joint state, IMU mean, picture) is due
``overlays``       shapes a controller asks to have drawn over the 3D view (arrows)
``trajectory``     ``TrajectoryLog``: ``qpos`` at a fixed frame rate, for plots and replays
=================  ==============================================================

A running project (world, controllers, simulation, view) is :mod:`tutorial.app`, one layer up.

Nothing here imports a step module (:mod:`tutorial.controllers`): a project
file names the controllers, and :mod:`tutorial.core.project` loads them by name.
"""
