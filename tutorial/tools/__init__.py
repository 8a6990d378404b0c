"""The ``rtt-*`` programs: one thin ``main`` per program, built from the library.

==================  ================================================================
module              program
==================  ================================================================
``rtt_run``         ``rtt-run PROJECT``: open a project and run it, as Choreonoid does
``rtt_joy``         ``rtt-joy``: publish ``/joy`` from a gamepad, the keyboard or a demo
``rtt_plot``        ``rtt-plot``: joint positions over time (rqt_plot's stand-in)
``rtt_graph``       ``rtt-graph``: nodes and topics (rqt_graph's stand-in)
``rtt_image``       ``rtt-image``: a camera topic's pictures (rqt_image_view's stand-in)
``rtt_bag``         ``rtt-bag``: record, list, replay and recover MCAP bags (``ros2 bag``'s stand-in)
``rtt_urdf``        ``rtt-urdf``: a MuJoCo model as a URDF
``rtt_foxglove``    ``rtt-foxglove``: every topic, and TF, to Foxglove over its WebSocket
``rtt_ros2``        ``rtt-ros2``: the ``ros2`` commands of ROS 2's beginner tutorials
==================  ================================================================

Nothing in the library imports these modules (``make lint``'s import contracts).
"""
