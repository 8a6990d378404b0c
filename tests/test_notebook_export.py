"""One source: the controller modules are exactly what their notebooks export, and notebooks read well."""

import json
import re
import subprocess
import sys

import pytest

from conftest import ROOT

NOTEBOOKS = sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb"))


def test_controller_modules_are_what_the_notebooks_export():
    result = subprocess.run(
        [sys.executable, "scripts/export_notebooks.py", "--check"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 0, result.stderr
    assert "are in step" in result.stdout


def test_the_check_fails_when_a_module_is_edited_by_hand(tmp_path):
    import shutil

    library = tmp_path / "tutorial"
    shutil.copytree(ROOT / "tutorial" / "controllers", library / "controllers")
    module = library / "controllers" / "tank_controller.py"
    module.write_text(module.read_text().replace("TRACK_DEAD_ZONE = 0.2", "TRACK_DEAD_ZONE = 0.3"))
    result = subprocess.run(
        [sys.executable, "scripts/export_notebooks.py", "--check", "--library", str(library)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 1
    assert "tutorial/controllers/tank_controller.py: differs from what its notebook exports" in result.stderr


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_code_lines_fit_the_book(path):
    """Code cells stay within 88 characters, so the book never scrolls them sideways."""
    long = [
        (i, line)
        for i, cell in enumerate(json.loads(path.read_text())["cells"])
        if cell["cell_type"] == "code"
        for line in "".join(cell["source"]).splitlines()
        if len(line) > 88
    ]
    assert long == [], f"{path.name}: cells with lines over 88 characters: {long}"


def unregistered_recorders(sources: list[str]) -> list[str]:
    """The code cells that start a recorder outside ``register(...)``: reset() would leave it recording."""
    import ast

    found = []
    for source in sources:
        tree = ast.parse("\n".join(line for line in source.splitlines() if not line.startswith(("%", "!"))))
        registered = {
            id(node)
            for call in ast.walk(tree)
            if isinstance(call, ast.Call) and getattr(call.func, "id", None) == "register"
            for node in ast.walk(call)
        }
        calls = [c for c in ast.walk(tree) if isinstance(c, ast.Call) and getattr(c.func, "id", None) == "BagRecorder"]
        found += [source.splitlines()[call.lineno - 1] for call in calls if id(call) not in registered]
    return found


def test_a_section_that_records_can_run_again():
    """A recorder a cell starts is registered, so the section's reset() closes it before it records again
    (two recorders on one file mixed both runs in it, a learner found)."""
    sources = [
        "".join(cell["source"])
        for path in NOTEBOOKS
        for cell in json.loads(path.read_text())["cells"]
        if cell["cell_type"] == "code" and not "".join(cell["source"]).startswith("#| export")
    ]
    assert any("BagRecorder(" in s for s in sources)
    assert unregistered_recorders(sources) == []
    left = ["r = BagRecorder(path, topics).start()", "with BagRecorder(path, topics) as r:\n    pass"]
    assert unregistered_recorders(left + ["r = register(BagRecorder(path, topics).start())"]) == [
        "r = BagRecorder(path, topics).start()",
        "with BagRecorder(path, topics) as r:",
    ]


LEFT_BEHIND = re.compile(r"\b(mkdtemp|mkstemp|mktemp)\(|delete\s*=\s*False")


def test_no_notebook_leaves_temporary_files_behind():
    """A notebook's temporary files live in a ``TemporaryDirectory``, which Python removes when the kernel is shut
    down (``mkdtemp`` left a folder in /tmp at every run of notebooks 07 and 09; a kernel that is killed, as nbval
    kills its kernels, still leaves it)."""
    code = [
        "".join(cell["source"])
        for path in NOTEBOOKS
        for cell in json.loads(path.read_text())["cells"]
        if cell["cell_type"] == "code"
    ]
    assert any("TemporaryDirectory(" in s for s in code)
    assert [s.splitlines()[0] for s in code if LEFT_BEHIND.search(s)] == []
    assert LEFT_BEHIND.search('folder = Path(tempfile.mkdtemp(prefix="rtt-"))')
    assert LEFT_BEHIND.search("f = tempfile.NamedTemporaryFile(delete=False)")


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_ignored_outputs_say_why(path):
    """An output nbval ignores has its reason on the next line, and the marker is one nbval knows."""
    for cell in json.loads(path.read_text())["cells"]:
        lines = "".join(cell["source"]).splitlines()
        for i, line in enumerate(lines):
            if "NBVAL_IGNORE_OUTPUT" in line:
                assert line.strip() == "# NBVAL_IGNORE_OUTPUT", f"nbval only knows the bare marker: {line!r}"
                assert i + 1 < len(lines) and lines[i + 1].startswith("# (why:"), lines[:3]


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_saved_outputs_hold_no_widget(path):
    """A saved output that is a widget needs the kernel that made it: reopened, JupyterLab draws its controls
    crossed by broken-link icons (or "model not found"), and the book a dead copy.  Every panel and live view
    leaves a stand-in or a recording at reset(), and each notebook ends with one."""
    widgets = [
        i
        for i, cell in enumerate(json.loads(path.read_text())["cells"])
        for output in cell.get("outputs", [])
        if "application/vnd.jupyter.widget-view+json" in output.get("data", {})
    ]
    assert widgets == [], f"{path.name}: cells whose saved output is a widget: {widgets}"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_a_notebook_opens_unchanged(path):
    """JupyterLab writes the kernel's own display name into a notebook it opens: saved with another, the notebook
    opens marked as changed, and a learner is asked to save what they never touched."""
    from jupyter_client.kernelspec import KernelSpecManager

    kernelspec = json.loads(path.read_text())["metadata"]["kernelspec"]
    assert kernelspec["display_name"] == KernelSpecManager().get_kernel_spec(kernelspec["name"]).display_name
