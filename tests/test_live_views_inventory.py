"""Every live view a notebook shows travels over the notebook's own connection: the list, and the check.

A view whose bytes reach the browser only from a server the kernel starts
(an ``<iframe src="http://127.0.0.1:PORT">``) shows nothing when the browser
is on another machine (a JupyterHub, an SSH tunnel, Colab).  The notebooks'
live outputs, and how each reaches the browser:

==========================  ==================================================
output                      how its bytes travel
==========================  ==================================================
``views.LiveView``          a run's 3D view (and ``views.show``: side by side,
                            the IMU's arrows, notebook 07's replay into a
                            fresh viewer): a ``MeshcatWidget``
``drawing.MeshcatPage``     a page drawn by hand (notebook 00): a ``MeshcatWidget``
``live_plot.LivePlot``      a picture redrawn in place: a display update
``live_image.LiveImage``    the camera's picture: a display update
``teleop.TeleopPanel``,     ipywidgets
``panels``
recordings, still pages     self-contained HTML in the output
==========================  ==================================================

The check: no module of the notebooks' layer starts a server or points an
output at one, and the classes above use what the table says.
"""

from __future__ import annotations

import inspect
import re
from pathlib import Path

import pytest

pytestmark = pytest.mark.unit

NOTEBOOK_LAYER = Path(__file__).resolve().parents[1] / "tutorial" / "notebook"

TRAVELS = {
    "tutorial.notebook.views.LiveView": "MeshcatWidget",
    "tutorial.notebook.drawing.MeshcatPage": "MeshcatWidget",
    "tutorial.notebook.live.LiveOutput": "display_id=True",  # LivePlot's and LiveImage's base
    "tutorial.notebook.teleop.TeleopPanel": "ipywidgets",
}


def test_no_notebook_output_is_a_page_of_a_server_in_the_kernel():
    offending = []
    for path in sorted(NOTEBOOK_LAYER.glob("*.py")):
        text = path.read_text(encoding="utf-8")
        for pattern in (r"start_server\(", r"src=\\?[\"']https?://", r"server\.web_url", r"127\.0\.0\.1"):
            if re.search(pattern, text):
                offending.append(f"{path.name}: {pattern}")
    assert not offending, "a notebook output reached through a server in the kernel:\n" + "\n".join(offending)


@pytest.mark.parametrize("name, how", sorted(TRAVELS.items()))
def test_each_live_output_travels_as_listed(name, how):
    import importlib

    module, cls = name.rsplit(".", 1)
    source = inspect.getsource(getattr(importlib.import_module(module), cls))
    assert how in source, f"{name} no longer uses {how}: update the list in this module's docstring"


def test_the_live_plot_and_the_camera_picture_are_live_outputs():
    from tutorial.notebook.live import LiveOutput
    from tutorial.notebook.live_image import LiveImage
    from tutorial.notebook.live_plot import LivePlot

    assert issubclass(LivePlot, LiveOutput) and issubclass(LiveImage, LiveOutput)


# Every way the notebooks, the book, the README and the docstrings show a run's 3D view, each run below.
VIEW_FORMS = {
    "app.show()": "sim.show(height=300)",  # BackgroundApp.show: sim, viewer, viewer_app in the notebooks
    "views.show(app.view, ...)": "views.show(sim.view, height=320)",
    "views.show(a.view, b.view, ...)": "views.show(sim.view, viewer.view, height=320)",
    "display(app.view)": "display(sim.view)",
    "app.view, as a cell's last expression": "sim.view",
}
# What else is shown with .show() in those texts, and is not a run's 3D view.
OTHER_SHOWN = {"plt", "plot", "camera_view", "page"}  # matplotlib, LivePlot, LiveImage, MeshcatPage (its own test)
RUNS = {"sim", "viewer", "viewer_app"}  # BackgroundApps in the notebooks


def documented_texts():
    import json

    root = NOTEBOOK_LAYER.parents[1]
    for path in sorted((root / "notebooks").glob("*.ipynb")):
        for cell in json.loads(path.read_text(encoding="utf-8"))["cells"]:
            yield path.name, "".join(cell["source"])
    for path in [
        root / "README.md",
        *sorted((root / "book").rglob("*.md")),
        *sorted((root / "tutorial").rglob("*.py")),
    ]:
        if "_build" not in path.parts:
            yield str(path.relative_to(root)), path.read_text(encoding="utf-8")


def test_every_way_the_texts_show_a_view_is_one_tested_here():
    unknown = set()
    for where, text in documented_texts():
        for receiver in re.findall(r"\b(\w+)\.show\(", text):
            if receiver not in RUNS | OTHER_SHOWN | {"views"}:
                unknown.add(f"{where}: {receiver}.show(")
        for shown in re.findall(r"views\.show\(([^)]*)\)", text):
            for arg in filter(None, (a.strip() for a in shown.split(","))):
                if "=" not in arg and not (arg.startswith("*") or re.fullmatch(r"\w+\.view", arg)):
                    unknown.add(f"{where}: views.show({shown})")
        for shown in re.findall(r"display\((\w+\.view)\)", text):
            if shown.split(".")[0] not in RUNS:
                unknown.add(f"{where}: display({shown})")
    assert not unknown, "a way to show a view that VIEW_FORMS does not run:\n" + "\n".join(sorted(unknown))


@pytest.fixture(scope="module")
def shell():
    from IPython.core.interactiveshell import InteractiveShell

    ip = InteractiveShell.instance()
    setup = ip.run_cell(
        "from tutorial.notebook.runs import BackgroundApp, load\n"
        "from tutorial.notebook import views\n"
        "sim = BackgroundApp(load('step2.yaml'), node_name='shown')\n"
        "viewer = BackgroundApp(load('step3.yaml'), node_name='shown_viewer')\n"
    )
    assert setup.success, setup.error_in_exec
    yield ip
    ip.run_cell("sim.stop(); viewer.stop()")


@pytest.mark.parametrize("form", sorted(VIEW_FORMS))
def test_each_way_to_show_a_view_shows_its_live_widget(shell, form):
    from IPython.utils.capture import capture_output

    displays = len(shell.user_ns["sim"].view._displays)
    with capture_output() as shown:
        result = shell.run_cell(VIEW_FORMS[form])
    assert result.success, f"{form}: {result.error_in_exec!r}"
    widgets = [
        o.data["application/vnd.jupyter.widget-view+json"]["model_id"]
        for o in shown.outputs
        if "application/vnd.jupyter.widget-view+json" in o.data
    ]
    assert len(widgets) == 1, f"{form} showed {[list(o.data) for o in shown.outputs]}, not one live view"
    sim, viewer = shell.user_ns["sim"], shell.user_ns["viewer"]
    assert len(sim.view._displays) == displays + 1, f"{form} made no output of its own"
    display_ = sim.view._displays[-1]  # the output this form made
    if "viewer" in VIEW_FORMS[form]:  # side by side: one box of both views' widgets
        assert display_._box is not None and widgets == [display_._box.model_id]
        assert list(display_._box.children) == [sim.view.widget, viewer.view.widget]
    else:
        assert widgets == [sim.view.widget.model_id]
