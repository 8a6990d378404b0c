"""The library's layers are import-linter's contracts (``pyproject.toml``, ``[tool.importlinter]``).

``make lint`` runs ``lint-imports`` on the tree.  These tests prove that each
contract catches what it claims: a copy of the library is given one wrong
import, and ``lint-imports`` must report that contract broken, naming the
import; the copy without it must pass.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.unit

ROOT = Path(__file__).resolve().parent.parent
LINT_IMPORTS = Path(sys.executable).with_name("lint-imports")


def lint_imports(tree: Path) -> subprocess.CompletedProcess:
    """``lint-imports`` run in ``tree`` (its cwd is first on the path, so the copy is what it reads)."""
    return subprocess.run(
        [str(LINT_IMPORTS), "--no-cache", "--no-logo"],
        cwd=tree,
        capture_output=True,
        text=True,
        timeout=120,
    )


@pytest.fixture(scope="module")
def pristine(tmp_path_factory) -> Path:
    """A copy of the library, the benchmarks' package marker and the contracts."""
    tree = tmp_path_factory.mktemp("layers")
    shutil.copytree(ROOT / "tutorial", tree / "tutorial", ignore=shutil.ignore_patterns("__pycache__"))
    (tree / "benchmarks").mkdir()
    (tree / "benchmarks" / "__init__.py").write_text("")
    shutil.copy(ROOT / "pyproject.toml", tree / "pyproject.toml")
    return tree


@pytest.fixture
def tree(pristine, tmp_path) -> Path:
    copy = tmp_path / "tree"
    shutil.copytree(pristine, copy)
    return copy


def test_the_library_keeps_every_contract(pristine):
    run = lint_imports(pristine)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "Contracts: 6 kept, 0 broken." in run.stdout, run.stdout


# (module given the import, the import, the contract's name as reported, the import as reported: a
# cycle is reported within its package, ".reader -> .info")
WRONG = [
    (
        "tutorial/core/controller.py",
        "from tutorial.view.meshcat_overlays import MeshcatOverlays",
        "The library's layers",
        "tutorial.core.controller -> tutorial.view.meshcat_overlays",
    ),
    (
        "tutorial/interfaces/tf.py",
        "from tutorial.tools.bag.qos import profile_dict",
        "The library's layers",
        "tutorial.interfaces.tf -> tutorial.tools.bag.qos",
    ),
    (
        "tutorial/app/app.py",
        "from tutorial.notebook.session import TEST_MODE",
        "The library's layers",
        "tutorial.app.app -> tutorial.notebook.session",
    ),
    (
        # one layer's packages are independent: the view does not read URDF
        "tutorial/view/scene.py",
        "from tutorial.tools.urdf.frames import pose_matrix",
        "The library's layers",
        "tutorial.view.scene -> tutorial.tools.urdf.frames",
    ),
    (
        # an import inside a function counts too
        "tutorial/core/simulator.py",
        "def _late():\n    from tutorial.controllers.joint_state_publisher import RttJointStatePublisher",
        "The library's layers",
        "tutorial.core.simulator -> tutorial.controllers.joint_state_publisher",
    ),
    (
        "tutorial/controllers/imu_state_subscriber.py",
        "from .imu_state_publisher import find_imu",
        "A step never imports another step",
        "tutorial.controllers.imu_state_subscriber -> tutorial.controllers.imu_state_publisher",
    ),
    (
        "tutorial/exercises/step5_imu_viewer.py",
        "from tutorial.exercises.step4_imu_publisher import check_peak_publisher",
        "A notebook's checks never import another notebook's",
        "tutorial.exercises.step5_imu_viewer -> tutorial.exercises.step4_imu_publisher",
    ),
    (
        # the layers allow it (a notebook's helper above the URDF tools): the lessons never import the tooling
        "tutorial/notebook/live.py",
        "from tutorial.tools.urdf.frames import pose_matrix",
        "The lessons' library never imports the tooling",
        "tutorial.notebook.live -> tutorial.tools.urdf.frames",
    ),
    (
        # nor a lesson of notebooks 07 to 09 a tool other than the one it teaches
        "tutorial/notebook/two_hosts.py",
        "from tutorial.tools.bag.reader import iter_raw",
        "The lessons' library never imports the tooling",
        "tutorial.notebook.two_hosts -> tutorial.tools.bag.reader",
    ),
    (
        "tutorial/view/status.py",
        "import benchmarks",
        "The library imports neither the tests nor the benchmarks",
        "tutorial.view.status -> benchmarks",
    ),
    (
        "tutorial/tools/bag/reader.py",
        "from tutorial.tools.bag.info import bag_info",
        "No cycles",
        ".reader -> .info",
    ),
]


@pytest.mark.parametrize("module, line, contract, reported", WRONG, ids=[w[0] for w in WRONG])
def test_a_wrong_import_breaks_its_contract(tree, module, line, contract, reported):
    path = tree / module
    path.write_text(path.read_text(encoding="utf-8") + "\n\n" + line + "  # noqa\n", encoding="utf-8")
    run = lint_imports(tree)
    assert run.returncode != 0, run.stdout
    broken = " ".join(run.stdout.split("Broken contracts", 1)[-1].split())  # lint-imports wraps long lines
    assert contract in broken, run.stdout
    assert reported in broken, run.stdout
    # a wrong import between packages may make a cycle between them too, so no "1 broken" here
