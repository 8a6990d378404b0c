"""A live view through Jupyter's port alone: JupyterLab on one host, the learner's browser on another.

This is how a course's JupyterHub, Binder, Colab and ``ssh -L 8888:...``
work: the browser reaches the kernel's machine through Jupyter's port and
nothing else.  The hosts are the network tier's (tests/netns.py):

- ``robot`` runs JupyterLab, bound to its own address, and the demo
  joystick (``rtt-joy --demo``) driving the tank over ROS 2;
- ``operator`` runs Chromium (tests/lab_browser.py), which reaches the
  robot host's Jupyter port and nothing else on it (the kernel's and ROS's
  sockets are the robot host's own).

A notebook starts Step 2 with its live view (``BackgroundApp(...).show()``),
run with Run All, then keeps the kernel busy for 20 s: the view draws its
first picture within 2 s of its output appearing and moves while the
joystick drives, while the cell runs; a page reload in that cell has the
scene back within 2 s of the view's output, and the view moving, before
the cell ends.  Then, with the kernel idle: the view moves, and a
trivial cell answers while the view is live.  The same without the busy
cell, with the browser on the robot host, the kernel's own, and an idle
page reload that has the scene back within 5 s, is a ``more`` case.
The figures are printed (``-s``).
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from tests.jupyterlab import JupyterLab
from tests.lab_browser import step2_notebook

from netns import net, on  # noqa: F401 - the fixture

pytestmark = pytest.mark.network

ROOT = Path(__file__).resolve().parents[1]


# The busy cell of the Run All notebook (a scripted drive or a wait_until, as a learner's): long enough that the
# view is measured and the page reloaded while it runs (the browser checks that it still ran).
BUSY_S = 20


def browse(host, url: str, address: str, busy_s: float = 0) -> dict:
    """tests/lab_browser.py on ``host``; what it measured."""
    done = subprocess.run(
        host.command([sys.executable, "-m", "tests.lab_browser", url, address, *([str(busy_s)] if busy_s else [])]),
        cwd=ROOT,
        env=host.env(PYTHONPATH=str(ROOT)),
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, f"the browser on {host.name} failed:\n{done.stdout[-2000:]}\n{done.stderr[-4000:]}"
    return json.loads(done.stdout.strip().splitlines()[-1])


def lab_run(hosts, procs, tmp_path, where: str, busy_s: float = 0) -> dict:
    """Step 2's notebook in a JupyterLab on the robot host, the demo joystick driving, the browser on
    ``where`` ("operator": another host; "robot": the kernel's own); what the browser measured."""
    robot, host = hosts["robot"], hosts[where]
    step2_notebook(tmp_path / "step2.ipynb", f"rtt_{where}", busy_s=busy_s)
    on(procs, robot, "tutorial.tools.rtt_joy", "--demo")
    env = {
        "ROS_AUTOMATIC_DISCOVERY_RANGE": "SUBNET",  # the robot host's own subnet: nothing else is on it
        "PYTHONPATH": str(ROOT),
        "RTT_TEST_MODE": None,  # a run lasts until the kernel stops, as for a learner
    }
    with JupyterLab(tmp_path, env=env, ip=robot.address, prefix=robot.command([])) as lab:
        got = browse(host, lab.notebook_url("step2.ipynb", workspace=where), robot.address, busy_s)
        print(f"browser on {where}: {got}")
        lab.note_processes()
    assert got["moved"] > 200, f"the view did not move: {got}"
    assert got["fps"] >= 10, f"the view drew {got['fps']} frames/s from the kernel"
    assert max(got["cell_ms"]) < 1000, f"a trivial cell took {got['cell_ms']} ms"
    assert got["dropped"] == 0, f"the view dropped {got['dropped']} frames"
    if not busy_s:  # with a busy cell, the page was reloaded in it (measured by the busy test)
        assert got["moved_after"] > 200, f"the view did not move after a reload: {got}"
        assert got["reload_s"] < 5, f"the scene came {got['reload_s']} s after the reload"
    return got


def test_a_live_view_draws_through_jupyters_port_alone_while_run_all_keeps_the_kernel_busy(
    net,  # noqa: F811
    procs,
    tmp_path,
):
    got = lab_run(net, procs, tmp_path, "operator", busy_s=BUSY_S)
    assert got["first_picture_s"] < 2, f"the view's first picture came {got['first_picture_s']} s after its output"
    assert got["moved_busy"] > 200, f"the view did not move while a cell ran: {got}"
    assert got["fps_busy"] >= 20, f"the view drew {got['fps_busy']} frames/s while a cell ran"
    # A reload while the cell runs: the page asks the kernel for its widgets, and the views' subshell answers
    # (tutorial/view/widget/subshell.py, ViewSubshell._restore_there): the scene is back within 2 s of the
    # view's output, and the view moves, before the cell ends.  From the reload itself, JupyterLab's own
    # loading comes first: printed (reload_busy_s), not held to a figure.
    assert got["scene_after_view_busy_s"] < 2, f"the scene came late after a reload in the busy cell: {got}"
    assert got["moved_after_busy"] > 200 and got["reload_busy_before_end"], f"a reload waited for the cell: {got}"


@pytest.mark.more
def test_a_live_view_in_a_browser_on_the_kernels_host(net, procs, tmp_path):  # noqa: F811
    lab_run(net, procs, tmp_path, "robot")
