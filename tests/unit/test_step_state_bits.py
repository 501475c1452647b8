"""The transient's in-place step updates and reaction sums give bitwise the numbers of the
plain array expressions they replace (issue 15: no arrays made per step, no number changed)."""

import numpy as np
import pytest

from beamfx.analyses.dynamics import _advance_in_place
from beamfx.analyses.reactions import _cross, _moment_about
from beamfx.analyses.transient_reactions import _norm
from beamfx.solvers.integrators import AlphaStep, generalized_alpha, hht, newmark


@pytest.mark.parametrize("params", [generalized_alpha(0.9), generalized_alpha(0.0), hht(0.05),
                                    newmark()])  # fmt: skip
def test_advance_in_place_is_bitwise_alpha_step_advance(params):
    """Random states of mixed magnitudes and step sizes: v, a and q̈ written in place equal
    AlphaStep.advance's arrays bit for bit, and q_n is left alone."""
    rng = np.random.default_rng(3)
    step = AlphaStep(params, None)
    for h in (0.0125, 1e-5, 0.37, 1 / 3):
        q, *state = (rng.normal(size=57) * 10 ** rng.uniform(-8, 3, 57) for _ in range(5))
        want = step.advance(q, *state, h)
        q_n = state[0].copy()
        work = tuple(np.empty_like(q) for _ in range(3))
        _advance_in_place(params, h, q, state, work)
        for got, expected in zip(state[1:], want):
            assert got.tobytes() == expected.tobytes()
        assert state[0].tobytes() == q_n.tobytes()


def test_moment_about_and_norm_are_bitwise_the_array_forms():
    """moment − x × f in floats equals the array cross product's; the norm equals
    np.linalg.norm's, bit for bit."""
    rng = np.random.default_rng(5)
    for _ in range(2000):
        m, x, f = (rng.normal(size=3) * 10 ** rng.uniform(-6, 6) for _ in range(3))
        want = m - _cross(x[None], f[None])[0]
        assert np.array(_moment_about(m, x, f)).tobytes() == want.tobytes()
        assert _norm(f) == float(np.linalg.norm(f))
