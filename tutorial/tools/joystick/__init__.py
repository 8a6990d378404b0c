"""``rtt-joy``'s inputs and publisher (the demo scripts the notebooks play are :mod:`tutorial.joystick`).

==================  ================================================================
module              job
==================  ================================================================
``sources``         the input sources: ``GamepadInput``, ``KeyboardInput``
``publisher``       ``JoyPublisher``: a source published on ``/joy``, repeated at 20 Hz
==================  ================================================================
"""
