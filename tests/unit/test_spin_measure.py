"""The spin-up bench's reading of a sampled history: peaks between samples, time means."""

import numpy as np

from beamfx.bench.spin_measure import least, time_mean


def test_least_reads_the_minimum_between_samples():
    """−cos(ω(t − 0.5)) sampled every dt with its minimum 0.4 dt from the nearest sample:
    the quartic through five samples errs by at most max|f⁽⁵⁾| max|Π(t − t_i)|/5!
    ≤ ω⁵ · 12 dt⁵/120; the least sample by 1 − cos(0.4 ω dt)."""
    omega, dt = 2 * np.pi, 0.05
    t = np.arange(20) * dt + 0.4 * dt
    y = -np.cos(omega * (t - 0.5))
    bound = 0.1 * (omega * dt) ** 5
    assert abs(least(t, y) + 1.0) <= bound, (least(t, y), bound)
    assert abs(y.min() + 1.0) > 10 * bound  # the least sample is far off


def test_least_at_an_end_is_the_end_sample():
    t = np.linspace(0.0, 1.0, 21)
    assert least(t, t) == 0.0 and least(t, -t) == -1.0


def test_time_mean_simpson_on_an_even_grid_else_trapezoidal():
    """Mean of f = sin t + t² over [15, 18] from samples every 0.0125 s (240 intervals):
    Simpson's error is at most dt⁴ max|f''''|/180 = dt⁴/180. Over [15, 17.97] every 0.03 s
    (99 intervals) the trapezoidal rule: at most dt² max|f''|/12 = dt² 3/12."""

    def mean(a, b):
        return ((np.cos(a) - np.cos(b)) + (b**3 - a**3) / 3) / (b - a)

    t = np.arange(1441) * 0.0125
    assert abs(time_mean(t, np.sin(t) + t**2, 15.0, 18.0) - mean(15.0, 18.0)) <= 0.0125**4 / 180
    t = 15.0 + np.arange(100) * 0.03
    error = abs(time_mean(t, np.sin(t) + t**2, 15.0, t[-1]) - mean(15.0, t[-1]))
    assert error <= 0.03**2 * 3 / 12
