"""Models that other packages ship: every hinge and slide joint is numbered or skipped with
a reason, and a viewer mirrors a simulation of each.

The models come from MuJoCo's own test data and from gymnasium's and dm_control's
MuJoCo assets (test-only dependencies).  They were picked to cover what our own
models do not: unnamed links and joints, ball and free joints, slides, several
top-level bodies, geoms fixed to the world, relative includes and mesh directories,
actuators on tendons and sites, and joints in group 3.  Every check counts from
``mujoco.MjModel.from_xml_path`` of the file on its own, not from ``Body``.
"""

from __future__ import annotations

import importlib.util
import time
from dataclasses import dataclass
from pathlib import Path

import mujoco
import pytest

from tutorial.core.body import MECHANISM_JOINT_GROUP, Body
from tutorial.core.world import ModelEntry, build_world

from conftest import MODEL

HINGE_SLIDE = (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE))
REASON_START = {
    int(mujoco.mjtJoint.mjJNT_FREE): "free joint",
    int(mujoco.mjtJoint.mjJNT_BALL): "ball joint",
}


@dataclass(frozen=True)
class Case:
    """A model file in an installed package, and facts counted from that file."""

    name: str  # the body name in the world
    package: str
    path: str  # inside the package
    hinge_slide: int  # hinge + slide joints in the file
    numbered: int  # of those, how many a JointState carries (the rest are in joint group 3)
    what: str  # why it is here

    def file(self) -> Path:
        spec = importlib.util.find_spec(self.package)
        if spec is None or not spec.submodule_search_locations:
            pytest.skip(f"{self.package} is not installed (pip install -e '.[test]')")
        return Path(spec.submodule_search_locations[0]) / self.path


CASES = [
    Case(
        "Ant",
        "gymnasium",
        "envs/mujoco/assets/ant.xml",
        8,
        8,
        "four unnamed links (the feet) under named ones; a free root",
    ),
    Case(
        "Pusher",
        "gymnasium",
        "envs/mujoco/assets/pusher.xml",
        11,
        11,
        "three top-level bodies: an arm, and an object and a goal on slides",
    ),
    Case(
        "Hopper",
        "gymnasium",
        "envs/mujoco/assets/hopper.xml",
        6,
        6,
        "a planar robot: two slides and a hinge as its root",
    ),
    Case("Humanoid", "gymnasium", "envs/mujoco/assets/humanoid.xml", 17, 17, "17 motorised hinges, a free root"),
    Case(
        "MujocoTest",
        "mujoco",
        "testdata/model.xml",
        10,
        10,
        "unnamed links and joints, a ball, a slide, five free bodies, six top-level bodies, "
        "an unnamed world geom, actuators on tendons and a site",
    ),
    Case(
        "Quadruped",
        "dm_control",
        "suite/quadruped.xml",
        16,
        16,
        "relative includes, two top-level bodies with free joints",
    ),
    Case(
        "Manipulator",
        "dm_control",
        "suite/manipulator.xml",
        14,
        14,
        "seven top-level bodies, slides and hinges, includes",
    ),
    Case(
        "Dog",
        "dm_control",
        "suite/dog.xml",
        73,
        30,
        "meshes from an asset directory; 43 spine and tail hinges in joint group 3",
    ),
    Case(
        "BallJoints",
        "dm_control",
        "mujoco/testing/assets/model_with_ball_joints.xml",
        0,
        0,
        "unnamed links, ball joints only",
    ),
    Case(
        "ThirdOrder",
        "dm_control",
        "mujoco/testing/assets/model_with_third_order_actuators.xml",
        1,
        1,
        "an unnamed link on a slide with four kinds of actuator",
    ),
]
IDS = [c.name for c in CASES]


def file_joint_names(model: mujoco.MjModel) -> list[str]:
    """Each joint's name in a model loaded alone: its own, or ``joint<id>`` (the documented rule).

    None of these files names a joint ``joint<id>`` of another joint's id, so the
    rule's collision suffix does not come up here (tests/test_body.py covers it).
    """
    return [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) or f"joint{j}" for j in range(model.njnt)]


