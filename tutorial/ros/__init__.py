"""ROS 2 plumbing: the process's environment, the launcher, shared memory, the graph.

==================  ================================================================
module              job
==================  ================================================================
``env``             localhost-only discovery and the Fast DDS profile by default, init
``spin``            the spin thread: where callbacks run, and why they hand work over
``program``         what every ``rtt-*`` program shares: ``--ros-args``, its stop
``launch``          ``launch_py/``'s launcher: one process per node, a clean stop
``shm``             Fast DDS's shared-memory files, and removing what killed nodes left
``graph``           which nodes publish and subscribe which topics, and a picture of it
``messages``        any message as ``ros2 topic echo``'s YAML, and its fields set from YAML
==================  ================================================================
"""
