"""The notebooks' exercises and their checks: one module per step, a grader shared by all.

A notebook imports the check of each exercise from its step's module, e.g.
``from tutorial.exercises.step1 import check_dpad_steering``.
"""
