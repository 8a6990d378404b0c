"""The course's grading machinery, which no notebook imports (the checks themselves are :mod:`tutorial.exercises`).

==================  ================================================================
module              job
==================  ================================================================
``release``         the release's stubs, in ``nbgrader generate_assignment``
``sandbox``         each graded kernel as a user of its own, without network, limited
``seal``            the grading kernel's verdicts, signed only when the teacher's own
                    check made them
``sealed_kernel``   the kernel the sandbox starts, sealed before any cell runs
``judge``           every exercise's check, in a process of its own
``judged``          the kernel's side: each judged check asks the judge
``wire``            what crosses between them: data, built back only from listed types
``keyrings``        the kernel keyrings refused to the kernel and all it starts
==================  ================================================================

``course/grade.py``, ``course/sandboxing.py`` and ``course/nbgrader_config.py`` use them.
"""
