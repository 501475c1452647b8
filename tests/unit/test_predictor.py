"""The transient predictor's acceleration trend (beamfx/analyses/predictor.py): its divided
differences extrapolate a polynomial acceleration exactly over varying steps, it picks the
order that predicted the last step best, order 0 leaves the old start bit for bit, and its
checkpoint state round-trips."""

import numpy as np
from mpi4py import MPI

from beamfx.analyses.predictor import AccelerationTrend

BETA = 0.3


def accelerations(times, coefficients):
    """a(t) at ``times`` for the polynomial with per-dof ``coefficients`` (dof, degree+1)."""
    return [np.polynomial.polynomial.polyval(t, coefficients.T) for t in times]


def march(trend, times, a):
    """Accept the steps between ``times`` with accelerations ``a``."""
    for i in range(1, len(times)):
        trend.accept(a[i], a[i - 1].copy(), times[i] - times[i - 1])


def predicted(trend, a_n, h):
    """ã_{n+1} - a_n as :meth:`add_to` adds it (divided by β h²)."""
    w = np.zeros_like(a_n)
    trend.add_to(w, BETA, h, np.empty_like(a_n))
    return w / (BETA * h**2)


def test_a_quadratic_acceleration_is_extrapolated_exactly_over_varying_steps():
    """Order 2 through three accepted accelerations predicts a quadratic a(t) at t_{n+1}
    (relative 1e-12: the divided differences' round-off), and is the order chosen."""
    rng = np.random.default_rng(1)
    c = rng.normal(size=(7, 3))
    times = np.cumsum([0.0, 0.01, 0.013, 0.007, 0.011, 0.009])
    a = accelerations(times, c)
    trend = AccelerationTrend(7, 7, MPI.COMM_SELF)
    march(trend, times, a)
    assert trend.order == 2
    h = 0.012
    (a_next,) = accelerations([times[-1] + h], c)
    got = a[-1] + predicted(trend, a[-1], h)
    assert np.allclose(got, a_next, rtol=1e-12, atol=1e-12 * np.abs(a_next).max())


def test_an_alternating_acceleration_keeps_the_unchanged_one():
    """a_k = (-1)^k c: extrapolation would double or quadruple the miss, so order 0."""
    times = np.arange(6) * 0.01
    a = [(-1.0) ** k * np.ones(4) for k in range(6)]
    trend = AccelerationTrend(4, 4, MPI.COMM_SELF)
    march(trend, times, a)
    assert trend.order == 0


def test_order_zero_leaves_the_start_bit_for_bit_and_the_state_round_trips():
    """At the start (and after a restart without the trend) nothing is added to the
    starting point; a saved state gives the same prediction after restore."""
    rng = np.random.default_rng(2)
    w = rng.normal(size=5)
    start = AccelerationTrend(5, 5, MPI.COMM_SELF)
    before = w.tobytes()
    start.add_to(w, BETA, 0.01, np.empty(5))
    assert w.tobytes() == before
    times = np.cumsum([0.0, 0.01, 0.02, 0.015])
    trend = AccelerationTrend(5, 5, MPI.COMM_SELF)
    march(trend, times, accelerations(times, rng.normal(size=(5, 3))))
    again = AccelerationTrend(5, 5, MPI.COMM_SELF)
    again.set_state(trend.state())
    a = np.zeros(5)
    assert predicted(again, a, 0.01).tobytes() == predicted(trend, a, 0.01).tobytes()
    again.set_state({})  # an older checkpoint
    assert again.order == 0 and predicted(again, a, 0.01).tobytes() == np.zeros(5).tobytes()
