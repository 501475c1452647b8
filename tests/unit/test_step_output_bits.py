"""The cheaper per-step paths of a transient's output give the same bits as the plain ones:
the rotation unwrap, and a history evaluated at one time (issue 15)."""

import math
import warnings

import numpy as np

from beamfx.physics.rotations import axis_angle, unwrap_rotation_vector
from beamfx.scene.expr import compile_expression

SPIN = "where(t < 15, (6/15) * (t**2/2 + (15/(2*pi))**2 * (cos(2*pi*t/15) - 1)), 6*t - 45)"


def _unwrap_reference(q, previous):
    """The unwrap written with arrays of all the candidate turns (the definition)."""
    axis, angle = axis_angle(q)
    prev = np.asarray(previous, float)
    k0 = math.ceil(np.linalg.norm(prev) / (2 * np.pi))
    turns = np.arange(-k0 - 2, k0 + 3)
    candidates = (angle + 2 * np.pi * turns)[:, None] * axis[None, :]
    return candidates[np.argmin(np.linalg.norm(candidates - prev, axis=1))]


def test_unwrap_is_the_nearest_turn_and_follows_axis_angle():
    """Random quaternions of any norm (tiny and zero vector parts too) against the definition:
    the same turn, and the axis and angle of :func:`axis_angle` (same values to round-off)."""
    rng = np.random.default_rng(7)
    for i in range(3000):
        q = rng.normal(size=4) * 10 ** rng.uniform(-3, 3)
        if i % 7 == 0:
            q[1:] *= 1e-9
        if i % 11 == 0:
            q[1:] = 0.0
        axis, angle = axis_angle(q)
        prev = (angle + 2 * np.pi * rng.integers(-4, 5)) * axis + 0.3 * rng.normal(size=3)
        got = unwrap_rotation_vector(q.tolist(), prev.tolist())
        want = _unwrap_reference(q, prev)
        assert got.dtype == np.float64 and got.shape == (3,)
        np.testing.assert_allclose(got, want, rtol=1e-13, atol=1e-13)


def test_unwrap_of_a_growing_spin_counts_the_turns():
    """Turning about z by steps of 0.5 rad to 20 rad: the unwrapped angle is the spin."""
    theta = np.zeros(3)
    for phi in np.arange(0.5, 20.0, 0.5):
        q = [math.cos(phi / 2), 0.0, 0.0, math.sin(phi / 2)]
        theta = unwrap_rotation_vector(q, theta)
        np.testing.assert_allclose(theta, [0.0, 0.0, phi], atol=1e-12)


def test_history_at_one_time_is_bitwise_the_array_value():
    """A history at one time (the per-step path) gives bitwise the value of the same time in
    an array, and leaves NumPy's error handling as it found it."""
    f = compile_expression(SPIN, "t")
    times = np.linspace(0.0, 18.0, 1441)
    before = np.geterr()
    one = np.array([float(f(t)) for t in times])
    assert np.geterr() == before
    assert one.tobytes() == f(times).tobytes()


def test_history_at_one_time_ignores_floating_errors_quietly():
    """A non-finite value at one time is returned without a warning (the callers report it),
    and an error inside does not leave errors ignored."""
    f, h = compile_expression("1/t", "t"), compile_expression("log(t - 1)", "t")
    before = np.geterr()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert math.isinf(float(f(0.0)))
        assert math.isnan(float(h(0.5)))
    assert np.geterr() == before
    g = compile_expression("1/0", "t")  # constants: Python float arithmetic raises
    try:
        g(1.0)
    except ValueError:
        pass
    assert np.geterr() == before