@pytest.fixture(scope="module")
def loaded():
    """Case name -> (the file loaded alone, the world built from it, its Body), built once."""
    cache = {}

    def load(case: Case):
        if case.name not in cache:
            path = case.file()
            alone = mujoco.MjModel.from_xml_path(str(path))
            world = build_world([ModelEntry(case.name, path)])
            cache[case.name] = alone, world, Body(world, mujoco.MjData(world), case.name)
        return cache[case.name]

    return load


@pytest.mark.parametrize("case", CASES, ids=IDS)
def test_every_hinge_and_slide_joint_is_numbered_or_skipped_with_a_reason(case, loaded):
    alone, _, body = loaded(case)
    names = file_joint_names(alone)
    hinge_slide = [j for j in range(alone.njnt) if alone.jnt_type[j] in HINGE_SLIDE]
    assert len(hinge_slide) == case.hinge_slide  # the file is the one this test was written for
    # Every joint of the file is numbered or skipped, never both, never lost.
    assert set(body.joint_names).isdisjoint(body.skipped_joints)
    assert sorted([*body.joint_names, *body.skipped_joints]) == sorted(names)
    numbered = [j for j in hinge_slide if alone.jnt_group[j] != MECHANISM_JOINT_GROUP]
    assert body.joint_names == [names[j] for j in numbered]  # in model order
    assert body.num_joints == case.numbered
    for j in range(alone.njnt):
        reason = body.skipped_joints.get(names[j])
        if j in numbered:
            assert reason is None
        elif alone.jnt_type[j] in HINGE_SLIDE:
            assert reason.startswith("joint group 3"), (names[j], reason)
        else:
            assert reason.startswith(REASON_START[int(alone.jnt_type[j])]), (names[j], reason)
    # What the publisher sends: no name is empty, none twice.
    assert all(body.joint_names) and len(set(body.joint_names)) == len(body.joint_names)
    for info in body.joint_infos:  # the numbered joint is the file's joint, with its range
        j = names.index(info.name)
        assert info.kind == ("slide" if alone.jnt_type[j] == int(mujoco.mjtJoint.mjJNT_SLIDE) else "hinge")
        assert info.limited == bool(alone.jnt_limited[j])
        if info.limited:
            assert (info.lower, info.upper) == pytest.approx(tuple(alone.jnt_range[j]))


@pytest.mark.parametrize("case", CASES, ids=IDS)
def test_the_body_owns_every_element_of_its_model(case, loaded):
    alone, world, body = loaded(case)
    assert len(body.body_ids) == alone.nbody - 1  # all but the world body, named or not
    assert len(body.joint_ids) == alone.njnt
    assert len(body.geom_ids) == alone.ngeom
    assert len(body.site_ids) == alone.nsite
    assert len(body.actuator_ids) == alone.nu
    assert world.nu == alone.nu and world.ngeom == alone.ngeom  # nothing of the file was left out of the world
    top_level = sum(1 for b in range(1, alone.nbody) if alone.body_parentid[b] == 0)
    assert len(body.root_ids) == top_level


def test_models_in_one_world_own_disjoint_parts_that_cover_it():
    """All the models and the tank in one world: each element has exactly one owner."""
    available, numbered = [], {"Tank": 2}
    for case in CASES:
        spec = importlib.util.find_spec(case.package)
        if spec is not None and spec.submodule_search_locations:
            available.append(ModelEntry(case.name, case.file(), position=(4.0 * len(available), 0.0, 0.0)))
            numbered[case.name] = case.numbered
    entries = [ModelEntry("Tank", MODEL / "tank.xml", position=(-4.0, 0.0, 0.0)), *available]
    world = build_world(entries)
    data = mujoco.MjData(world)
    bodies = [Body(world, data, e.name) for e in entries]
    for attribute, count in (
        ("body_ids", world.nbody - 1),
        ("joint_ids", world.njnt),
        ("geom_ids", world.ngeom),
        ("site_ids", world.nsite),
        ("actuator_ids", world.nu),
    ):
        owned = [getattr(b, attribute) for b in bodies]
        assert sum(len(o) for o in owned) == count, attribute  # disjoint ...
        assert len(frozenset().union(*owned)) == count, attribute  # ... and covering
    assert {b.name: b.num_joints for b in bodies} == numbered  # as many as each has alone
    assert bodies[0].joint_names == ["TURRET_Y", "TURRET_P"]


