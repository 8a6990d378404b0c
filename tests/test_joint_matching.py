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


def test_a_following_joint_is_ignored_not_rejected(tank):
    """A mimic joint (``Body.following``), which joint_state_publisher sends too: neither applied nor rejected;
    a name the body does not have at all is still an unknown name."""
    r = match_joint_state(tank.joint_infos, ["TURRET_Y", "finger_2", "finger_3"], [0.5, 0.1, 0.2], {"finger_2"})
    assert r.applied == {"TURRET_Y": 0.5} and r.ignored == ["finger_2"]
    assert r.rejected == [(2, "finger_3", "unknown_name")]
    assert match_joint_state(tank.joint_infos, ["finger_2"], [0.1]).counts() == {"unknown_name": 1}


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
        r = match_joint_state(tank.joint_infos, names, positions, following={"X"})
        assert r.matched + len(r.rejected) + len(r.ignored) == max(len(names), len(positions))
        assert set(r.counts()) <= set(REASONS)
        assert all(math.isfinite(v) for v in r.applied.values())


@pytest.fixture(scope="module")
def mixed(tmp_path_factory):
    """A limited hinge, an unlimited hinge and a limited slide: what the tank alone does not have."""
    path = tmp_path_factory.mktemp("mixed") / "mixed.xml"
    path.write_text(
        """<mujoco model="mixed"><compiler angle="radian"/><worldbody><body name="base">
  <joint name="pan" type="hinge" range="-1 1" limited="true"/>
  <geom type="box" size="0.1 0.1 0.1"/>
  <body name="spinner" pos="0 0 0.3"><joint name="spin" type="hinge" limited="false"/>
    <geom type="box" size="0.05 0.05 0.05"/>
    <body name="carriage" pos="0 0 0.2"><joint name="lift" type="slide" range="0 0.5" limited="true"/>
      <geom type="box" size="0.02 0.02 0.02"/></body></body></body></worldbody></mujoco>"""
    )
    model = build_world([ModelEntry("Mixed", path)])
    return Body(model, mujoco.MjData(model), "Mixed")


# A table written by hand (not by match_joint_state): (names, positions, applied, rejected reasons by entry).
HAND_TABLE = [
    # limits, with their tolerance: 0.05 rad for a hinge, 0.01 m for a slide, at both ends
    (["pan"], [-1.0 - 0.049], {"pan": -1.049}, {}),
    (["pan"], [-1.0 - 0.051], {}, {0: "out_of_range"}),
    (["pan"], [1.0 + 0.049], {"pan": 1.049}, {}),
    (["pan"], [1.0 + 0.051], {}, {0: "out_of_range"}),
    (["lift"], [-0.009], {"lift": -0.009}, {}),
    (["lift"], [-0.011], {}, {0: "out_of_range"}),
    (["lift"], [0.509], {"lift": 0.509}, {}),
    (["lift"], [0.511], {}, {0: "out_of_range"}),
    # an unlimited joint takes any finite value, and never an infinite one
    (["spin"], [1e6], {"spin": 1e6}, {}),
    (["spin"], [-1e6], {"spin": -1e6}, {}),
    (["spin"], [math.inf], {}, {0: "not_finite"}),
    (["spin"], [-math.inf], {}, {0: "not_finite"}),
    (["spin"], [math.nan], {}, {0: "not_finite"}),
    # a name given three times: all three rejected, the others applied
    (
        ["pan", "spin", "pan", "pan"],
        [0.1, 0.2, 0.3, 0.4],
        {"spin": 0.2},
        {0: "duplicate_name", 2: "duplicate_name", 3: "duplicate_name"},
    ),
    (["spin", "spin"], [0.1, 0.2], {}, {0: "duplicate_name", 1: "duplicate_name"}),
    # unknown names, missing positions and missing names
    (["gun", "pan"], [0.1, 0.2], {"pan": 0.2}, {0: "unknown_name"}),
    (["pan", "lift"], [0.3], {"pan": 0.3}, {1: "no_position"}),
    (["pan"], [0.3, 0.4], {"pan": 0.3}, {1: "no_name"}),
]


@pytest.mark.parametrize("names, positions, applied, rejected", HAND_TABLE)
def test_a_table_written_by_hand(mixed, names, positions, applied, rejected):
    r = match_joint_state(mixed.joint_infos, names, positions)
    assert r.applied == pytest.approx(applied)
    assert {i: reason for i, _, reason in r.rejected} == rejected
    assert set(r.missing) == {"pan", "spin", "lift"} - set(applied)


def test_a_position_that_is_not_a_number_is_rejected_never_raised(tank):
    """A buggy publisher's value that float() refuses counts as not finite; the call itself never raises."""
    r = match_joint_state(tank.joint_infos, ["TURRET_Y", "TURRET_P"], ["left", 0.2])
    assert r.applied == {"TURRET_P": 0.2} and r.rejected == [(0, "TURRET_Y", "not_finite")]
    r = match_joint_state(tank.joint_infos, ["TURRET_Y"], [object()])
    assert r.applied == {} and r.counts() == {"not_finite": 1}


def test_the_tolerance_includes_its_edge_at_both_limits(tank):
    """A position exactly the tolerance past a limit is applied (the range is closed); any further is not."""
    from tutorial.interfaces.joint_state import HINGE_TOLERANCE

    info = tank.joint("TURRET_P").info
    for edge, outward in ((info.lower - HINGE_TOLERANCE, -1e-9), (info.upper + HINGE_TOLERANCE, 1e-9)):
        assert match_joint_state(tank.joint_infos, ["TURRET_P"], [edge]).applied == {"TURRET_P": edge}
        beyond = edge + outward
        assert match_joint_state(tank.joint_infos, ["TURRET_P"], [beyond]).counts() == {"out_of_range": 1}


def test_the_original_loop_never_reads_past_an_array(tank):
    """It stops at the shortest of the model's joints, the names and the positions."""
    names, positions = ["TURRET_Y", "TURRET_P", "X"], [0.1, 0.2, 0.3]
    assert match_like_the_original(tank.joint_names, names, positions) == {0: 0.1, 1: 0.2}  # 3 entries, 2 joints
    assert match_like_the_original(tank.joint_names + ["X"], names[:2], positions) == {0: 0.1, 1: 0.2}
    assert match_like_the_original(tank.joint_names + ["X"], names, positions[:2]) == {0: 0.1, 1: 0.2}
