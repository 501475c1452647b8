"""Rotation helpers: R(q) is a rotation for any q, hat/axial are inverse, unwrapping follows 4π."""

import numpy as np
import pytest

from beamfx.physics.rotations import (
    axis_angle,
    np_hat,
    np_quaternion,
    np_rotation,
    principal_rotation_vector,
    unwrap_rotation_vector,
)

rng = np.random.default_rng(1)


@pytest.mark.parametrize("q", rng.normal(size=(20, 4)) * rng.uniform(0.1, 10, size=(20, 1)))
def test_rotation_is_orthogonal_for_any_norm(q):
    R = np_rotation(q)
    assert np.allclose(R.T @ R, np.eye(3), atol=1e-14)
    assert np.isclose(np.linalg.det(R), 1.0, atol=1e-14)


def test_rotation_matches_rodrigues_formula():
    for axis, angle in [((0, 0, 1), 0.3), ((1, 1, 1), 2.5), ((1, -2, 0.5), 7.0)]:
        n = np.asarray(axis, float) / np.linalg.norm(axis)
        N = np_hat(n)
        expected = np.eye(3) + np.sin(angle) * N + (1 - np.cos(angle)) * N @ N
        assert np.allclose(np_rotation(np_quaternion(axis, angle)), expected, atol=1e-14)


def test_axis_angle_round_trip_and_principal_vector():
    for angle in (0.1, 1.0, 3.0, 3.5, 6.0):
        q = np_quaternion((0, 1, 0), angle)
        axis, a = axis_angle(q)
        assert np.isclose(a, angle) and np.allclose(axis, (0, 1, 0))
        theta = principal_rotation_vector(q)
        assert np.linalg.norm(theta) <= np.pi + 1e-14
        assert np.allclose(np_rotation(np_quaternion(theta, np.linalg.norm(theta))), np_rotation(q))


def test_unwrap_follows_a_roll_up_to_two_turns():
    previous = np.zeros(3)
    for angle in np.linspace(0, 4 * np.pi, 41)[1:]:
        previous = unwrap_rotation_vector(np_quaternion((0, -1, 0), angle), previous)
    assert np.allclose(previous, (0, -4 * np.pi, 0), atol=1e-12)


def test_ufl_hat_axial_and_quaternion_rates_agree_with_numpy():
    """The UFL maps, evaluated on constants, equal their NumPy counterparts."""
    import ufl

    from beamfx.physics.rotations import axial, body_rate, hat, rotation, spatial_rate

    # evaluate by substituting numbers: UFL expressions of as_vector literals are constants
    q = np.array([0.3, -0.4, 1.2, 0.5])
    dq = np.array([0.1, 0.7, -0.2, 0.4])
    Q, dQ = ufl.as_vector(q.tolist()), ufl.as_vector(dq.tolist())

    def num(e, shape):
        return (
            np.array([[float(e[i, j]) for j in range(shape[1])] for i in range(shape[0])])
            if len(shape) == 2
            else np.array([float(e[i]) for i in range(shape[0])])
        )

    R = num(rotation(Q), (3, 3))
    assert np.allclose(R, np_rotation(q))
    # derivative of R along dq by finite differences
    eps = 1e-7
    dR = (np_rotation(q + eps * dq) - np_rotation(q - eps * dq)) / (2 * eps)
    W_body, W_spatial = R.T @ dR, dR @ R.T
    assert np.allclose(
        num(body_rate(Q, dQ), (3,)), [W_body[2, 1], W_body[0, 2], W_body[1, 0]], atol=1e-7
    )
    assert np.allclose(
        num(spatial_rate(Q, dQ), (3,)),
        [W_spatial[2, 1], W_spatial[0, 2], W_spatial[1, 0]],
        atol=1e-7,
    )
    v = np.array([0.2, -1.0, 3.0])
    assert np.allclose(num(axial(hat(ufl.as_vector(v.tolist()))), (3,)), v)


def test_unwrap_with_uneven_steps_past_pi():
    """A step from 2.8 to 3.2 rad must continue forward, not jump back (regression)."""
    v = unwrap_rotation_vector(np_quaternion((0, 0, 1), 3.2), (0, 0, 2.8))
    assert np.allclose(v, (0, 0, 3.2))
    previous = np.zeros(3)
    for angle in np.cumsum(np.full(37, 0.37)):
        previous = unwrap_rotation_vector(np_quaternion((1, 2, 2), angle), previous)
    assert np.allclose(previous, 0.37 * 37 * np.array([1, 2, 2]) / 3)
