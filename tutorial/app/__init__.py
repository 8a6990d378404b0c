"""A running project: the App that builds the world, attaches the controllers, simulates and draws.

It sits above the core, the ROS plumbing and the 3D view, and below the
steps' notebooks and the programs, which open it (``rtt-run`` through
:mod:`tutorial.tools.standalone`).

==================  ==============================================================
module              what
==================  ==============================================================
``app``             :class:`App`: the lifecycle of a running project (Choreonoid's
                    opening of a ``.cnoid`` project), its threads and its stop
``frame_clock``     :class:`FramePacer`: when the view draws a frame
``summary``         the exit summary a run prints or returns
``reference``       the earlier steps' worked solutions, frozen, that later steps stand on
==================  ==============================================================
"""
