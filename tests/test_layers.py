"""The library's layers: who may import whom, read from the source (no import is run).

* a step module (``tutorial/controllers/*.py``, written from a notebook)
  imports the library and never another step module, so editing one
  step's notebook cannot change another step;
* the library never imports a step module: project files name them and the
  project loader imports them by name (only the notebook helpers and the
  exercises, which sit above the steps, may);
* nothing but the programs themselves imports ``tutorial.tools`` (the
  ``rtt-*`` mains): what a program and a notebook share lives in the library.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

pytestmark = pytest.mark.unit

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "tutorial"
ABOVE_THE_STEPS = ("tutorial.notebook", "tutorial.exercises")


def module_name(path: Path) -> str:
    """``tutorial/core/app.py`` -> ``tutorial.core.app``; a package's ``__init__`` is the package."""
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def imported_modules(source: str, name: str, is_package: bool) -> set[str]:
    """Every module ``source`` imports, at any depth (functions too), relative imports resolved.

    ``from a.b import c`` counts as ``a.b`` and ``a.b.c`` (``c`` may be a module).
    """
    package = name if is_package else name.rpartition(".")[0]
    found: set[str] = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")
                anchor = anchor[: len(anchor) - (node.level - 1)]
                base = ".".join([*anchor, base] if base else anchor)
            found.add(base)
            found.update(f"{base}.{alias.name}" for alias in node.names)
    return found


def violations(modules: dict[str, set[str]]) -> list[str]:
    """The broken rules, one line each, for ``{module name: the modules it imports}``."""
    problems = []
    for name, imports in sorted(modules.items()):
        steps = {m for m in imports if m.startswith("tutorial.controllers.")}
        tools = {m for m in imports if m == "tutorial.tools" or m.startswith("tutorial.tools.")}
        if name.startswith("tutorial.controllers."):
            others = {m for m in steps if not m.startswith(name)}
            if others:
                problems.append(f"step module {name} imports another step: {sorted(others)}")
        elif steps and not name.startswith(ABOVE_THE_STEPS) and name != "tutorial.controllers":
            problems.append(f"library module {name} imports a step module: {sorted(steps)}")
        if tools and not name.startswith("tutorial.tools"):
            problems.append(f"{name} imports a program's main: {sorted(tools)}")
    return problems


def library_imports() -> dict[str, set[str]]:
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        name = module_name(path)
        out[name] = imported_modules(path.read_text(encoding="utf-8"), name, path.name == "__init__.py")
    return out


def test_the_layers_hold():
    modules = library_imports()
    assert "tutorial.controllers.joint_state_publisher" in modules  # the scan found the step modules
    problems = violations(modules)
    assert not problems, "\n".join(problems)


def test_each_step_module_reaches_the_interfaces_not_a_sibling():
    """The shared contracts moved out of the steps: every step that publishes or subscribes uses them."""
    modules = library_imports()
    steps = [n for n in modules if n.startswith("tutorial.controllers.") and n != "tutorial.controllers"]
    assert len(steps) == 7
    for name in steps:
        assert any(m.startswith("tutorial.interfaces.") for m in modules[name]), name


@pytest.mark.parametrize(
    "name, source, expected",
    [
        (
            "tutorial.controllers.imu_state_subscriber",
            "from .imu_state_publisher import find_imu",
            "step module tutorial.controllers.imu_state_subscriber imports another step",
        ),
        (
            "tutorial.controllers.camera_image_publisher",
            "def f():\n    from tutorial.controllers.joint_state_publisher import stamp_parts",
            "imports another step",
        ),
        (
            "tutorial.core.trajectory",
            "from tutorial.controllers.joint_state_publisher import PeriodAccumulator",
            "library module tutorial.core.trajectory imports a step module",
        ),
        (
            "tutorial.view.images",
            "from ..controllers import camera_image_publisher",
            "library module tutorial.view.images imports a step module",
        ),
        (
            "tutorial.notebook.live_image",
            "from tutorial.tools.rtt_image import ImageReceiver",
            "imports a program's main",
        ),
    ],
)
def test_the_check_catches_each_kind_of_wrong_import(name, source, expected):
    imports = imported_modules(source, name, is_package=False)
    problems = violations({name: imports})
    assert len(problems) == 1 and expected in problems[0], problems


@pytest.mark.parametrize(
    "name, source",
    [
        ("tutorial.controllers.joint_state_subscriber", "from ..interfaces.joint_state import joint_state_qos"),
        ("tutorial.exercises.step2_joint_state_publisher", "from tutorial.controllers.tank_controller import RttTankController"),
        ("tutorial.notebook.runs", "from tutorial.core.app import App"),
        ("tutorial.tools.rtt_joy", "from tutorial.tools import rtt_run"),
    ],
)
def test_what_the_layers_allow_passes(name, source):
    assert violations({name: imported_modules(source, name, is_package=False)}) == []
