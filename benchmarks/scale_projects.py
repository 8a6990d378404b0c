"""The scale runs' worlds: their sizes and publish rate, and the project files written for each size."""

from __future__ import annotations

from pathlib import Path

from benchmarks.arm_model import JOINT_COUNTS
from benchmarks.paths import ROOT

SCALE_TANKS = (1, 2, 4, 8)
SCALE_JOINTS = JOINT_COUNTS  # model/arm<N>.xml
SCALE_RATE = 50.0  # Hz: the Step 2 publisher's default, every body of the scale runs
# Where the tanks of an N-tank world start (x, y in m): in two rows across the 6 m room,
# clear of its crates and pillar and of each other.
TANK_POSITIONS = (
    (-2.1, -0.6),
    (-0.7, 0.6),
    (0.7, -0.6),
    (2.1, 0.6),
    (-2.1, 0.6),
    (-0.7, -0.6),
    (0.7, 0.6),
    (2.1, -0.6),
)

# The controllers of the generated projects: (name, "module:Class").
STEP_CLOCK = ("StepClock", "benchmarks.probes:StepClock")
STEP1 = ("RttTankController", "tutorial.controllers.tank_controller:RttTankController")
STEP2 = ("RttJointStatePublisher", "tutorial.controllers.joint_state_publisher:RttJointStatePublisher")
SWING = ("SwingController", "tests.fixtures.swing_controller:SwingController")
MONITOR = ("RttJointStateMonitor", "benchmarks.probes:ProbedJointStateSubscriber")
SIMULATOR = {"time_step": 0.001, "realtime_sync": True}


def write_yaml(path: Path, project: dict) -> Path:
    """``project`` written to ``path`` as YAML, keys in their order; returns ``path``."""
    import yaml

    path.write_text(yaml.safe_dump(project, sort_keys=False))
    return path


def _controllers(*entries: tuple[str, str]) -> list[dict]:
    return [{"name": name, "class": cls} for name, cls in entries]


def tanks_projects(n: int, directory: Path) -> tuple[Path, Path]:
    """Project files of an N-tank world (the room, tanks ``Tank1``...) and of a viewer of all N.

    Each tank has its Step 1 controller and Step 2 publisher; the first also
    has the step clock, which runs first in every step.
    """
    tank = str(ROOT / "model" / "tank.xml")
    sim_models = [{"name": "Room", "file": str(ROOT / "model" / "room.xml")}]
    view_models = []
    for i, (x, y) in enumerate(TANK_POSITIONS[:n]):
        place = {"name": f"Tank{i + 1}", "file": tank, "position": [x, y, 0.0]}
        sim_models.append({**place, "controllers": _controllers(*([STEP_CLOCK] if i == 0 else []), STEP1, STEP2)})
        view_models.append({**place, "position": list(place["position"]), "controllers": _controllers(MONITOR)})
    sim = write_yaml(
        directory / f"tanks{n}_sim.yaml",
        {"name": f"bench_tanks{n}_sim", "models": sim_models, "simulator": dict(SIMULATOR)},
    )
    view = write_yaml(directory / f"tanks{n}_view.yaml", {"name": f"bench_tanks{n}_view", "models": view_models})
    return sim, view


def arm_projects(joints: int, directory: Path) -> tuple[Path, Path]:
    """Project files of one ``model/arm<joints>.xml`` arm swinging (step clock, sine PD, publisher) and its viewer."""
    arm = {"name": f"Arm{joints}", "file": str(ROOT / "model" / f"arm{joints}.xml")}
    sim = write_yaml(
        directory / f"arm{joints}_sim.yaml",
        {
            "name": f"bench_arm{joints}_sim",
            "models": [{**arm, "controllers": _controllers(STEP_CLOCK, SWING, STEP2)}],
            "simulator": dict(SIMULATOR),
        },
    )
    view = write_yaml(
        directory / f"arm{joints}_view.yaml",
        {"name": f"bench_arm{joints}_view", "models": [{**arm, "controllers": _controllers(MONITOR)}]},
    )
    return sim, view
