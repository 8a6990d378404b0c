"""The book's design page and the layout page say what the code is: each figure measured from the code.

``book/design.md`` names the definitions that hold the design, each row
with "about N lines".  Each named file and definition must exist (a dotted
name is a method of a class), and each row's figure must be within 10 % of
the lines its definitions span (decorators included).  The page's total and
the library's size are held the same way, and so are the lessons' library's
figures in ``book/reference/layout.md`` (``scripts/library_size.py``).
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

pytestmark = pytest.mark.unit

ROOT = Path(__file__).resolve().parents[1]
DESIGN = ROOT / "book" / "design.md"
LAYOUT = ROOT / "book" / "reference" / "layout.md"
ROW = re.compile(r"^\| `(tutorial/[\w/]+\.py)`: (.+?) \(about (\d+) lines\) \|", re.MULTILINE)


def span(path: Path, name: str) -> int:
    """Lines of the definition ``name`` (``Class.method`` for a method) in ``path``.

    Raises:
        LookupError: there is no such definition.
    """
    tree = ast.parse(path.read_text(encoding="utf-8"))
    scope, *rest = name.split(".")
    kinds = (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)
    found = [n for n in ast.walk(tree) if isinstance(n, kinds) and n.name == scope]
    if len(found) > 1 and not rest:
        raise LookupError(f"{path.relative_to(ROOT)} defines {name} {len(found)} times: name it Class.{name}")
    node = found[0] if found else None
    if node is not None and rest:
        node = next((n for n in node.body if isinstance(n, kinds) and n.name == rest[0]), None)
    if node is None:
        raise LookupError(f"{path.relative_to(ROOT)} has no {name}")
    return node.end_lineno - min([node.lineno] + [d.lineno for d in node.decorator_list]) + 1


def rows() -> list[tuple[str, list[str], int]]:
    text = DESIGN.read_text(encoding="utf-8")
    return [(path, re.findall(r"`([\w.]+)`", names), int(n)) for path, names, n in ROW.findall(text)]


def near(measured: float, stated: float) -> bool:
    return abs(measured - stated) <= 0.10 * measured


def test_the_design_page_has_its_rows_and_names_where_call_later_is_wired():
    found = rows()
    assert len(found) >= 8, f"only {len(found)} rows of the form `file`: `name` (about N lines)"
    assert "tutorial/app/app.py" in {path for path, _, _ in found}


@pytest.mark.parametrize("path, names, stated", rows(), ids=[r[0] for r in rows()])
def test_each_row_names_definitions_that_exist_and_spans_about_its_lines(path, names, stated):
    measured = sum(span(ROOT / path, name) for name in names)
    assert near(measured, stated), f"{path} {names}: {measured} lines, the page says about {stated}"


def test_the_pages_total_and_the_librarys_size_are_measured():
    text = DESIGN.read_text(encoding="utf-8")
    total = sum(sum(span(ROOT / path, name) for name in names) for path, names, _ in rows())
    stated_total = int(re.search(r"about (\d+) lines hold them", text).group(1))
    assert near(total, stated_total), f"the rows span {total} lines; the page says about {stated_total}"
    assert f"in {stated_total} lines" in text.splitlines()[0], "the title's figure is the total's"
    library = sum(len(p.read_text(encoding="utf-8").splitlines()) for p in (ROOT / "tutorial").rglob("*.py"))
    stated = int(re.search(r"The library is about ([\d,]+) lines", text).group(1).replace(",", ""))
    assert near(library, stated), f"tutorial/ is {library} lines; the page says about {stated}"


def test_the_layout_page_states_the_lessons_librarys_size_as_measured():
    import sys

    sys.path.insert(0, str(ROOT / "scripts"))
    try:
        import library_size
    finally:
        sys.path.remove(str(ROOT / "scripts"))
    m = library_size.measure()
    text = LAYOUT.read_text(encoding="utf-8")
    found = re.search(r"(\d+) modules, ([\d,]+) lines, ([\d,]+) of them code", text)
    assert found, "the layout page does not state the lessons' library's size"
    modules, lines, code = (int(g.replace(",", "")) for g in found.groups())
    measured = f"{len(m['modules'])} modules, {m['lines']} lines, {m['code']} of them code"
    stated = (modules, lines, code)
    assert all(near(a, b) for a, b in zip((len(m["modules"]), m["lines"], m["code"]), stated)), (
        f"the page: {found.group(0)}; measured: {measured}"
    )
    rest = sum(len(p.read_text(encoding="utf-8").splitlines()) for p in (ROOT / "tutorial").rglob("*.py")) - m["lines"]
    said = int(re.search(r"The rest of\s+`tutorial/`, about ([\d,]+) lines", text).group(1).replace(",", ""))
    assert near(rest, said), f"the rest of tutorial/ is {rest} lines; the page says about {said}"


# What the lessons' library (notebooks 01 to 06, their checks and project files) never reaches: the tooling package
# (the programs, the App rtt-run runs, recording, the URDF tools, the test hosts, Foxglove, grading's machinery), the
# lesson modules (the checks stand on app/reference's frozen copies), and the two interfaces only notebook 09 and the
# tooling speak.
TOOLING = (
    "tutorial.tools",
    "tutorial.controllers",
    "tutorial.interfaces.robot_description",
    "tutorial.interfaces.odometry",
)


def test_the_lessons_library_reaches_none_of_the_tooling():
    """Followed as library_size follows it (imports at any depth, the project files' classes): a module of the
    lessons that imports the URDF tools again, or a step's project that runs notebook 09's publisher, fails."""
    import sys

    sys.path.insert(0, str(ROOT / "scripts"))
    try:
        import library_size
    finally:
        sys.path.remove(str(ROOT / "scripts"))
    reached = [m for m in library_size.library() if m.startswith(TOOLING)]
    assert reached == [], f"the lessons' library reaches the tooling: {reached}"
    later = library_size.library(("01", "02", "03", "04", "05", "06", "09"))
    assert "tutorial.tools.urdf.export" in later, "the test can fail: notebook 09's lesson reaches the URDF tools"