@pytest.mark.parametrize("case", CASES, ids=IDS)
def test_the_publisher_sends_every_numbered_joint_by_name(case, loaded, node):
    from tutorial.controllers.joint_state_publisher import RttJointStatePublisher
    from tutorial.core.controller import ControllerConfig, ControllerIO

    _, world, _ = loaded(case)
    data = mujoco.MjData(world)
    body = Body(world, data, case.name)
    publisher = RttJointStatePublisher()
    assert publisher.configure(
        ControllerConfig(name="RttJointStatePublisher", body=body, node=node, parameters={"rate": 50.0})
    )
    try:
        assert publisher.initialize(ControllerIO(body=body, time_step=world.opt.timestep, node=node, data=data))
        assert publisher.topic == f"/{case.name}/joint_state"
        assert [j.name for j in publisher.joints] == body.joint_names
        assert all(j.name for j in publisher.joints)
        publisher.publish()  # a message with these names goes out without an error
    finally:
        publisher.unconfigure()


# ---- a viewer mirrors a simulation of each -----------------------------------------

SIM_YAML = """name: sim_{tag}
models:
  - name: {name}
    file: {file}
    controllers:
      - name: Swing
        class: tests.fixtures.swing_controller:SwingController
      - name: RttJointStatePublisher
        class: tutorial.controllers.joint_state_publisher:RttJointStatePublisher
        parameters: {{rate: 100}}
simulator:
  time_step: 0.001
  realtime_sync: false
"""
VIEW_YAML = """name: view_{tag}
models:
  - name: {name}
    file: {file}
    controllers:
      - name: RttJointStateMonitor
        class: tutorial.controllers.joint_state_subscriber:RttJointStateMonitor
"""
MIN_SIM_TIME = 0.5  # s: the models have moved by then
MIN_APPLIED = 3  # messages the viewer applied before the simulation is stopped: it has matched the publisher


def step_until(apps, predicate, timeout: float) -> bool:
    """Step every app (each runs its posted calls) until ``predicate()`` or ``timeout`` s; its last value."""
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            return bool(predicate())
        for app in apps:
            app.step(timeout=0.002)
    return True


