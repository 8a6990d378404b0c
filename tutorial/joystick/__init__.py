"""Where the notebooks' ``/joy`` comes from: a demo script.

``rtt-joy``'s gamepad and keyboard are tooling: :mod:`tutorial.tools.joystick`.

==================  ================================================================
module              job
==================  ================================================================
``demo``            ``DemoInput`` and its scripts (the drives the notebooks and ``rtt-joy --demo`` play)
``scripted``        ``ScriptedJoy``: the demo script fed by simulated time, no network (notebooks, tests)
==================  ================================================================
"""
