"""The tooling around the lessons' library: the ``rtt-*`` programs and what only they, or notebooks 07 to 09, use.

The lessons' library (``core``, ``interfaces``, ``ros``, ``view``, ``app``,
``joystick``, ``notebook``, ``controllers``, ``exercises``) never imports this package
(``make lint``'s import contract ``tooling``).  Three of the later notebooks
teach a tool here: 07 recording (``bag``), 08 the network lab (``network``),
09 the URDF (``urdf``); their modules are the contract's stated exceptions.

==================  ================================================================
module              job
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
``standalone/``     what ``rtt-run`` adds to the lessons' App: its own meshcat server,
                    robots from a description topic, a base placed by odometry
``joystick/``       ``rtt-joy``'s gamepad and keyboard, and its ``/joy`` publisher
``image_files``     ``rtt-image``'s PNG files and status line
``bag/``            MCAP recording and replay (``rtt-bag``; notebook 07)
``urdf/``           a MuJoCo body as a URDF, and back (``rtt-urdf``; notebook 09)
``network/``        hosts of their own in network namespaces (notebook 08, the network tests)
``foxglove/``       the Foxglove WebSocket bridge (``rtt-foxglove``)
``grading/``        the course's grading: the release's stubs, the seal, the sandbox
==================  ================================================================
"""
