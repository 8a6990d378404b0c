"""nbval: a cell that needs network hosts is skipped, saying why, where none exist.

Notebook 08 runs programs on two hosts made of network namespaces
(:mod:`tutorial.network.hosts`), which needs root.  Its cells that need them
begin with ``# NEEDS_HOSTS``; without root they only print
``no hosts here: <reason>``, which is not what their saved outputs (a run
that had hosts) say, so nbval skips exactly those cells, saying why.  Every
other cell, the exercises too, is checked as usual.
"""

from __future__ import annotations

import pytest

MARK = "# NEEDS_HOSTS"


def pytest_collection_modifyitems(config, items):
    needing = [
        i for i in items if MARK in getattr(getattr(i, "cell", None), "source", "")
    ]
    if not needing:
        return
    from tutorial.network.hosts import why_unavailable

    problem = why_unavailable()
    if problem is None:
        return
    for item in needing:
        reason = f"this cell needs its own network hosts: {problem}"
        item.add_marker(pytest.mark.skip(reason=reason))
