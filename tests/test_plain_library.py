"""A library a teacher can read: short modules, and controllers as plain as ros2/demos.

Three checks, each proved to catch what it claims on a made-up module:

- a module of ``tutorial/`` over :data:`MAX_LINES` lines says in its
  docstring why it is one job (the words "one job");
- the controllers the notebooks export (``tutorial/controllers/``, the code a
  learner writes in notebooks 01 to 06, and 09's robot-model publisher) use no speed tricks: no
  ``memoryview``, no ``array`` module, no ``bytes``/``bytearray`` buffers.
  Where a step needs speed, it calls a library function in one line.
- each package's docstring names every module it holds, and no module it
  does not hold: the map a teacher reads first is the package as it is.
  ``controllers`` and ``exercises`` are one module per notebook, said once.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

pytestmark = pytest.mark.unit

ROOT = Path(__file__).resolve().parent.parent
MAX_LINES = 400
TRICK_CALLS = {"memoryview", "bytes", "bytearray"}
ONE_PER_NOTEBOOK = {"controllers", "exercises"}  # their docstrings give the rule, not a list
# A module named in a package's docstring: ``name`` (or ``name/``) starting a table's row, or :mod:`tutorial.x.name`
TABLE_ROW = re.compile(r"^``(\w+)/?``\s{2,}", re.M)


def long_modules_without_a_reason(package: Path) -> list[str]:
    """Modules under ``package`` over MAX_LINES lines whose docstring does not say "one job"."""
    found = []
    for path in sorted(package.rglob("*.py")):
        text = path.read_text()
        docstring = " ".join((ast.get_docstring(ast.parse(text)) or "").split())  # a line break is a space
        if text.count("\n") > MAX_LINES and "one job" not in docstring:
            found.append(f"{path.relative_to(package.parent)}: {text.count(chr(10))} lines")
    return found


def unnamed_or_gone_modules(package: Path) -> list[str]:
    """What the docstring of ``package``'s subpackages (``__init__.py``) gets wrong about their modules."""
    found = []
    for init in sorted(package.glob("**/__init__.py")):  # every depth: tools/, and tools/bag/ in it
        sub = init.parent
        if sub == package or sub.name in ONE_PER_NOTEBOOK:
            continue
        where = ".".join(sub.relative_to(package.parent).parts)  # tutorial.tools.bag
        doc = ast.get_docstring(ast.parse(init.read_text())) or ""
        held = {p.stem for p in sub.glob("[!_]*.py")} | {p.parent.name for p in sub.glob("[!_]*/__init__.py")}
        named = set(TABLE_ROW.findall(doc))
        named |= {m.group(1) for m in re.finditer(rf":mod:`{re.escape(where)}\.(\w+)", doc)}
        label = where.removeprefix(package.name + ".")
        found += [f"{label}: {name} not named" for name in sorted(held - named)]
        found += [f"{label}: {name} named, not there" for name in sorted(named - held)]
    return found


def speed_tricks(source: str) -> list[str]:
    """``line: what`` for each speed trick in ``source``: memoryview/bytes/bytearray calls, the array module."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in TRICK_CALLS:
            found.append(f"{node.lineno}: {node.func.id}(")
        elif isinstance(node, ast.Import) and any(alias.name == "array" for alias in node.names):
            found.append(f"{node.lineno}: import array")
        elif isinstance(node, ast.ImportFrom) and node.module == "array":
            found.append(f"{node.lineno}: from array import")
    return found


def test_every_long_module_says_why_it_is_one_job():
    assert long_modules_without_a_reason(ROOT / "tutorial") == []


def test_the_length_check_catches_a_long_module_without_a_reason(tmp_path):
    package = tmp_path / "tutorial"
    package.mkdir()
    body = "x = 1\n" * MAX_LINES
    (package / "long.py").write_text('"""Many jobs."""\n' + body)
    (package / "long_but_said.py").write_text('"""Long: one\njob, the file format."""\n' + body)
    (package / "short.py").write_text('"""Short."""\n' + "x = 1\n" * (MAX_LINES - 1))
    assert long_modules_without_a_reason(package) == [f"tutorial/long.py: {MAX_LINES + 1} lines"]


def test_every_package_names_its_modules():
    assert unnamed_or_gone_modules(ROOT / "tutorial") == []


def test_the_module_map_check_catches_a_module_unnamed_or_gone(tmp_path):
    package = tmp_path / "tutorial" / "things"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text(
        '"""Things.\n\n``kept``      one job\n``gone``      was here\n\n:mod:`tutorial.things.also` too.\n"""\n'
    )
    for name in ("kept", "also", "new"):
        (package / f"{name}.py").write_text('"""A module."""\n')
    assert unnamed_or_gone_modules(tmp_path / "tutorial") == ["things: new not named", "things: gone named, not there"]


def test_the_module_map_check_reads_a_package_inside_a_package_too(tmp_path):
    """As tutorial/tools/bag/ is in tutorial/tools/: its own docstring, with :mod: paths of its full name."""
    outer = tmp_path / "tutorial" / "tools"
    inner = outer / "bag"
    inner.mkdir(parents=True)
    (outer / "__init__.py").write_text('"""Tools.\n\n``bag/``      recording\n"""\n')
    (inner / "__init__.py").write_text('"""Bags.\n\n:mod:`tutorial.tools.bag.record` writes.\n"""\n')
    for name in ("record", "play"):
        (inner / f"{name}.py").write_text('"""A module."""\n')
    assert unnamed_or_gone_modules(tmp_path / "tutorial") == ["tools.bag: play not named"]


def test_the_exported_controllers_use_no_speed_tricks():
    modules = sorted(m for m in (ROOT / "tutorial" / "controllers").glob("*.py") if m.name != "__init__.py")
    assert len(modules) >= 6  # at least one for each of notebooks 01 to 06
    found = {m.name: speed_tricks(m.read_text()) for m in modules}
    assert {name: tricks for name, tricks in found.items() if tricks} == {}


@pytest.mark.parametrize(
    "source, trick",
    [
        ("buf = memoryview(data.qpos)\n", "1: memoryview("),
        ("positions = bytes(8 * n)\n", "1: bytes("),
        ("scratch = bytearray(64)\n", "1: bytearray("),
        ("import array\n", "1: import array"),
        ("from array import array\n", "1: from array import"),
    ],
)
def test_the_trick_check_catches_each_trick(source, trick):
    assert speed_tricks(source) == [trick]


def test_the_trick_check_leaves_numpy_alone():
    assert speed_tricks("import numpy as np\nhome = np.array([0.0, 0.0, 0.107])\n") == []