@pytest.mark.parametrize("case", CASES, ids=IDS)
def test_a_viewer_mirrors_a_simulation(case, ros, tmp_path):
    """rtt-run's pieces in one process: a simulation App (SwingController and the publisher)
    and a viewer App (the subscriber) on the same model, two nodes, stepped on this thread.

    The simulation runs as fast as it can until the viewer has applied a few of its
    messages, then is stopped; the publisher sends the final state in ``stop()``.  The
    viewer must end on exactly that state (the same float64s), no entry rejected for its name.
    """
    from tutorial.app.app import App
    from tutorial.core.project import load_project

    path = case.file()
    tag = case.name.lower()
    (tmp_path / "sim.yaml").write_text(SIM_YAML.format(tag=tag, name=case.name, file=path))
    (tmp_path / "view.yaml").write_text(VIEW_YAML.format(tag=tag, name=case.name, file=path))
    records: list[dict] = []
    view = App(load_project(tmp_path / "view.yaml"), node_name=f"view_{tag}", headless=True, output=records.append)
    sim = App(load_project(tmp_path / "sim.yaml"), node_name=f"sim_{tag}", headless=True, output=records.append)
    open_apps = [view, sim]
    try:
        view.open()
        sim.open()
        subscriber = view.controller("RttJointStateMonitor")
        status = subscriber.status
        assert step_until(
            open_apps,
            lambda: status.applied >= MIN_APPLIED and sim.sim.sim_time >= MIN_SIM_TIME or sim.sim.finished.is_set(),
            timeout=60,
        ), (status.applied, sim.sim.sim_time)
        assert not sim.sim.finished.is_set(), sim.sim.error  # it was still running: nothing failed
        sim.request_stop()
        open_apps.remove(sim)
        sim.close()  # joins the simulation (whose stop() published the final state), waits for the acks
        assert sim.sim.error is None, sim.sim.error
        body = sim.bodies[case.name]
        final = body.joint_positions()  # the simulation's final state
        mirrored = step_until([view], lambda: status.last_positions == final, timeout=10)
        assert mirrored, {
            k: (final[k], status.last_positions.get(k)) for k in final if status.last_positions.get(k) != final[k]
        }
        assert view.bodies[case.name].joint_positions() == final  # and the viewer's model is in it
        # No entry is rejected for its name.  Out-of-range rejections on the way are the
        # viewer's policy working: MuJoCo's joint limits are soft, and a model may start
        # outside them (gymnasium's ant: ankles at 0 rad, range 30..70 degrees) or be
        # driven hard into them (the dog's legs) by more than the tolerance.
        assert set(status.rejections) <= {"out_of_range"}, status.rejections
        assert status.matched == len(final) == case.numbered
        moved = [i.name for i in body.joint_infos if abs(final[i.name] - sim.model.qpos0[i.qpos_adr]) > 1e-3]
        assert moved or not final, final  # the simulation really moved something
    finally:
        for app in open_apps:
            app.close()
    assert view.loop.errors == [] and sim.loop.errors == []
    assert view.spin.error is None and sim.spin.error is None


def test_ant_mirrors_across_processes(procs, tmp_path):
    """The issue's example end to end: rtt-run simulates gymnasium's ant (four unnamed feet
    links) and a second, renamed rtt-run shows it; the viewer ends on all eight hinges."""
    import json
    import signal

    from conftest import module_command

    case = CASES[0]
    path = case.file()
    (tmp_path / "sim.yaml").write_text(
        SIM_YAML.format(tag="ant", name=case.name, file=path).replace("realtime_sync: false", "realtime_sync: true")
    )
    (tmp_path / "view.yaml").write_text(VIEW_YAML.format(tag="ant", name=case.name, file=path))

    def stale(line: str) -> bool:
        return line.startswith("{") and json.loads(line).get("event") == "stale"

    view = procs(
        module_command(
            "tutorial.tools.rtt_run",
            str(tmp_path / "view.yaml"),
            "--headless",
            "--json",
            "--ros-args",
            "-r",
            "__node:=ant_viewer",
        )
    )
    # 4 s of real time: the two processes find each other well before the final state goes out.
    sim = procs(
        module_command("tutorial.tools.rtt_run", str(tmp_path / "sim.yaml"), "--headless", "--json", "--duration", "4")
    )
    stale_before = view.count(stale)
    assert sim.wait(60) == 0, sim.err
    final = sim.summary()["bodies"][case.name]["joint_positions"]
    view.wait_for_count(stale, stale_before + 1, timeout=30)  # silent since the sim ended: all applied
    view.p.send_signal(signal.SIGINT)
    assert view.wait(30) == 0, view.err
    shown = view.summary()["controllers"]["RttJointStateMonitor"]
    assert shown["topic"] == "/Ant/joint_state"
    assert set(shown["rejected"]) <= {"out_of_range"}  # the ant starts outside its ankle limits
    assert (
        sorted(final)
        == sorted(shown["last_positions"])
        == sorted(f"{leg}_{i}" for leg in ("hip", "ankle") for i in range(1, 5))
    )
    for name, q in final.items():
        assert abs(shown["last_positions"][name] - q) <= 1e-6, (name, q, shown["last_positions"][name])
