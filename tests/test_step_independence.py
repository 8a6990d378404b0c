"""Editing one step's lesson module changes no other step.

A lesson module (``tutorial/controllers/``) is what one notebook builds,
written from it by ``make export``.  Later steps stand on the frozen copies in
``tutorial/app/reference/`` (``scripts/freeze_reference.py``), and run earlier
steps' projects as ``project/reference/*.yaml``.  These tests read everything
that could reach a lesson module and fail on any that is not its own step:

* the library's imports, at any depth and inside functions (grimp, the graph
  import-linter builds; the ``steps`` and ``checks`` contracts keep lesson
  modules and checks apart from each other);
* each notebook's code cells: what they import and the project files they load;
* each project file: the classes it names, which ``tutorial.core.project``
  imports by name where no import statement shows them;
* each launch file: the project files it runs.

Each rule is also shown catching a wrong reference.  Not held here: the
terminal commands in the notebooks' text (``rtt-run project/step2.yaml``),
which run the learner's own earlier steps, as the original tutorial's
terminals do.
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import grimp
import pytest

pytestmark = pytest.mark.unit

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))
import library_size  # noqa: E402  (scripts/: what a notebook imports and loads, read as the size script reads it)

LESSON = "tutorial.controllers."
# step (its notebook's number) -> the lesson module its notebook builds, and its checks' modules
STEPS = {
    "01": ("tank_controller", ["step1_tank_controller"]),
    "02": ("joint_state_publisher", ["step2_joint_state_publisher"]),
    "03": ("joint_state_subscriber", ["step3_viewer"]),
    "04": ("imu_state_publisher", ["step4_imu_publisher"]),
    "05": ("imu_state_subscriber", ["step5_imu_viewer"]),
    "06": ("camera_image_publisher", ["step6_camera", "camera_rig"]),
    "07": (None, ["record_and_replay"]),
    "08": (None, ["across_machines"]),
    "09": ("robot_model_publisher", ["stock_ros2_tools"]),
    "10": ("tunable_tank_controller", ["parameters_and_services"]),
    "11": ("managed_tank_controller", ["managed_nodes_and_actions"]),
}


@pytest.fixture(scope="module")
def graph():
    return grimp.build_graph("tutorial", include_external_packages=False)


def lessons_reached(graph, module: str) -> set[str]:
    """The lesson modules (short names) ``module`` imports, directly or not."""
    return {m.removeprefix(LESSON) for m in graph.find_upstream_modules(module) if m.startswith(LESSON)}


def test_every_lesson_module_is_built_by_the_notebook_of_its_step():
    built = {}
    for path in sorted((ROOT / "tutorial" / "controllers").glob("*.py")):
        if path.name == "__init__.py":
            continue
        header = path.read_text(encoding="utf-8").splitlines()[0]
        found = re.search(r"notebooks/(\d\d)_\w+\.ipynb", header)
        assert found, f"{path.name}: not written from a notebook ({header!r})"
        built[path.stem] = found.group(1)
    assert built == {lesson: step for step, (lesson, _) in STEPS.items() if lesson}


def test_no_check_imports_a_lesson_module(graph):
    """A check judges by the frozen references of ``app/reference`` (its own step's too), never a lesson module:
    so re-exporting a notebook changes no grade, and the lessons' library holds no lesson module for a check's sake."""
    wrong = {}
    for _, checks in STEPS.values():
        for check in checks:
            reached = lessons_reached(graph, f"tutorial.exercises.{check}")
            if reached:
                wrong[check] = sorted(reached)
    assert not wrong, f"checks that reach a lesson module: {wrong}"


def test_nothing_else_in_the_library_imports_a_lesson_module(graph):
    """The frozen references, the programs, the notebooks' helpers and the checks' machinery included."""
    checks = {f"tutorial.exercises.{c}" for _, cs in STEPS.values() for c in cs}
    wrong = {
        m: sorted(lessons_reached(graph, m))
        for m in graph.modules
        if not m.startswith(LESSON) and m not in checks and lessons_reached(graph, m)
    }
    assert not wrong, f"modules that import a lesson module (use tutorial/app/reference/): {wrong}"


# ---- notebooks, project files, launch files: what names or loads a lesson -------------------------------


def project_file_lessons(text: str) -> set[str]:
    """The lesson modules a project file's ``class:`` entries name."""
    return set(re.findall(r"""class:\s*["']?tutorial\.controllers\.(\w+):""", text))


def step_of_project(name: str) -> str | None:
    """The step a project file is the own project of (``step3_description.yaml``: 03); None for the rest.

    A template (``tank_world.yaml``) or a later step's copy (``reference/step2.yaml``) is no step's own.
    """
    found = re.fullmatch(r"step(\d+)(?:_\w+)?\.yaml", name)
    return f"{int(found.group(1)):02d}" if found else None


def notebook_violations(step: str, sources: list[str]) -> list[str]:
    """What step ``step``'s notebook, of code cells ``sources``, reaches of another step."""
    wrong = []
    for source in sources:
        imported = library_size._imports_of_code(source)  # "from m import n" gives m and m.n: one module each
        lessons = {m.removeprefix(LESSON).split(".")[0] for m in imported if m.startswith(LESSON)}
        wrong += [f"imports {LESSON}{lesson}" for lesson in sorted(lessons - {STEPS[step][0]})]
        for name in sorted(library_size.project_files(source)):
            owner = step_of_project(name)
            if owner is not None and owner != step:
                wrong.append(f"loads {name} (Step {owner}'s own project)")
    return wrong


def notebook_sources(path: Path) -> list[str]:
    cells = json.loads(path.read_text(encoding="utf-8"))["cells"]
    return ["".join(c["source"]) for c in cells if c["cell_type"] == "code"]


@pytest.mark.parametrize("step", sorted(STEPS))
def test_a_notebook_imports_and_loads_only_its_own_step(step):
    (path,) = (ROOT / "notebooks").glob(f"{step}_*.ipynb")
    assert notebook_violations(step, notebook_sources(path)) == []


@pytest.mark.parametrize(
    "source, wrong",
    [
        (
            "from tutorial.controllers.tank_controller import RttTankController",
            ["imports tutorial.controllers.tank_controller"],
        ),
        ("import tutorial.controllers.tank_controller as tc", ["imports tutorial.controllers.tank_controller"]),
        ('sim = BackgroundApp("step2.yaml", node_name="rtt")', ["loads step2.yaml (Step 02's own project)"]),
        ('lab.simulation("robot", "project/step6.yaml")', ["loads step6.yaml (Step 06's own project)"]),
        ('load("../project/step4.yaml")', ["loads step4.yaml (Step 04's own project)"]),
        ("from tutorial.app.reference.tank_controller import RttTankController", []),
        ('BackgroundApp("reference/step2.yaml")\nload("tank_view.yaml")\nload("step3_description.yaml")', []),
    ],
)
def test_the_notebook_rule_catches_another_steps_lesson_or_project(source, wrong):
    assert notebook_violations("03", [source]) == wrong


def project_violations(name: str, text: str) -> set[str]:
    """The lesson modules project file ``name`` names that are not its step's own (all, for a non-step file)."""
    owner = step_of_project(name)
    return project_file_lessons(text) - ({STEPS[owner][0]} if owner else set())


def test_a_project_file_names_only_its_own_steps_lesson():
    files = sorted((ROOT / "project").rglob("*.yaml"))
    assert len(files) >= 12
    wrong = {
        str(p.relative_to(ROOT)): sorted(project_violations(str(p.relative_to(ROOT / "project")), p.read_text("utf-8")))
        for p in files
    }
    assert {k: v for k, v in wrong.items() if v} == {}
    # each step's own project names its own lesson: the check above is not vacuous
    for step, (lesson, _) in STEPS.items():
        path = ROOT / "project" / f"step{int(step)}.yaml"
        if path.exists():
            assert project_file_lessons(path.read_text("utf-8")) == {lesson}, path.name


def test_the_project_rule_catches_another_steps_class():
    step2 = (ROOT / "project" / "step2.yaml").read_text("utf-8")
    unfrozen = step2.replace("tutorial.app.reference.tank_controller:", "tutorial.controllers.tank_controller:")
    assert project_violations("step2.yaml", step2) == set()
    assert project_violations("step2.yaml", unfrozen) == {"tank_controller"}
    assert project_violations("reference/step2.yaml", step2) == {"joint_state_publisher"}
    assert project_violations("tank_world.yaml", "class: tutorial.controllers.tank_controller:X") == {"tank_controller"}
    assert project_violations("step5.yaml", "class: 'tutorial.controllers.tank_controller:X'") == {"tank_controller"}


@pytest.mark.parametrize("path", sorted((ROOT / "launch_py").glob("step*_launch.py")), ids=lambda p: p.name)
def test_a_launch_file_runs_only_its_own_steps_project(path):
    step = step_of_project(path.name.replace("_launch.py", ".yaml"))
    loaded = library_size.project_files(path.read_text("utf-8"))
    assert loaded, f"{path.name} runs no project file"
    assert {n for n in loaded if step_of_project(n) not in (None, step)} == set()
