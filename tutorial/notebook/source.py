"""Show a piece of the library's source in a notebook, with the file it lives in.

The ROS interface of each topic (its name, its QoS and why) lives in
:mod:`tutorial.interfaces`, shared by every step; a notebook shows it where
the learner meets it, rather than defining a copy::

    show_source(joint_state_qos)
"""

from __future__ import annotations

import inspect
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def source_markdown(obj) -> str:
    """``obj``'s source as Markdown: a line naming its file, then a Python code block.

    Args:
        obj: a function, class or module of this project.

    Raises:
        TypeError: ``obj`` has no Python source (a built-in).
    """
    path = Path(inspect.getsourcefile(obj)).resolve()
    where = path.relative_to(ROOT) if path.is_relative_to(ROOT) else path.name
    code = inspect.getsource(obj).rstrip()
    return f"From `{where}`:\n\n```python\n{code}\n```\n"


def show_source(*objs) -> None:
    """Display each object's source (see :func:`source_markdown`) in the notebook (kernel thread)."""
    from IPython.display import Markdown, display

    for obj in objs:
        display(Markdown(source_markdown(obj)))
