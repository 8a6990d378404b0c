"""Foxglove, live: ``rtt-foxglove`` serves the ROS 2 graph over the Foxglove WebSocket protocol.

:mod:`tutorial.foxglove.bridge` holds :class:`~tutorial.foxglove.bridge.FoxgloveBridge`;
``tutorial/tools/rtt_foxglove.py`` is the program's thin main.
"""
