"""Helpers for the notebooks, one module per job; a notebook imports each from its home.

=================  ==============================================================
module             what it gives a notebook
=================  ==============================================================
``session``        ``init_ros``, ``reset``, ``TEST_MODE``, ``wait_until``, paths
``runs``           ``run_project`` (deterministic), ``BackgroundApp`` (live, over ROS 2), ``load``
``views``          ``LiveView`` (a run's 3D view: live, then its recording), ``show``
``drawing``        ``MeshcatPage``: a meshcat page to draw in by hand (notebook 00)
``replay``         self-contained meshcat pages of recorded runs (no server)
``panels``         widget panels that say what they are doing, and a stand-in where widgets cannot run
``teleop``         ``TeleopPanel``: sliders and a gamepad publishing ``/joy``
``live_plot``      ``LivePlot``: joint positions from ``/<body>/joint_state``
``live_image``     ``LiveImage``: the newest picture of a camera topic
``live``           ``LiveOutput``: what the two share, an image output redrawn in place
``graph_picture``  ``graph_picture``: the ROS 2 graph as a picture
``source``         ``show_source``: a piece of the library's source, with its file
``two_hosts``      ``TwoHosts``: notebook 08's robot and operator as two hosts
=================  ==============================================================

The exercises' checks live in :mod:`tutorial.exercises`.
"""
