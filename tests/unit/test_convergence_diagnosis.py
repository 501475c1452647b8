"""The classification of Newton's stops (beamfx.solvers.convergence), without a solve."""

import numpy as np

from beamfx.solvers.convergence import FLOOR_FACTOR, REASONS, describe, diagnose, remedy


def records(fnorms, scale=1.0, step=1e-3, state=1.0):
    return [{"fnorm": f, "step": step, "state": state, "scale": scale} for f in fnorms]


def test_every_petsc_reason_of_the_brief_has_a_meaning():
    for name in (
        "CONVERGED_FNORM_ABS",
        "CONVERGED_FNORM_RELATIVE",
        "CONVERGED_SNORM_RELATIVE",
        "DIVERGED_MAX_IT",
        "DIVERGED_LINE_SEARCH",
        "DIVERGED_LINEAR_SOLVE",
        "DIVERGED_FNORM_NAN",
        "DIVERGED_DTOL",
    ):
        assert describe(name).startswith(f"{name} (") and REASONS[name]
    assert "floor" in REASONS["CONVERGED_SNORM_RELATIVE"]  # a floor exit is convergence


def test_causes_follow_the_residual_history_and_the_floor():
    floor = 1e-8
    stalled_at_floor = records([1.0, 1e-3, 5e-8, 4e-8, 6e-8], scale=1.0)
    stalled_at_floor[-1]["step"] = 1e-3  # increments did not settle
    assert diagnose("DIVERGED_MAX_IT", stalled_at_floor, floor)[0] == "stagnation at the floor"
    above = records([1.0, 1e-2, 2e-3, 3e-3, 2.5e-3])
    assert diagnose("DIVERGED_MAX_IT", above, floor)[0] == "stagnation above the floor"
    growing = records([1.0, 5.0, 30.0, 20.0, 50.0])
    assert diagnose("DIVERGED_MAX_IT", growing, floor)[0] == "divergence"
    slow = records([1.0, 0.3, 0.05, 0.004, 1e-4])
    assert diagnose("DIVERGED_MAX_IT", slow, floor)[0] == "max iterations"
    nan = records([1.0, np.nan])
    assert diagnose("DIVERGED_FNORM_NAN", nan, floor)[0] == "nan"
    assert diagnose("DIVERGED_LINEAR_SOLVE", above, floor)[0] == "linear solve"
    assert diagnose("DIVERGED_LINE_SEARCH", above, floor)[0] == "line search"


def test_a_floor_far_above_the_forces_is_named_and_remedied():
    big = records([1e3, 2e2, 1.1e2, 1.2e2, 1.0e2], scale=1e6)  # 1e-4 of the forces
    cause, detail = diagnose("DIVERGED_MAX_IT", big, 1e2 / FLOOR_FACTOR * 2)
    assert cause == "floor above the force scale" and "1.0e-04" in detail
    assert "smaller load" in remedy(cause)
    assert "steps = 40" in remedy("divergence", 40)
