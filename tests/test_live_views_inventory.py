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
``views.MeshcatPage``       a page drawn by hand (notebook 00): a ``MeshcatWidget``
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
    "tutorial.notebook.views.MeshcatPage": "MeshcatWidget",
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
