"""The one step controller: cut-backs, growth policies and their bounds."""

import math

import pytest

from beamfx.solvers.step_control import (
    EasyGrowth,
    ErrorBased,
    IterationRatio,
    StepControl,
    StepTooSmall,
)


def test_easy_growth_needs_a_run_of_easy_clean_steps_and_stops_at_largest():
    c = StepControl(0.1, 0.2, 1e-3, EasyGrowth(1.5, easy=4, run=2, clean=True))
    assert c.accepted(3) == 0.1  # one easy step: not yet
    assert c.accepted(3) == pytest.approx(0.15)  # two in a row
    assert c.accepted(3, cutbacks=1) == pytest.approx(0.15)  # a cut-back step never grows
    assert c.accepted(5) == pytest.approx(0.15)  # a hard step breaks the run
    c.accepted(2)
    assert c.accepted(2) == pytest.approx(0.2)  # capped: 0.225 > largest


def test_halving_raises_below_the_smallest_step():
    c = StepControl(0.1, 0.1, 0.03, EasyGrowth())
    assert c.rejected() == pytest.approx(0.05)
    with pytest.raises(StepTooSmall):
        c.rejected()


def test_iteration_ratio_is_crisfields_rule_within_bounds():
    c = StepControl(1.0, 10.0, 1e-3, IterationRatio(desired=4, least=0.5, most=2.0))
    assert c.accepted(1) == pytest.approx(2.0)  # sqrt(4) = 2
    assert c.accepted(16) == pytest.approx(1.0)  # sqrt(1/4) = 0.5
    assert c.accepted(9) == pytest.approx(1.0 * math.sqrt(4 / 9))


def test_error_based_sizes_both_ways_and_stops_at_smallest():
    c = StepControl(0.01, 0.02, 0.001, ErrorBased(order=2, safety=0.9))
    assert c.rejected(error=8.0) == pytest.approx(0.01 * 0.45)  # 0.9 * 8^(-1/3)
    assert c.rejected(error=1e6) == pytest.approx(0.001)  # floor 0.2, then smallest
    assert c.accepted(3, error=1e-12) == pytest.approx(0.002)  # at most doubled
    assert c.accepted(3, error=1.0) == pytest.approx(0.0018)


def test_a_halving_past_the_smallest_step_tries_the_smallest_itself_first():
    """With reach_smallest (the time steps'), 10 -> ... -> 0.0195 -> 0.01 (dt_min), then
    StepTooSmall: the smallest step allowed is the last one tried (it stopped at 0.0195 and
    the failure said "down to dt_min = 0.01")."""
    c = StepControl(10.0, 10.0, 0.01, EasyGrowth(), reach_smallest=True)
    sizes = [c.size]
    with pytest.raises(StepTooSmall):
        while True:
            sizes.append(c.rejected())
    assert sizes[-2] == pytest.approx(10.0 / 2**9) and sizes[-1] == 0.01
    assert len(sizes) == 11
    exact = StepControl(0.08, 0.08, 0.01, EasyGrowth(), reach_smallest=True)
    assert [exact.rejected(), exact.rejected(), exact.rejected()] == [0.04, 0.02, 0.01]
    with pytest.raises(StepTooSmall):  # a halving that lands on it: no second try
        exact.rejected()
