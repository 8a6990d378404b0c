"""Joint matching: every entry of a received JointState is applied or rejected for one reason."""

import math

import mujoco
import pytest

from tutorial.core.body import Body
from tutorial.core.world import ModelEntry, build_world
from tutorial.interfaces.joint_state import REASONS, match_joint_state, match_like_the_original

from conftest import MODEL


@pytest.fixture(scope="module")
def tank():
    model = build_world([ModelEntry("Tank", MODEL / "tank.xml")])
    return Body(model, mujoco.MjData(model), "Tank")


def test_in_order(tank):
    r = match_joint_state(tank.joint_infos, ["TURRET_Y", "TURRET_P"], [0.5, 0.25])
    assert r.applied == {"TURRET_Y": 0.5, "TURRET_P": 0.25}
    assert r.rejected == [] and r.missing == []


def test_reordered_matches_by_name(tank):
    r = match_joint_state(tank.joint_infos, ["TURRET_P", "TURRET_Y"], [0.25, 0.5])
    assert r.applied == {"TURRET_Y": 0.5, "TURRET_P": 0.25}
    # the original loop applies nothing to a reordered message
    assert match_like_the_original(tank.joint_names, ["TURRET_P", "TURRET_Y"], [0.25, 0.5]) == {}


def test_unknown_names_are_ignored_and_counted(tank):
    r = match_joint_state(tank.joint_infos, ["wheel", "TURRET_Y", ""], [1.0, 0.5, 2.0])
    assert r.applied == {"TURRET_Y": 0.5}
    assert r.counts() == {"unknown_name": 2}
    assert r.missing == ["TURRET_P"]


def test_duplicates_are_all_rejected(tank):
    r = match_joint_state(tank.joint_infos, ["TURRET_Y", "TURRET_P", "TURRET_Y"], [0.1, 0.2, 0.3])
    assert r.applied == {"TURRET_P": 0.2}
    assert r.counts() == {"duplicate_name": 2}


def test_short_positions_and_short_names(tank):
    r = match_joint_state(tank.joint_infos, ["TURRET_Y", "TURRET_P"], [0.1])
    assert r.applied == {"TURRET_Y": 0.1} and r.counts() == {"no_position": 1}
    r = match_joint_state(tank.joint_infos, ["TURRET_Y"], [0.1, 0.2, 0.3])
    assert r.applied == {"TURRET_Y": 0.1} and r.counts() == {"no_name": 2}
    r = match_joint_state(tank.joint_infos, [], [])
    assert r.applied == {} and r.missing == ["TURRET_Y", "TURRET_P"]


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_non_finite_rejected(tank, bad):
    r = match_joint_state(tank.joint_infos, ["TURRET_Y", "TURRET_P"], [bad, 0.2])
    assert r.applied == {"TURRET_P": 0.2} and r.counts() == {"not_finite": 1}
    # the original loop would apply the value to the model as it is
    assert match_like_the_original(tank.joint_names, ["TURRET_Y"], [bad]) == {0: bad}


def test_range_policy_reject_far_apply_near(tank):
    upper = tank.joint("TURRET_P").info.upper
    r = match_joint_state(tank.joint_infos, ["TURRET_P"], [upper + 0.01])  # pressing on the stop: applied as is
    assert r.applied == {"TURRET_P": upper + 0.01}
    r = match_joint_state(tank.joint_infos, ["TURRET_P", "TURRET_Y"], [upper + 0.5, 1e300])
    assert r.applied == {} and r.counts() == {"out_of_range": 2}


def test_every_entry_gets_exactly_one_outcome(tank):
    import random

    rng = random.Random(7)
    pool = ["TURRET_Y", "TURRET_P", "X", ""]
    values = [0.1, -0.1, math.nan, math.inf, 1e9, 0.7]
    for _ in range(2000):
        names = [rng.choice(pool) for _ in range(rng.randint(0, 6))]
        positions = [rng.choice(values) for _ in range(rng.randint(0, 6))]
        r = match_joint_state(tank.joint_infos, names, positions)
        assert r.matched + len(r.rejected) == max(len(names), len(positions))
        assert set(r.counts()) <= set(REASONS)
        assert all(math.isfinite(v) for v in r.applied.values())
