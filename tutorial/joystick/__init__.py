"""Where ``/joy`` comes from: a gamepad, the keyboard, or a demo script.

==================  ================================================================
module              job
==================  ================================================================
``demo``            ``DemoInput`` and its scripts (the drives the notebooks and ``rtt-joy --demo`` play)
``sources``         the other input sources: ``GamepadInput``, ``KeyboardInput`` (``rtt-joy``)
``publisher``       ``JoyPublisher``: a source published on ``/joy``, repeated at 20 Hz (``rtt-joy``)
``scripted``        ``ScriptedJoy``: the demo script fed by simulated time, no network (notebooks, tests)
==================  ================================================================
"""
