"""The notebooks' exercises and their checks: one module per notebook, named after it
(``step1_tank_controller`` for ``01_step1_tank_controller.ipynb``), a grader shared by all.

A notebook imports the check of each exercise from its notebook's module, e.g.
``from tutorial.exercises.step1_tank_controller import check_dpad_steering``.
The checks' helpers: ``capture`` (what a controller publishes, kept in-process) and ``camera_rig``
(Step 6's camera controller driven on the tank, picture by picture).

Grading's own machinery, which no notebook imports (the release's stubs, the
seal, the sandbox), is tooling: :mod:`tutorial.tools.grading`.
"""
