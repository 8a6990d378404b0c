"""The parts of the checks of notebook 10 that whole answers do not pin down: no ROS node.

The exercises' tests (tests/test_exercises.py) run each check on worked
solutions and on wrong answers.  These hold a hidden case's draws to what its
label tells the learner (found by make mutate: mutants of the draws survived
the whole answers, which fail on some step of a sequence however it is drawn).
"""

from __future__ import annotations

import math
import random

import pytest

from tutorial.exercises import parameters_and_services as step10

pytestmark = pytest.mark.unit

SEEDS = range(300)


@pytest.mark.parametrize("meddled", [False, True], ids=["alone", "meddled"])
def test_10_2_a_hidden_sequence_is_4_to_8_requests_either_way_from_either_start(meddled):
    drawn = [step10._hidden_sequence(random.Random(seed), meddled) for seed in SEEDS]
    assert {start for start, _ in drawn} == {True, False}
    assert all(type(start) is bool for start, _ in drawn)
    assert {len(steps) for _, steps in drawn} == set(range(4, 9))
    requests = [step for _, steps in drawn for step in steps]
    assert all(type(data) is bool and type(turned) is bool for data, turned in requests)
    assert {data for data, _ in requests} == {True, False}
    if not meddled:
        assert not any(turned for _, turned in requests)  # "a drawn sequence": nobody else turns the switch
        return
    # "also turned by another thread between requests": before at least one request of each sequence, and not
    # before every request drawn (a sequence may still be turned before each of its own), before requests of both
    # kinds, and sometimes before the first
    assert all(any(turned for _, turned in steps) for _, steps in drawn)
    assert not all(turned for _, turned in requests)
    assert {data for data, turned in requests if turned} == {True, False}
    assert any(steps[0][1] for _, steps in drawn) and any(not steps[0][1] for _, steps in drawn)


@pytest.mark.parametrize("last", [False, True], ids=["anywhere", "last"])
def test_10_1_a_rate_among_others_has_1_to_3_of_them_far_out_and_the_rate_once_anywhere(last):
    # the hidden cases leave last at its default unless they put the rate last
    lists = [step10._among(random.Random(seed), 25.0, **({"last": True} if last else {})) for seed in SEEDS]
    assert all([p.name for p in params].count(step10.RATE) == 1 for params in lists)
    others = [[p for p in params if p.name != step10.RATE] for params in lists]
    assert {len(o) for o in others} == ({2, 3} if last else {1, 2, 3})
    assert {p.name for o in others for p in o} == set(step10.OTHERS)
    values = [p.value for o in others for p in o]
    assert {v for v in values if not math.isnan(v)} == {-1.0, 5000.0} and any(math.isnan(v) for v in values)
    places = {[p.name for p in params].index(step10.RATE) - len(params) for params in lists}  # from the end
    assert places == ({-1} if last else {-1, -2, -3, -4})  # last, or anywhere: first, between, last
    assert not last or all(len(params) >= 3 for params in lists)


def test_10_1_the_hidden_cases_are_hairs_past_either_end_a_rate_inside_and_anothers_rate_far_out():
    drawn = [step10._hidden_10_1(random.Random(seed)) for seed in SEEDS]
    assert all([label for label, _, _ in cases] == [label for label, _, _ in drawn[0]] for cases in drawn)
    by_label = {label: [cases[i][1] for cases in drawn] for i, (label, _, _) in enumerate(drawn[0])}
    (above,) = {tuple((p.name, p.value) for p in params) for params in by_label["a rate a hair above the highest"]}
    (below,) = {tuple((p.name, p.value) for p in params) for params in by_label["a rate a hair below zero"]}
    # the floats next to either end, past it: any tolerance lets them in
    assert above == ((step10.RATE, math.nextafter(step10.MAX_RATE, math.inf)),)
    assert below == ((step10.RATE, -math.ulp(0.0)),) and below[0][1] < 0.0
    inside = [params for params in by_label["a rate anywhere inside the range"]]
    assert all(len(params) == 1 and params[0].name == step10.RATE for params in inside)
    assert all(0.0 <= params[0].value <= step10.MAX_RATE for params in inside)
    another = by_label["another controller's rate far out of range"]
    assert all(len(params) == 1 for params in another)
    assert {params[0].name for params in another} == set(step10.OTHERS[:2])  # controllers' rates, named like ours
    assert all(2 * step10.MAX_RATE <= params[0].value <= 9 * step10.MAX_RATE for params in another)
    good = [
        next(p.value for p in params if p.name == step10.RATE)
        for params in by_label["a good rate among other parameters set together"]
    ]
    assert all(0.0 <= value <= step10.MAX_RATE for value in good)
    for label in ("a bad rate among other parameters set together", "a bad rate after several other parameters"):
        bad = [next(p.value for p in params if p.name == step10.RATE) for params in by_label[label]]
        assert not any(step10._rate_ok(value) for value in bad), label
