"""The notebooks' exercises and their checks: one module per notebook, named after it
(``step1_tank_controller`` for ``01_step1_tank_controller.ipynb``), a grader shared by all.

A notebook imports the check of each exercise from its notebook's module, e.g.
``from tutorial.exercises.step1_tank_controller import check_dpad_steering``.
"""
