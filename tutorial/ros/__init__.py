"""ROS 2 plumbing: the process's environment, the launcher, shared memory, the graph.

==================  ================================================================
module              job
==================  ================================================================
``env``             localhost-only discovery by default, init, the spin thread
``launch``          ``launch_py/``'s launcher: one process per node, a clean stop
``shm``             Fast DDS's shared-memory files, and removing what killed nodes left
``graph``           which nodes publish and subscribe which topics, and a picture of it
==================  ================================================================
"""
