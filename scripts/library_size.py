"""The lessons' library, measured: what notebooks 01 to 06 import from this project, and how big it is.

    python scripts/library_size.py [--notebooks 01 02 ...] [--modules] [--json]

The lessons' library is every module of ``tutorial`` that notebooks 01 to 06
import, directly or through other modules (at any depth, inside functions
too: grimp, import-linter's own graph), with the checks of their exercises,
and the modules the project files they load name as a class's module (the
controllers ``tutorial.core.project`` imports by name, which no import
statement shows).  For each module: its lines, and its lines of code (no
docstring, no comment, no blank line).  The figures go into
``book/reference/layout.md``; the design card's limits are 8,000 lines and
4,500 lines of code (issue #61).
"""

from __future__ import annotations

import argparse
import ast
import io
import json
import re
import sys
import tokenize
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = ("01", "02", "03", "04", "05", "06")
LIMITS = {"lines": 8000, "code": 4500}


def _imports_of_code(source: str) -> set[str]:
    """The ``tutorial`` modules a cell's code imports (lines of IPython magics and shell commands left out)."""
    if source.lstrip().startswith("%%"):  # a cell magic: the cell is not Python
        return set()
    code = "\n".join(line for line in source.splitlines() if not line.lstrip().startswith(("%", "!")))
    try:
        tree = ast.parse(code)
    except SyntaxError:  # IPython's own syntax (x = !cmd, x?): its import statements alone
        imports = [line.strip() for line in code.splitlines() if line.lstrip().startswith(("import ", "from "))]
        tree = ast.parse("\n".join(i for i in imports if not i.endswith(("(", "\\"))))
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names if a.name.split(".")[0] == "tutorial"}
        elif isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] == "tutorial":
            found.add(node.module)
            found |= {f"{node.module}.{a.name}" for a in node.names}  # a module imported from its package
    return found


def project_files(source: str) -> set[str]:
    """The project files (relative to ``project/``) code ``source`` names: ``"step2.yaml"``,
    ``"project/reference/step6.yaml"``, ``"../project/step2.yaml"`` or an absolute path."""
    found = re.findall(r"""["']([\w/.-]+\.yaml)["']""", source)
    return {name.rpartition("project/")[2] for name in found}


def notebook_imports(numbers=NOTEBOOKS) -> tuple[set[str], set[str]]:
    """The ``tutorial`` modules the notebooks' code cells import, and the project files they load."""
    modules, projects = set(), set()
    for number in numbers:
        for path in sorted((ROOT / "notebooks").glob(f"{number}_*.ipynb")):
            for cell in json.loads(path.read_text(encoding="utf-8"))["cells"]:
                if cell["cell_type"] != "code":
                    continue
                source = "".join(cell["source"])
                modules |= _imports_of_code(source)
                projects |= project_files(source)
    return modules, projects


def project_classes(names: set[str]) -> set[str]:
    """The modules that project files ``names`` (of ``project/``, with the templates they extend) name classes of."""
    modules, seen, todo = set(), set(), list(names)
    while todo:
        name = todo.pop()
        path = ROOT / "project" / name
        if name in seen or not path.exists():
            continue
        seen.add(name)
        text = path.read_text(encoding="utf-8")
        modules |= set(re.findall(r"class:\s*(tutorial[\w.]*):", text))
        todo += re.findall(r"""(?:extends|template|include)\w*:\s*["']?([\w.-]+\.yaml)""", text)
    return modules


def library(numbers=NOTEBOOKS) -> list[str]:
    """Every module of the lessons' library, sorted."""
    import grimp

    graph = grimp.build_graph("tutorial", include_external_packages=False)
    known = graph.modules
    direct, projects = notebook_imports(numbers)
    roots = {m for m in direct | project_classes(projects) if m in known}
    out = set(roots)
    for module in roots:
        out |= graph.find_upstream_modules(module)
    # a package's __init__ runs whenever one of its modules is imported
    for module in list(out):
        parts = module.split(".")
        out |= {".".join(parts[:k]) for k in range(1, len(parts)) if ".".join(parts[:k]) in known}
    return sorted(out)


def _path(module: str) -> Path:
    base = ROOT / Path(*module.split("."))
    return base / "__init__.py" if base.is_dir() else base.with_suffix(".py")


def code_lines(source: str) -> int:
    """Lines holding code: no blank line, no comment, no docstring (a string standing alone as a statement)."""
    docstrings = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant) and isinstance(node.value.value, str):
            docstrings |= set(range(node.lineno, node.end_lineno + 1))
    lines = set()
    for tok in tokenize.generate_tokens(io.StringIO(source).readline):
        if tok.type in (tokenize.COMMENT, tokenize.NL, tokenize.NEWLINE, tokenize.INDENT, tokenize.DEDENT):
            continue
        if tok.type == tokenize.ENDMARKER:
            continue
        lines |= {n for n in range(tok.start[0], tok.end[0] + 1) if n not in docstrings}
    return len(lines)


def measure(numbers=NOTEBOOKS) -> dict:
    """``{"modules": {name: [lines, code lines]}, "lines": total, "code": total}``."""
    sizes = {}
    for module in library(numbers):
        source = _path(module).read_text(encoding="utf-8")
        sizes[module] = [len(source.splitlines()), code_lines(source)]
    return {
        "modules": sizes,
        "lines": sum(s[0] for s in sizes.values()),
        "code": sum(s[1] for s in sizes.values()),
    }


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--notebooks", nargs="+", default=list(NOTEBOOKS), help="notebook numbers (default 01 to 06)")
    p.add_argument("--modules", action="store_true", help="also each module's figures, largest first")
    p.add_argument("--json", action="store_true", help="the figures as JSON")
    args = p.parse_args(argv)
    m = measure(tuple(args.notebooks))
    if args.json:
        print(json.dumps(m, indent=1))
        return 0
    if args.modules:
        for name, (lines, code) in sorted(m["modules"].items(), key=lambda kv: -kv[1][0]):
            print(f"{lines:6d} {code:6d}  {name}")
    print(
        f"the lessons' library (notebooks {args.notebooks[0]} to {args.notebooks[-1]}): {len(m['modules'])} modules, "
        f"{m['lines']:,} lines (limit {LIMITS['lines']:,}), {m['code']:,} lines of code (limit {LIMITS['code']:,})"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
