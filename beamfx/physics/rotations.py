"""Rotations in UFL and NumPy: hat/axial maps and the quaternion rotation.

Quaternions are ``(q0, q1, q2, q3)`` with scalar part first. ``R(q)`` maps section (body) vectors
to global (spatial) vectors.
"""

import math

import numpy as np


def hat(v):
    """Skew matrix with ``hat(v) @ a = v × a``."""
    import ufl

    return ufl.as_matrix([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def axial(A):
    """Inverse of :func:`hat` applied to the skew part of ``A``."""
    import ufl

    return ufl.as_vector([A[2, 1] - A[1, 2], A[0, 2] - A[2, 0], A[1, 0] - A[0, 1]]) / 2


def quaternion_vector(q):
    """Vector part of the quaternion ``q``."""
    import ufl

    return ufl.as_vector([q[1], q[2], q[3]])


def rotation(q):
    r"""Rotation matrix of a quaternion of any norm.

    :math:`R(q) = [(q_0^2 - v\cdot v) I + 2 v v^T + 2 q_0 \hat v] / |q|^2`
    (e.g. Géradin & Cardona 2001, eq. 4.53, divided by the norm so that it is a rotation for
    every non-zero ``q``).
    """
    import ufl

    v = quaternion_vector(q)
    q0 = q[0]
    return ((q0**2 - ufl.dot(v, v)) * ufl.Identity(3) + 2 * ufl.outer(v, v) + 2 * q0 * hat(v)) / (
        ufl.dot(q, q)
    )


def body_rate(q, dq):
    r"""Body-frame rate :math:`\mathrm{axial}(R^T \delta R) = 2\,\mathrm{Im}(\bar q\,\delta q)/|q|^2`.

    With ``dq = q'`` this is the curvature of the rotation field; with ``dq`` a variation it is
    the virtual rotation in body axes. Independent of a (pointwise) scaling of ``q``.
    """
    import ufl

    v, dv = quaternion_vector(q), quaternion_vector(dq)
    return 2 * (q[0] * dv - dq[0] * v - ufl.cross(v, dv)) / ufl.dot(q, q)


def spatial_rate(q, dq):
    r"""Spatial rate :math:`\mathrm{axial}(\delta R\, R^T) = 2\,\mathrm{Im}(\delta q\,\bar q)/|q|^2`."""
    import ufl

    v, dv = quaternion_vector(q), quaternion_vector(dq)
    return 2 * (q[0] * dv - dq[0] * v + ufl.cross(v, dv)) / ufl.dot(q, q)


def quaternion_rotation_vector(q):
    r"""Rotation vector ψ = 2 atan2(|v|, q0) v/|v| of a quaternion of any norm.

    Continuous for angles up to 2π along a continuous quaternion field (q0 changes sign at π);
    near zero the series 2 v/q0 (1 − |v|²/(3 q0²)) replaces the quotient 0/0.
    """
    import ufl

    v, q0 = quaternion_vector(q), q[0]
    vv = ufl.dot(v, v)
    norm_v = ufl.sqrt(vv + 1e-300)
    exact = 2 * ufl.atan_2(norm_v, q0) / norm_v * v
    series = 2 / q0 * (1 - vv / (3 * q0**2)) * v
    small = ufl.And(ufl.lt(vv, 1e-8 * q0**2), ufl.gt(q0, 0))
    return ufl.conditional(small, series, exact)


# --- NumPy counterparts, for set-up and post-processing --------------------------------------


def np_hat(v):
    """NumPy :func:`hat` of one vector (3,) or of many (..., 3) -> (..., 3, 3)."""
    v = np.asarray(v, dtype=float)
    W = np.zeros(v.shape + (3,))
    W[..., 0, 1], W[..., 0, 2], W[..., 1, 2] = -v[..., 2], v[..., 1], -v[..., 0]
    W[..., 1, 0], W[..., 2, 0], W[..., 2, 1] = v[..., 2], -v[..., 1], v[..., 0]
    return W


def np_rotation(q):
    """NumPy :func:`rotation` of one quaternion (4,) or of many (..., 4), any norm."""
    q = np.asarray(q, dtype=float)
    q0, v = q[..., 0, None, None], q[..., 1:]
    vv = np.einsum("...i,...i->...", v, v)[..., None, None]
    R = (q0**2 - vv) * np.eye(3) + 2 * np.einsum("...i,...j->...ij", v, v) + 2 * q0 * np_hat(v)
    return R / np.einsum("...i,...i->...", q, q)[..., None, None]


def np_exp_rotation(theta):
    """Rotation exp(hat θ) (Rodrigues) of one rotation vector (3,) or of many (..., 3)."""
    theta = np.asarray(theta, dtype=float)
    angle = np.linalg.norm(theta, axis=-1)[..., None, None]
    W = np_hat(theta)
    small = angle < 1e-8
    a = np.where(small, 1.0, angle)
    c1 = np.where(small, 1.0 - angle**2 / 6, np.sin(a) / a)
    c2 = np.where(small, 0.5 - angle**2 / 24, (1 - np.cos(a)) / a**2)
    return np.eye(3) + c1 * W + c2 * (W @ W)


def np_left_jacobian(g):
    """J(ψ) = I + (1 − cos θ)/θ² ψ̂ + (θ − sin θ)/θ³ ψ̂² (θ = |ψ|): the spatial virtual
    rotation δθ = axial(δR Rᵀ) = J δψ of R = exp(ψ̂) (NumPy, one vector; Taylor series of
    both factors below θ = 1e-4)."""
    W = np_hat(g)
    theta = float(np.linalg.norm(g))
    if theta < 1e-4:
        a, b = 0.5 - theta**2 / 24, 1 / 6 - theta**2 / 120
    else:
        a, b = (1 - np.cos(theta)) / theta**2, (theta - np.sin(theta)) / theta**3
    return np.eye(3) + a * W + b * (W @ W)


def np_quaternion(axis, angle):
    """Unit quaternion of a rotation by ``angle`` about ``axis``."""
    axis = np.asarray(axis, dtype=float)
    axis = axis / np.linalg.norm(axis)
    return np.r_[np.cos(angle / 2), np.sin(angle / 2) * axis]


def _norm(v):
    """‖v‖₂ of a 1-D float array: what ``np.linalg.norm(v)`` computes (sqrt of ``v.dot(v)``,
    bitwise), without its dispatch (a probe history calls it at every step)."""
    return math.sqrt(v.dot(v))


def axis_angle(q):
    """Axis and angle in [0, 2π] of the rotation of a quaternion of any norm.

    Use :func:`unwrap_rotation_vector` to follow angles beyond 2π along a load path.
    """
    q = np.asarray(q, dtype=float)
    q = q / _norm(q)
    s = _norm(q[1:])
    angle = 2 * np.arctan2(s, q[0])  # in [0, 2π]
    axis = q[1:] / s if s > 1e-300 else np.array([1.0, 0.0, 0.0])
    return axis, angle


def principal_rotation_vector(q):
    """Rotation vector with |θ| ≤ π of the rotation encoded by ``q``."""
    axis, angle = axis_angle(q)
    if angle > np.pi:
        axis, angle = -axis, 2 * np.pi - angle
    return angle * axis


def unwrap_rotation_vector(q, previous):
    """Rotation vector of ``q`` closest to ``previous`` among all equivalent ones.

    The rotation vectors of the rotation (n, φ) are (φ + 2πk) n for every integer k (negative
    k gives the turns the other way about n). Keeping the one nearest to the previous value
    follows a rotation past π, 2π, 4π along a load or time path.
    """
    # :func:`axis_angle`'s operations (the norms through ``dot``, arctan2 through NumPy),
    # the axis divided in plain floats (the same IEEE quotients as the array's)
    q = np.asarray(q, dtype=float)
    q = q / _norm(q)
    s = _norm(q[1:])
    angle = float(2 * np.arctan2(s, q[0]))  # in [0, 2π]
    if s > 1e-300:
        _, a, b, c = q.tolist()
        n = [a / s, b / s, c / s]
    else:
        n = [1.0, 0.0, 0.0]
    return np.array(nearest_turn(n, angle, np.asarray(previous, dtype=float).tolist()))


def nearest_turn(n, angle, p):
    """Of the rotation vectors (``angle`` + 2πk) ``n`` (k integer) the one nearest to ``p``,
    as a list; ``n`` (unit axis), ``p`` lists of 3 floats.

    |(φ + 2πk) n - p| is least at the integer nearest to (n·p - φ)/2π: of the turns -k0-2 ..
    k0+2 only that one and its neighbours are compared, in plain floats (the same operations
    as arrays of all the turns would do, at a tenth of the cost per call)."""
    k0 = math.ceil(math.sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) / (2 * np.pi))
    centre = round((n[0] * p[0] + n[1] * p[1] + n[2] * p[2] - angle) / (2 * np.pi))
    best, best_x = None, None
    for k in range(max(centre - 1, -k0 - 2), min(centre + 1, k0 + 2) + 1):
        c = angle + 2 * np.pi * k
        x = [c * n[0], c * n[1], c * n[2]]
        d = [x[0] - p[0], x[1] - p[1], x[2] - p[2]]
        dist = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
        if best is None or dist < best:
            best, best_x = dist, x
    return best_x
