"""What ``rtt-run`` adds to the lessons' App, none of which a notebook needs.

==================  ================================================================
module              job
==================  ================================================================
``app``             :class:`StandaloneApp`: the lessons' App with the rest below
``meshcat_server``  a meshcat server on 127.0.0.1 that ends with its process
``sinks``           where a frame's transforms go: the fast ways, and which a view gets
``descriptions``    a model taken from a robot description topic
``floating_base``   a viewer's floating base: the root link placed where odometry says
==================  ================================================================
"""
