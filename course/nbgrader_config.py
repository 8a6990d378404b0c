"""nbgrader's configuration for the class: the course is this folder (``make assignments``, ``make grade``).

The exchange, where learners fetch and submit, is the hub's (its state
folder's ``exchange/``: ``course/.hub/exchange``, or under ``RTT_HUB_STATE``,
which ``make hub`` gives its learners) unless ``RTT_NBGRADER_EXCHANGE`` names another (a course's server: nbgrader's
usual ``/srv/nbgrader/exchange``; a test's own folder).  Every learner must
be able to write to it (``chmod 777``, as nbgrader's documentation says).
"""

import os
import sys
from pathlib import Path

from nbgrader.preprocessors import (
    CheckCellMetadata,
    ClearHiddenTests,
    ClearMarkScheme,
    ClearOutput,
    ClearSolutions,
    ComputeChecksums,
    IncludeHeaderFooter,
    InstantiateTests,
    LockCells,
    SaveCells,
)

from tutorial.tools.grading.release import ReleaseStubs

c = get_config()  # noqa: F821 - given by nbgrader when it reads this file

c.CourseDirectory.root = str(Path(__file__).resolve().parent)
c.CourseDirectory.course_id = "ros-tank-tutorial"
# The hub's: its state folder's exchange/, which RTT_HUB_STATE moves as it moves the hub's (course/domains.py's
# hub_state(), written out: this file imports nothing of the course, whose copies elsewhere have no course/
# modules beside them, and nbgrader would go on without this file after an error in it), unless
# RTT_NBGRADER_EXCHANGE names one.
STATE = Path(os.environ.get("RTT_HUB_STATE", Path(__file__).resolve().parent / ".hub")).resolve()
c.Exchange.root = os.environ.get("RTT_NBGRADER_EXCHANGE", str(STATE / "exchange"))
c.Exchange.path_includes_course = True

# The release shows each exercise's own stub (tutorial/tools/grading/release.py), right after nbgrader's
# ClearSolutions has taken the worked solution out; the rest is nbgrader's own list, in its order.
c.ClearSolutions.code_stub = {"python": "raise NotImplementedError"}
c.GenerateAssignment.preprocessors = [
    IncludeHeaderFooter,
    InstantiateTests,
    LockCells,
    ClearSolutions,
    ReleaseStubs,
    ClearOutput,
    CheckCellMetadata,
    ComputeChecksums,
    SaveCells,
    ClearHiddenTests,
    ClearMarkScheme,
    ComputeChecksums,
    CheckCellMetadata,
]

# Grading: a cell that runs longer than this (an answer that never returns) is interrupted, its
# exercise gets 0, and the rest of the notebook is graded.  An answer that never returns on a thread of
# its own (a camera's render thread) cannot be interrupted and slows the kernel for the rest of the
# notebook: its outputs may come late, which must not end the grading of the notebook.
c.Execute.timeout = int(os.environ.get("RTT_GRADING_CELL_TIMEOUT", "120"))
# course/grade.py grades in a sandbox (tutorial/tools/grading/sandbox.py): each kernel as the job's own user,
# without network, limited and sealed; RTT_SANDBOX describes the job.
if os.environ.get("RTT_SANDBOX"):
    from nbconvert.preprocessors import ClearMetadataPreprocessor
    from nbgrader.preprocessors import (
        AssignLatePenalties,
        IgnorePattern,
        LimitOutput,
        SaveAutoGrades,
    )

    from tutorial.tools.grading.sandbox import KERNEL_MARK, SandboxedExecute

    # nbgrader's own list (nbgrader.converters.autograde), its Execute sandboxed
    c.Autograde.autograde_preprocessors = [
        SandboxedExecute,
        IgnorePattern,
        ClearMetadataPreprocessor,
        LimitOutput,
        SaveAutoGrades,
        AssignLatePenalties,
        CheckCellMetadata,
    ]
    # Off unless a course turns it on; then it would take off the mark a dead kernel leaves in a cell, which the
    # crash, not run and CPU-time flags are read from (course/sandboxing.py), and nbgrader's own metadata.
    c.ClearMetadataPreprocessor.preserve_cell_metadata_mask = {"nbgrader", KERNEL_MARK}
else:
    from tutorial.tools.grading.sandbox import REFUSED, UNSANDBOXED, RefusedExecute

    if os.environ.get(UNSANDBOXED) != "1":
        # nbgrader autograde by hand, or the formgrader's button: refused, with what to run instead (a learner's
        # code would run with the teacher's rights, unsealed; course/grade.py --unsandboxed sets UNSANDBOXED).
        # The command is refused here, before its --force removes anything; the button, by the executor.
        if sys.argv[1:2] == ["autograde"]:
            sys.exit(f"nbgrader autograde: refused, nothing changed. {REFUSED}")
        c.Autograde.autograde_preprocessors = [RefusedExecute]
c.Execute.raise_on_iopub_timeout = False
c.Execute.iopub_timeout = 30
