"""Where ``/joy`` comes from: a gamepad, the keyboard, or a demo script.

==================  ================================================================
module              job
==================  ================================================================
``sources``         input sources: ``GamepadInput``, ``KeyboardInput``, ``DemoInput`` and its scripts
``publisher``       ``JoyPublisher``: a source published on ``/joy``, repeated at 20 Hz (``rtt-joy``)
``scripted``        ``ScriptedJoy``: the demo script fed by simulated time, no network (notebooks, tests)
==================  ================================================================
"""
