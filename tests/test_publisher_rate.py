"""Step 2's accumulator keeps the publish rate exact over the 1 ms step."""

import pytest

from tutorial.interfaces.timing import PeriodAccumulator


def due_steps(time_step, rate, steps):
    acc = PeriodAccumulator(time_step, rate)
    return [k for k in range(steps) if acc.tick()]


def test_50_hz_over_1_ms_is_every_20th_step_exactly():
    due = due_steps(0.001, 50.0, 100_000)  # 100 s of simulated time
    assert len(due) == 5000
    assert set(b - a for a, b in zip(due, due[1:])) == {20}


@pytest.mark.parametrize("rate", [0.0, 1000.0, 5000.0])
def test_every_step_when_rate_is_0_or_at_least_the_step_rate(rate):
    assert len(due_steps(0.001, rate, 1000)) == 1000


def test_uneven_rate_holds_on_average():
    due = due_steps(0.001, 300.0, 30_000)  # period 3.333 ms: steps of 3 and 4
    assert len(due) == pytest.approx(9000, abs=1)
    assert set(b - a for a, b in zip(due, due[1:])) <= {3, 4}
