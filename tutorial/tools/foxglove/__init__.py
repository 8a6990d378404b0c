"""Foxglove, live: ``rtt-foxglove`` serves the ROS 2 graph over the Foxglove WebSocket protocol.

:mod:`tutorial.tools.foxglove.bridge` holds :class:`~tutorial.tools.foxglove.bridge.FoxgloveBridge`;
``tutorial/tools/rtt_foxglove.py`` is the program's thin main.
"""
