"""A live view through Jupyter's port alone: JupyterLab on one host, the learner's browser on another.

This is how a course's JupyterHub, Binder, Colab and ``ssh -L 8888:...``
work: the browser reaches the kernel's machine through Jupyter's port and
nothing else.  The hosts are the network tier's (tests/netns.py):

- ``robot`` runs JupyterLab, bound to its own address, and the demo
  joystick (``rtt-joy --demo``) driving the tank over ROS 2;
- ``operator`` runs Chromium (tests/lab_browser.py), which reaches the
  robot host's Jupyter port and nothing else on it (the kernel's and ROS's
  sockets are the robot host's own).

A notebook starts Step 2 with its live view (``BackgroundApp(...).show()``):
the view gets its scene, draws, and moves while the joystick drives; a
trivial cell answers while the view is live; after a page reload the view
has its scene again and moves.  The same then runs with the browser on the
robot host, the kernel's own.  The figures are printed (``-s``).
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


def browse(host, url: str, address: str) -> dict:
    """tests/lab_browser.py on ``host``; what it measured."""
    done = subprocess.run(
        host.command([sys.executable, "-m", "tests.lab_browser", url, address]),
        cwd=ROOT,
        env=host.env(PYTHONPATH=str(ROOT)),
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, f"the browser on {host.name} failed:\n{done.stdout[-2000:]}\n{done.stderr[-4000:]}"
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_a_live_view_reaches_a_browser_through_jupyters_port_alone(net, procs, tmp_path):  # noqa: F811
    robot, operator = net["robot"], net["operator"]
    step2_notebook(tmp_path / "remote.ipynb", "rtt")
    step2_notebook(tmp_path / "local.ipynb", "rtt_local")
    on(procs, robot, "tutorial.tools.rtt_joy", "--demo")
    env = {
        "ROS_AUTOMATIC_DISCOVERY_RANGE": "SUBNET",  # the robot host's own subnet: nothing else is on it
        "PYTHONPATH": str(ROOT),
        "RTT_TEST_MODE": None,  # a run lasts until the kernel stops, as for a learner
    }
    with JupyterLab(tmp_path, env=env, ip=robot.address, prefix=robot.command([])) as lab:
        results = {}
        for where, host, name in (("another host", operator, "remote"), ("the kernel's host", robot, "local")):
            got = browse(host, lab.notebook_url(f"{name}.ipynb", workspace=name), robot.address)
            print(f"browser on {where}: {got}")
            results[where] = got
            lab.note_processes()
    for where, got in results.items():
        assert got["moved"] > 200 and got["moved_after"] > 200, f"{where}: the view did not move: {got}"
        assert got["fps"] >= 10, f"{where}: the view drew {got['fps']} frames/s from the kernel"
        assert max(got["cell_ms"]) < 1000, f"{where}: a trivial cell took {got['cell_ms']} ms"
        assert got["reload_s"] < 5, f"{where}: the scene came {got['reload_s']} s after the reload"
        assert got["dropped"] == 0, f"{where}: the view dropped {got['dropped']} frames"
