"""The release of an nbgrader assignment shows each exercise's own stub: :class:`ReleaseStubs`.

``course/assignments.py`` puts each exercise's worked solution between
nbgrader's solution delimiters and keeps the notebook's stub in the cell's
metadata (``rtt_stub``).  nbgrader's ``ClearSolutions`` would leave a bare
``raise NotImplementedError`` in the release; this preprocessor, run right
after it (``course/nbgrader_config.py``), puts the notebook's stub there
instead, so the learner sees the same cell as in the teacher's notebook.
It runs in ``nbgrader generate_assignment``, one notebook at a time.
"""

from __future__ import annotations

from nbgrader.preprocessors import NbGraderPreprocessor


class ReleaseStubs(NbGraderPreprocessor):
    """Each answer cell of the release shows the stub kept in its ``rtt_stub`` metadata (then dropped)."""

    def preprocess_cell(self, cell, resources, index):
        stub = cell.metadata.pop("rtt_stub", None)
        if stub is not None:
            cell.source = stub
        return cell, resources
