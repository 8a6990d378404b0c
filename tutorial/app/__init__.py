"""A running project: the App that builds the world, attaches the controllers, simulates and draws.

It sits above the core, the ROS plumbing, the 3D view and the URDF tools
(which only ``standalone`` and ``descriptions`` reach), and below the steps'
notebooks and the programs, which open it.

==================  ==============================================================
module              what
==================  ==============================================================
``app``             :class:`App`: the lifecycle of a running project (Choreonoid's
                    opening of a ``.cnoid`` project), its threads and its stop
``frame_clock``     :class:`FramePacer`: when the view draws a frame
``standalone``      :class:`StandaloneApp`, what ``rtt-run`` runs: a meshcat server of
                    its own, and the two below (the lessons' :class:`App` does neither)
``descriptions``    a model taken from a robot description topic
``floating_base``   a viewer's floating base: the root link placed where odometry says
``summary``         the exit summary a run prints or returns
``reference``       the earlier steps' worked solutions, frozen, that later steps stand on
==================  ==============================================================
"""
