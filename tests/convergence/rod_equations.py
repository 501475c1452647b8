"""Independent reference solver for static Reissner / Kirchhoff rod equations.

This module is deliberately independent of beamfx: it uses only numpy and scipy and
solves the *strong form* of the static rod equations with an adaptive high-order ODE
integrator (``scipy.integrate.solve_ivp``, DOP853) plus shooting. The tests of beamfx
use it to obtain reference answers for cantilever problems.

Conventions
-----------
* ``s`` is the arc length of the reference (stress-free) centre line ``X(s)``.
* The reference frame ``Lambda0(s)`` (3x3, columns ``(t, e2, e3)``) maps the material
  basis ``E_i`` to the reference section directors; ``t = X'`` is the unit tangent.
  Its material curvature is ``K0 = axial(Lambda0^T Lambda0')``.
* ``Lambda(s)`` is the *total* rotation (material basis -> current section directors);
  ``Lambda = Lambda0`` in the reference state.
* ``r(s)`` is the current centre line, ``n(s)``, ``m(s)`` the spatial internal force and
  moment (acting on the part ``[0, s]`` from the part ``(s, L]``).
* Simo-Reissner strains and linear elastic law:

      Gamma = Lambda^T r' - E1 = C_N^{-1} Lambda^T n,     C_N = diag(EA, GA_2, GA_3)
      K     = axial(Lambda^T Lambda'),   K - K0 = C_M^{-1} Lambda^T m,
                                                          C_M = diag(GJ, EI_2, EI_3)

* Equilibrium without distributed loads: ``n' = 0``, ``m' + r' x n = 0``.  With a
  clamp at ``s = 0`` and tip loads at ``s = L``: ``n(s) = n(L)`` and
  ``m(s) = m(0) - (r(s) - r(0)) x n``.
* Rotations are integrated as unit quaternions ``q = (w, x, y, z)`` with
  ``q' = 1/2 q * (0, K)`` (which is ``Lambda' = Lambda hat(K)``).

Run ``/usr/bin/python3 tests/convergence/rod_equations.py`` to print the reference numbers; the
``test_*`` functions are collected by pytest.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from scipy.integrate import quad, solve_ivp
from scipy.optimize import brentq, root

__all__ = [
    "RodCurve",
    "arc_curve",
    "axial",
    "axis_angle_to_rotation",
    "cantilever_shooting",
    "elastica_tip_force_exact",
    "hat",
    "matrix_to_quat",
    "pure_end_moments",
    "pure_end_moments_isotropic_exact",
    "quat_to_matrix",
    "rotation_to_axis_angle",
    "rotation_vector",
    "straight_curve",
]

_E1 = np.array([1.0, 0.0, 0.0])


# ----------------------------------------------------------------------------------------
# rotation utilities
# ----------------------------------------------------------------------------------------
def hat(v):
    """Skew matrix with ``hat(v) @ w == cross(v, w)``."""
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def axial(A):
    """Axial vector of the skew part of ``A`` (inverse of :func:`hat`)."""
    return 0.5 * np.array([A[2, 1] - A[1, 2], A[0, 2] - A[2, 0], A[1, 0] - A[0, 1]])


def quat_to_matrix(q):
    """Rotation matrix of the quaternion ``q = (w, x, y, z)`` (normalised first)."""
    w, x, y, z = q
    nq = math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / nq, x / nq, y / nq, z / nq
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def matrix_to_quat(R):
    """Unit quaternion ``(w, x, y, z)`` with ``w >= 0`` of a rotation matrix.

    Uses Shepperd's method (largest diagonal pivot), which is accurate for every
    angle including angles near pi. ``R`` is first projected onto SO(3) by a polar
    (SVD) decomposition, so slightly non-orthogonal input is accepted.
    """
    R = _orthonormalise(np.asarray(R, dtype=float))
    tr = np.trace(R)
    d = np.array([tr, R[0, 0], R[1, 1], R[2, 2]])
    i = int(np.argmax(d))
    if i == 0:
        w = 0.5 * math.sqrt(1.0 + tr)
        q = np.array(
            [
                w,
                (R[2, 1] - R[1, 2]) / (4 * w),
                (R[0, 2] - R[2, 0]) / (4 * w),
                (R[1, 0] - R[0, 1]) / (4 * w),
            ]
        )
    elif i == 1:
        x = 0.5 * math.sqrt(max(0.0, 1.0 + 2 * R[0, 0] - tr))
        q = np.array(
            [
                (R[2, 1] - R[1, 2]) / (4 * x),
                x,
                (R[0, 1] + R[1, 0]) / (4 * x),
                (R[0, 2] + R[2, 0]) / (4 * x),
            ]
        )
    elif i == 2:
        y = 0.5 * math.sqrt(max(0.0, 1.0 + 2 * R[1, 1] - tr))
        q = np.array(
            [
                (R[0, 2] - R[2, 0]) / (4 * y),
                (R[0, 1] + R[1, 0]) / (4 * y),
                y,
                (R[1, 2] + R[2, 1]) / (4 * y),
            ]
        )
    else:
        z = 0.5 * math.sqrt(max(0.0, 1.0 + 2 * R[2, 2] - tr))
        q = np.array(
            [
                (R[1, 0] - R[0, 1]) / (4 * z),
                (R[0, 2] + R[2, 0]) / (4 * z),
                (R[1, 2] + R[2, 1]) / (4 * z),
                z,
            ]
        )
    q /= np.linalg.norm(q)
    return -q if q[0] < 0 else q


def rotation_to_axis_angle(R):
    """Axis and angle of a rotation matrix.

    Args:
        R: 3x3 rotation matrix (projected onto SO(3) first).

    Returns:
        ``(axis, angle)`` with ``angle = 2 atan2(|v|, w)`` in ``[0, pi]`` computed from the
        quaternion ``(w, v)``, ``w >= 0``, and ``axis = v / |v|`` a unit vector
        (``(1, 0, 0)`` when the angle is exactly 0). At ``angle = pi`` the axis sign is
        arbitrary (``axis`` and ``-axis`` describe the same rotation).
    """
    q = matrix_to_quat(R)
    v = q[1:]
    nv = np.linalg.norm(v)
    angle = 2.0 * math.atan2(nv, q[0])
    if nv == 0.0:
        return np.array([1.0, 0.0, 0.0]), 0.0
    return v / nv, angle


def rotation_vector(R):
    """Rotation (pseudo-)vector ``theta = angle * axis`` with ``|theta| <= pi``, so that
    ``R = expm(hat(theta))``."""
    axis, angle = rotation_to_axis_angle(R)
    return angle * axis


def axis_angle_to_rotation(axis, angle=None):
    """Rodrigues formula. ``axis_angle_to_rotation(theta)`` takes a rotation vector,
    ``axis_angle_to_rotation(axis, angle)`` a (normalised here) axis and an angle."""
    axis = np.asarray(axis, dtype=float)
    if angle is None:
        angle = float(np.linalg.norm(axis))
        if angle == 0.0:
            return np.eye(3)
    axis = axis / np.linalg.norm(axis)
    A = hat(axis)
    return np.eye(3) + math.sin(angle) * A + (1.0 - math.cos(angle)) * (A @ A)


def _orthonormalise(R):
    """Nearest rotation matrix (polar decomposition via SVD)."""
    U, _, Vt = np.linalg.svd(R)
    Q = U @ Vt
    if np.linalg.det(Q) < 0:
        U[:, -1] *= -1
        Q = U @ Vt
    return Q


def _stiffness(C):
    """3x3 stiffness matrix from a 3-vector (diagonal) or a 3x3 matrix."""
    C = np.asarray(C, dtype=float)
    if C.shape == (3,):
        return np.diag(C)
    if C.shape == (3, 3):
        return C
    raise ValueError(f"stiffness must be a 3-vector or 3x3 matrix, got shape {C.shape}")


def _cross(a, b):
    """Cross product of two 3-vectors (much faster than np.cross for single vectors)."""
    return np.array(
        [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    )


def _qmul_pure(q, K):
    """Right-multiply quaternion ``q`` by the pure quaternion ``(0, K)``."""
    w, x, y, z = q
    a, b, c = K
    return np.array(
        [
            -x * a - y * b - z * c,
            w * a + y * c - z * b,
            w * b + z * a - x * c,
            w * c + x * b - y * a,
        ]
    )


# ----------------------------------------------------------------------------------------
# 1. straight rod under a pure end moment
# ----------------------------------------------------------------------------------------
def pure_end_moments(
    L, C_M, m, n_steps=None, *, rtol=1e-12, atol=1e-14, method="quaternion", return_solution=False
):
    """Straight clamped rod under a tip moment that is fixed in space.

    The rod lies along global x at rest (``Lambda0 = I``: section axes e1 = x (axial),
    e2 = y, e3 = z), is clamped at ``s = 0`` and loaded at ``s = L`` by the spatial
    moment ``m`` (no force). Then ``n = 0`` and ``m(s) = m`` everywhere, so the strains
    are ``Gamma = 0`` (no stretch or shear, whatever C_N is) and

        K  = C_M^{-1} R^T m,        R' = R hat(K),        r' = R e1,

    with ``R(0) = I``, ``r(0) = 0``. (``C_M K`` in material form is the Euler top of the
    Kirchhoff kinetic analogue: ``C_M K' = -K x C_M K``.)

    Args:
        L: rod length.
        C_M: bending/torsion stiffness, 3-vector ``(GJ, EI_y, EI_z)`` or 3x3 matrix in
            section axes.
        m: tip moment, 3-vector in global axes (fixed in space).
        n_steps: if given, at least this many integration steps (``max_step = L/n_steps``);
            by default the step size is purely adaptive.
        rtol, atol: solve_ivp tolerances (DOP853).
        method: ``"quaternion"`` (integrate a unit quaternion, default) or ``"matrix"``
            (integrate the 9 entries of R, re-orthonormalised by SVD at the end).
        return_solution: also return the ``OdeResult`` (dense output enabled).

    Returns:
        ``(r_tip, R_tip)``: tip position (3,) and tip rotation matrix (3, 3)
        (material-to-spatial, equal to the incremental rotation since ``Lambda0 = I``).
    """
    C = _stiffness(C_M)
    Cinv = np.linalg.inv(C)
    m = np.asarray(m, dtype=float)
    max_step = np.inf if n_steps is None else L / n_steps

    if method == "quaternion":

        def rhs(s, y):
            q = y[3:]
            R = quat_to_matrix(q)
            K = Cinv @ (R.T @ m)
            dq = 0.5 * _qmul_pure(q, K)
            return np.concatenate([R[:, 0], dq])

        y0 = np.array([0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0])
    elif method == "matrix":

        def rhs(s, y):
            R = y[3:].reshape(3, 3)
            K = Cinv @ (R.T @ m)
            return np.concatenate([R[:, 0], (R @ hat(K)).ravel()])

        y0 = np.concatenate([np.zeros(3), np.eye(3).ravel()])
    else:
        raise ValueError("method must be 'quaternion' or 'matrix'")

    sol = solve_ivp(
        rhs,
        (0.0, L),
        y0,
        method="DOP853",
        rtol=rtol,
        atol=atol,
        max_step=max_step,
        dense_output=return_solution,
    )
    if not sol.success:
        raise RuntimeError(f"solve_ivp failed: {sol.message}")
    y = sol.y[:, -1]
    r_tip = y[:3].copy()
    if method == "quaternion":
        R_tip = quat_to_matrix(y[3:])
    else:
        R_tip = _orthonormalise(y[3:].reshape(3, 3))
    if return_solution:
        return r_tip, R_tip, sol
    return r_tip, R_tip


def pure_end_moments_isotropic_exact(L, GJ, EI, m):
    """Closed form of :func:`pure_end_moments` for isotropic bending (EI_y = EI_z = EI).

    With ``C_M = diag(GJ, EI, EI)`` the twist ``m . t = m_1`` is constant and

        R(s) = exp(s hat(omega)) exp(s nu hat(e1)),   omega = m / EI,
        nu = m_1 (1/GJ - 1/EI),
        r(L) = int_0^L exp(s hat(omega)) e1 ds
             = [L I + (1 - cos wL)/w^2 hat(omega) + (L - sin(wL)/w)/w^2 hat(omega)^2] e1,

    ``w = |omega|`` (a helix; a circle when ``m`` is perpendicular to the rod).

    Returns:
        ``(r_tip, R_tip)``.
    """
    m = np.asarray(m, dtype=float)
    om = m / EI
    w = np.linalg.norm(om)
    nu = m[0] * (1.0 / GJ - 1.0 / EI)
    if w == 0.0:
        return L * _E1, np.eye(3)
    W = hat(om)
    # use expm1-like forms for accuracy at small wL
    c1 = 2.0 * math.sin(0.5 * w * L) ** 2 / w**2  # (1 - cos wL) / w^2
    c2 = (L - math.sin(w * L) / w) / w**2
    r_tip = (L * np.eye(3) + c1 * W + c2 * (W @ W)) @ _E1
    R_tip = axis_angle_to_rotation(om * L) @ axis_angle_to_rotation(_E1, nu * L)
    return r_tip, R_tip


# ----------------------------------------------------------------------------------------
# reference centre lines
# ----------------------------------------------------------------------------------------
def _frame_from_tangent(t, dt, up=(0.0, 0.0, 1.0)):
    """Frame ``(t, e2, e3)`` with e3 = ``up`` made normal to t, e2 = e3 x t, and its
    derivative given ``t'``."""
    up = np.asarray(up, dtype=float)
    p = up - (up @ t) * t
    npn = np.linalg.norm(p)
    if npn < 1e-8:
        raise ValueError("tangent parallel to the 'up' direction: frame undefined")
    e3 = p / npn
    dp = -(up @ dt) * t - (up @ t) * dt
    de3 = (dp - e3 * (e3 @ dp)) / npn
    e2 = np.cross(e3, t)
    de2 = np.cross(de3, t) + np.cross(e3, dt)
    Lam = np.column_stack([t, e2, e3])
    dLam = np.column_stack([dt, de2, de3])
    return Lam, dLam


class RodCurve:
    """Reference centre line with section frame.

    Calling ``curve(s)`` returns ``(X(s), Lambda0(s))``; ``curve.curvature(s)`` returns
    the material curvature ``K0(s) = axial(Lambda0^T Lambda0')``; ``curve.length`` is L.
    """

    def __init__(self, length, position, frame_and_derivative):
        self.length = float(length)
        self._position = position
        self._frame = frame_and_derivative

    def __call__(self, s):
        return self._position(s), self._frame(s)[0]

    def curvature(self, s):
        Lam, dLam = self._frame(s)
        return axial(Lam.T @ dLam)


def straight_curve(L, direction=(1.0, 0.0, 0.0), start=(0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0)):
    """Straight reference line ``X(s) = start + s t``, ``t = direction/|direction|``.

    Frame: e3 = ``up`` (global z) made normal to t, e2 = e3 x t. For ``direction = x``
    this is the identity.
    """
    t = np.asarray(direction, dtype=float)
    t = t / np.linalg.norm(t)
    start = np.asarray(start, dtype=float)
    Lam, _ = _frame_from_tangent(t, np.zeros(3), up)
    zero = np.zeros((3, 3))
    return RodCurve(L, lambda s: start + s * t, lambda s: (Lam, zero))


def arc_curve(R, angle, start, start_tangent, centre, up=(0.0, 0.0, 1.0), degrees=False):
    """Circular arc of radius ``R`` and opening ``angle`` (radians unless ``degrees``).

    The circle passes through ``start`` with unit tangent ``start_tangent`` and has
    centre ``centre`` (``|centre - start| = R`` and ``(centre - start) . t0 = 0`` are
    checked). With ``n0 = (centre - start)/R``, ``theta = s/R``:

        X(s) = centre + R (-n0 cos theta + t0 sin theta),  t(s) = t0 cos theta + n0 sin theta.

    Frame columns ``(t, e2, e3)``: e3 = ``up`` (global z) made normal to t, e2 = e3 x t
    (right-handed). For an arc in the x-y plane e3 = z and ``K0 = (0, 0, +-1/R)``.
    """
    if degrees:
        angle = math.radians(angle)
    start = np.asarray(start, dtype=float)
    centre = np.asarray(centre, dtype=float)
    t0 = np.asarray(start_tangent, dtype=float)
    t0 = t0 / np.linalg.norm(t0)
    d = centre - start
    if abs(np.linalg.norm(d) - R) > 1e-10 * R:
        raise ValueError("|centre - start| != R")
    n0 = d / R
    if abs(n0 @ t0) > 1e-10:
        raise ValueError("start_tangent is not perpendicular to centre - start")

    def position(s):
        th = s / R
        return centre + R * (-n0 * math.cos(th) + t0 * math.sin(th))

    def frame(s):
        th = s / R
        t = t0 * math.cos(th) + n0 * math.sin(th)
        dt = (-t0 * math.sin(th) + n0 * math.cos(th)) / R
        return _frame_from_tangent(t, dt, up)

    return RodCurve(R * angle, position, frame)


def _fd_curvature(curve, L):
    """K0(s) from an arbitrary frame callable by a 4th-order central difference
    (needs the callable to be defined slightly outside [0, L])."""
    h = 1e-3 * L

    def K0(s):
        F = [curve(s + k * h)[1] for k in (-2, -1, 1, 2)]
        dLam = (F[0] - 8 * F[1] + 8 * F[2] - F[3]) / (12 * h)
        return axial(curve(s)[1].T @ dLam)

    return K0


# ----------------------------------------------------------------------------------------
# 3. general cantilever by shooting
# ----------------------------------------------------------------------------------------
def _integrate_cantilever(X0, q0, L, K0, Cn_inv, Cm_inv, n, m0, rtol, atol, dense=False):
    """Integrate r, q from s = 0 to L for constant spatial force n and m(0) = m0."""
    K0_const = None
    if not callable(K0):
        K0_const = np.asarray(K0, dtype=float)

    def rhs(s, y):
        r = y[:3]
        q = y[3:]
        Lam = quat_to_matrix(q)
        nm = Lam.T @ n
        dr = Lam @ (_E1 + Cn_inv @ nm)
        msp = m0 - _cross(r - X0, n)
        K = (K0_const if K0_const is not None else K0(s)) + Cm_inv @ (Lam.T @ msp)
        return np.concatenate([dr, 0.5 * _qmul_pure(q, K)])

    y0 = np.concatenate([X0, q0])
    sol = solve_ivp(rhs, (0.0, L), y0, method="DOP853", rtol=rtol, atol=atol, dense_output=dense)
    if not sol.success:
        raise RuntimeError(f"solve_ivp failed: {sol.message}")
    return sol


def cantilever_shooting(
    curve,
    C_N,
    C_M,
    tip_force,
    tip_moment=(0.0, 0.0, 0.0),
    follower=False,
    *,
    follower_moment=False,
    L=None,
    n_load_steps=20,
    rtol=1e-12,
    atol=1e-14,
    rtol_continuation=1e-9,
    full_output=False,
):
    """Clamped Simo-Reissner rod with tip loads, solved by shooting.

    Unknowns at the clamp ``s = 0`` (where ``r = X(0)``, ``Lambda = Lambda0(0)``):
    ``m(0)`` (dead force: ``n = F`` is known), or ``(n, m(0))`` for a follower force.
    The ODE system on ``[0, L]`` is

        r'      = Lambda (E1 + C_N^{-1} Lambda^T n)
        Lambda' = Lambda hat(K0 + C_M^{-1} Lambda^T m),   m(s) = m(0) - (r(s) - r(0)) x n

    (n is constant since there are no distributed loads), integrated with a unit
    quaternion for Lambda. Shooting conditions at ``s = L``:

        dead force:      m(L) = M                               (3 equations)
        follower force:  n = Lambda(L) Lambda0(L)^T F,  m(L) = M  (6 equations)

    with ``M`` replaced by ``Lambda(L) Lambda0(L)^T M`` if ``follower_moment``. They are
    solved by ``scipy.optimize.root`` (hybr) with a load continuation: the load factor is
    ramped in ``n_load_steps`` equal steps, each started from a secant predictor built on
    the previous solutions. Intermediate steps use ``rtol_continuation``; the final load
    level is solved with ``rtol``.

    Args:
        curve: callable ``s -> (X(s), Lambda0(s))`` with ``Lambda0`` columns
            ``(tangent, e2, e3)``; ``s`` must be arc length. A :class:`RodCurve`
            (from :func:`straight_curve` / :func:`arc_curve`) also provides L and an
            analytic K0; for a plain callable pass ``L`` (K0 is then obtained by finite
            differences, accurate to ~1e-11 relative).
        C_N: ``(EA, GA_2, GA_3)`` or 3x3 (section axes). Use large values for an
            inextensible, shear-rigid (Kirchhoff) rod.
        C_M: ``(GJ, EI_2, EI_3)`` or 3x3 (section axes).
        tip_force: ``F`` (global axes). Dead, or for ``follower=True`` the reference
            force: the applied force is ``Lambda(L) Lambda0(L)^T F`` (rotates with the tip
            section).
        tip_moment: ``M`` (global axes, fixed in space unless ``follower_moment``).
        follower: follower tip force.
        follower_moment: follower tip moment.
        L: length, only needed when ``curve`` has no ``length`` attribute.
        n_load_steps: continuation steps (>= 1).
        rtol, atol: solve_ivp tolerances for the final solve.
        rtol_continuation: solve_ivp rtol for intermediate load levels.
        full_output: return a dict instead of a tuple.

    Returns:
        ``(r_tip, Lambda_tip)``: tip position and total tip rotation (material to spatial;
        for a straight rod along x, ``Lambda0 = I`` and this is the incremental rotation).
        With ``full_output``, a dict with keys ``r_tip``, ``Lambda_tip``, ``R_tip``
        (incremental rotation ``Lambda(L) Lambda0(L)^T``), ``n``, ``m0``, ``residual``,
        ``solution`` (dense ``OdeResult``: y = (r, q) along s).
    """
    if L is None:
        L = curve.length
    L = float(L)
    X0, Lam00 = curve(0.0)
    X0 = np.asarray(X0, dtype=float)
    _, Lam0L = curve(L)
    q0 = matrix_to_quat(Lam00)
    K0 = curve.curvature if hasattr(curve, "curvature") else _fd_curvature(curve, L)
    # constant curvature? (saves a Python call per RHS evaluation)
    ks = [K0(s) for s in np.linspace(0.0, L, 5)]
    if all(np.allclose(k, ks[0], rtol=0, atol=1e-15 / L) for k in ks):
        K0 = ks[0]
    Cn_inv = np.linalg.inv(_stiffness(C_N))
    Cm_inv = np.linalg.inv(_stiffness(C_M))
    F = np.asarray(tip_force, dtype=float)
    M = np.asarray(tip_moment, dtype=float) * np.ones(3)
    Lchar = max(L, np.linalg.norm(curve(L)[0] - X0))
    scale_m = np.linalg.norm(M) + np.linalg.norm(F) * Lchar
    scale_m = scale_m if scale_m > 0 else 1.0
    scale_n = np.linalg.norm(F) if np.linalg.norm(F) > 0 else 1.0
    six = bool(follower)

    def unpack(x, lam):
        if six:
            return x[:3] * scale_n, x[3:] * scale_m
        return lam * F, x * scale_m

    def residual(x, lam, tol):
        if not np.all(np.isfinite(x)):
            return np.full(x.size, 1e10)
        n, m0 = unpack(x, lam)
        sol = _integrate_cantilever(X0, q0, L, K0, Cn_inv, Cm_inv, n, m0, tol, atol)
        r = sol.y[:3, -1]
        Lam = quat_to_matrix(sol.y[3:, -1])
        Rinc = Lam @ Lam0L.T
        mL = m0 - np.cross(r - X0, n)
        Mt = lam * (Rinc @ M if follower_moment else M)
        res_m = (mL - Mt) / scale_m
        if six:
            return np.concatenate([(n - lam * (Rinc @ F)) / scale_n, res_m])
        return res_m

    def jacobian(x, lam, tol):
        # central differences with an absolute step: the unknowns are scaled to O(1), and
        # MINPACK's relative step breaks down for unknowns that are ~0 (e.g. 1e-75)
        h = 1e-6
        J = np.empty((x.size, x.size))
        for j in range(x.size):
            e = np.zeros(x.size)
            e[j] = h
            J[:, j] = (residual(x + e, lam, tol) - residual(x - e, lam, tol)) / (2 * h)
        return J

    # initial guess from the undeformed geometry: m(0) = M + (X(L) - X(0)) x F
    XL = np.asarray(curve(L)[0], dtype=float)
    m_lin = (M + np.cross(XL - X0, F)) / scale_m
    x_unit = np.concatenate([F / scale_n, m_lin]) if six else m_lin
    history = [(0.0, np.zeros_like(x_unit))]
    x = np.zeros_like(x_unit)
    n_load_steps = max(1, int(n_load_steps))
    for k in range(1, n_load_steps + 1):
        lam = k / n_load_steps
        if len(history) >= 2:
            (l1, x1), (l2, x2) = history[-2], history[-1]
            guess = x2 + (x2 - x1) * (lam - l2) / (l2 - l1)
        else:
            guess = lam * x_unit
        tol = rtol if k == n_load_steps else max(rtol, rtol_continuation)
        # xtol is near the ODE noise level: cap the evaluations, the residual check decides
        opts = {"xtol": 1e-13 if k == n_load_steps else 1e-9, "maxfev": 40 * (guess.size + 1)}
        sol = root(residual, guess, args=(lam, tol), method="hybr", jac=jacobian, options=opts)
        x = sol.x
        res = residual(x, lam, tol)
        if np.linalg.norm(res) > 1e-7:
            raise RuntimeError(
                f"shooting did not converge at load factor {lam}: |res| = "
                f"{np.linalg.norm(res):.3e} ({sol.message})"
            )
        history.append((lam, x.copy()))

    if np.linalg.norm(res) > 1e-10:
        warnings.warn(f"shooting residual {np.linalg.norm(res):.2e} > 1e-10", stacklevel=2)
    n, m0 = unpack(x, 1.0)
    sol = _integrate_cantilever(X0, q0, L, K0, Cn_inv, Cm_inv, n, m0, rtol, atol, dense=full_output)
    r_tip = sol.y[:3, -1].copy()
    Lam_tip = quat_to_matrix(sol.y[3:, -1])
    if full_output:
        return {
            "r_tip": r_tip,
            "Lambda_tip": Lam_tip,
            "R_tip": Lam_tip @ Lam0L.T,
            "n": n,
            "m0": m0,
            "residual": np.linalg.norm(res),
            "solution": sol,
        }
    return r_tip, Lam_tip


# ----------------------------------------------------------------------------------------
# exact elastica (independent check of the shooting)
# ----------------------------------------------------------------------------------------
def elastica_tip_force_exact(k):
    """Inextensible cantilever (Euler elastica) with a dead transverse tip force.

    ``k = P L^2 / EI``. With theta(s) the tangent angle, ``EI theta'' = -P cos theta``,
    ``theta(0) = 0``, ``theta'(L) = 0``; the first integral
    ``theta'^2 = 2 (P/EI)(sin a - sin theta)`` (``a`` = tip rotation) gives, after the
    substitution ``sin theta = sin a - u^2`` (regular integrands),

        sqrt(k) = int_0^sqrt(sin a) sqrt2 du / sqrt(1 - (sin a - u^2)^2)
        w/L     = (1/sqrt(k)) int_0^sqrt(sin a) sqrt2 (sin a - u^2) du
                  / sqrt(1 - (sin a - u^2)^2)
        x/L     = sqrt(2 sin a / k)

    Returns:
        ``(u/L, w/L, a)`` with ``u = L - x_tip`` (axial shortening), ``w`` the transverse
        tip deflection, ``a`` the tip rotation in radians.
    """
    sq2 = math.sqrt(2.0)

    def integral(a, weight):
        sa = math.sin(a)
        one_m_sa = 2.0 * math.sin(0.5 * (0.5 * math.pi - a)) ** 2  # 1 - sin a, accurately

        def f(u):
            v = sa - u * u
            return sq2 * weight(v) / math.sqrt((one_m_sa + u * u) * (1.0 + v))

        return quad(f, 0.0, math.sqrt(sa), epsabs=1e-15, epsrel=1e-13, limit=200)[0]

    sk = math.sqrt(k)
    a = brentq(
        lambda a: integral(a, lambda v: 1.0) - sk,
        1e-9,
        math.pi / 2 - 1e-9,
        xtol=1e-15,
        rtol=4 * np.finfo(float).eps,
    )
    w = integral(a, lambda v: v) / sk
    x = math.sqrt(2.0 * math.sin(a) / k)
    return 1.0 - x, w, a


def follower_elastica_exact(k):
    """Inextensible cantilever with a transverse *follower* tip force (always normal to
    the tip tangent, in the bending plane), ``k = P L^2 / EI < 3.437`` (tip rotation
    below pi/2).

    ``EI theta'' = -P cos(a - theta)``, ``theta(0) = 0``, ``theta'(L) = 0``; first integral
    ``theta'^2 = 2 (P/EI) sin(a - theta)``. With ``sin(a - theta) = u^2``:

        sqrt(k) = int_0^sqrt(sin a) sqrt2 du / sqrt(1 - u^4)
        x/L     = sqrt(2/k) int_0^sqrt(sin a) [cos a + sin a u^2 / sqrt(1 - u^4)] du
        w/L     = sqrt(2/k) int_0^sqrt(sin a) [sin a - cos a u^2 / sqrt(1 - u^4)] du

    Returns:
        ``(u/L, w/L, a)`` as :func:`elastica_tip_force_exact`.
    """
    sq2 = math.sqrt(2.0)

    def integral(a, f):
        return quad(f, 0.0, math.sqrt(math.sin(a)), epsabs=1e-15, epsrel=1e-13, limit=200)[0]

    sk = math.sqrt(k)

    def g(u):
        return sq2 / math.sqrt(1.0 - u**4)

    if k >= (integral(math.pi / 2 - 1e-12, g)) ** 2:
        raise ValueError("k too large: tip rotation would exceed pi/2")
    a = brentq(
        lambda a: integral(a, g) - sk,
        1e-12,
        math.pi / 2 - 1e-12,
        xtol=1e-15,
        rtol=4 * np.finfo(float).eps,
    )
    ca, sa = math.cos(a), math.sin(a)
    x = sq2 / sk * integral(a, lambda u: ca + sa * u * u / math.sqrt(1.0 - u**4))
    w = sq2 / sk * integral(a, lambda u: sa - ca * u * u / math.sqrt(1.0 - u**4))
    return 1.0 - x, w, a


# ----------------------------------------------------------------------------------------
# benchmark set-ups (used by the self-checks below)
# ----------------------------------------------------------------------------------------
MATTIASSON_TABLE = {
    1: (0.0564332, 0.3017208, 0.4613519),
    5: (0.3876284, 0.7137915, 1.2153681),
    10: (0.5549956, 0.810609, 1.4302855),
}


def mattiasson(k, L=1.0, EI=1.0, **kw):
    """Straight cantilever along x, dead tip force ``(0, 0, -P)``, ``P = k EI/L^2``,
    EA = GA = 1e9 EI/L^2. Returns ``(u/L, w/L, tip rotation)``. Pass ``follower=True``
    for the follower-force variant."""
    P = k * EI / L**2
    big = 1e9 * EI / L**2
    r, R = cantilever_shooting(
        straight_curve(L), (big, big, big), (EI, EI, EI), (0.0, 0.0, -P), **kw
    )
    _, angle = rotation_to_axis_angle(R)
    return (L - r[0]) / L, -r[2] / L, angle


def bathe_bolourchi(shear_factor=1.0, follower=False, **kw):
    """45-degree bend: R = 100, start (0,0,0), tangent (0,1,0), centre (100,0,0), unit
    square section, E = 1e7, nu = 0, G = E/2, GJ = 702885, tip force (0,0,600).
    Returns the tip position."""
    E, G, A = 1e7, 0.5e7, 1.0
    EI = E / 12.0
    curve = arc_curve(100.0, math.pi / 4, (0, 0, 0), (0, 1, 0), (100, 0, 0))
    C_N = (E * A, shear_factor * G * A, shear_factor * G * A)
    C_M = (702885.0, EI, EI)
    r, _ = cantilever_shooting(curve, C_N, C_M, (0.0, 0.0, 600.0), follower=follower, **kw)
    return r


def schwab_meijaard_23(**kw):
    """Schwab-Meijaard test 2.3: L = 1, E = 2.1e11, nu = 0.3, G = E/2.6, h = 0.02 (z),
    w = 0.005 (y), I_y = w h^3/12, I_z = h w^3/12, S_t = G h w^3/3, tip moment
    (25, 100, 0) fixed in space. Returns ``(r_tip, R_tip)``."""
    L, E = 1.0, 2.1e11
    G = E / 2.6
    h, w = 0.02, 0.005
    C_M = (G * h * w**3 / 3.0, E * w * h**3 / 12.0, E * h * w**3 / 12.0)
    return pure_end_moments(L, C_M, (25.0, 100.0, 0.0), **kw)


# ----------------------------------------------------------------------------------------
# 4. self-checks (pytest collects the test_* functions)
# ----------------------------------------------------------------------------------------
def test_rotation_utilities():
    rng = np.random.default_rng(0)
    for _ in range(50):
        th = rng.normal(size=3)
        th *= rng.uniform(0, math.pi) / np.linalg.norm(th)
        R = axis_angle_to_rotation(th)
        assert np.allclose(rotation_vector(R), th, atol=1e-12)
        assert np.allclose(quat_to_matrix(matrix_to_quat(R)), R, atol=1e-14)
    # angle pi and 0
    R = axis_angle_to_rotation((0, 1, 0), math.pi)
    axis, angle = rotation_to_axis_angle(R)
    assert abs(angle - math.pi) < 1e-14 and abs(abs(axis[1]) - 1) < 1e-14
    axis, angle = rotation_to_axis_angle(np.eye(3))
    assert angle == 0.0


def test_rollup_circle():
    L, EI = 1.0, 2.0
    for lam in (0.25, 1.0, 2.0):
        phi = 2 * math.pi * lam
        M = phi * EI / L
        r, R = pure_end_moments(L, (3.0, EI, 5.0), (0.0, M, 0.0))
        exact = np.array([L * math.sin(phi) / phi, 0.0, -L * (1 - math.cos(phi)) / phi])
        assert np.max(np.abs(r - exact)) < 1e-9 * L
        assert np.max(np.abs(R - axis_angle_to_rotation((0, 1, 0), phi))) < 1e-9


def test_pure_moment_helix_exact():
    L, GJ, EI = 2.0, 0.7, 1.3
    m = np.array([0.9, -1.7, 2.4])
    r, R = pure_end_moments(L, (GJ, EI, EI), m)
    re, Re = pure_end_moments_isotropic_exact(L, GJ, EI, m)
    assert np.max(np.abs(r - re)) < 1e-9 * L
    assert np.max(np.abs(R - Re)) < 1e-9
    r2, R2 = pure_end_moments(L, (GJ, EI, EI), m, method="matrix")
    assert np.max(np.abs(r2 - re)) < 1e-9 * L and np.max(np.abs(R2 - Re)) < 1e-9


def test_elastica_exact_vs_table():
    for k, ref in MATTIASSON_TABLE.items():
        assert np.max(np.abs(np.array(elastica_tip_force_exact(k)) - ref)) < 1e-6


def test_mattiasson_shooting():
    for k, ref in MATTIASSON_TABLE.items():
        got = np.array(mattiasson(k, n_load_steps=10 if k > 1 else 4))
        assert np.max(np.abs(got - ref)) < 1e-6, (k, got)
        exact = np.array(elastica_tip_force_exact(k))
        # EA = GA = 1e9 EI/L^2 changes the answer by O(1e-9)
        assert np.max(np.abs(got - exact)) < 2e-8, (k, got - exact)


def test_follower_cantilever_exact():
    for k in (1.0, 3.0):
        got = np.array(mattiasson(k, follower=True, n_load_steps=5))
        exact = np.array(follower_elastica_exact(k))
        assert np.max(np.abs(got - exact)) < 5e-8, (k, got - exact)


def test_shooting_pure_moment_matches_pure_end_moments():
    m = np.array([0.3, 1.1, -0.6])
    C_M = (0.8, 1.0, 2.5)
    r1, R1 = pure_end_moments(1.0, C_M, m)
    r2, R2 = cantilever_shooting(
        straight_curve(1.0), (1e3, 1e3, 1e3), C_M, (0, 0, 0), m, n_load_steps=2
    )
    assert np.max(np.abs(r1 - r2)) < 1e-9 and np.max(np.abs(R1 - R2)) < 1e-9


def test_arc_curve_frame():
    c = arc_curve(100.0, math.pi / 4, (0, 0, 0), (0, 1, 0), (100, 0, 0))
    X, Lam = c(c.length)
    s2 = math.sqrt(0.5)
    assert np.allclose(X, [100 - 100 * s2, 100 * s2, 0], atol=1e-12)
    assert np.allclose(Lam[:, 0], [s2, s2, 0]) and np.allclose(Lam[:, 2], [0, 0, 1])
    assert abs(np.linalg.det(Lam) - 1) < 1e-14
    assert np.allclose(c.curvature(10.0), [0, 0, -0.01], atol=1e-15)
    # finite-difference curvature for plain callables agrees
    assert np.allclose(_fd_curvature(c, c.length)(10.0), [0, 0, -0.01], atol=1e-12)


def test_bathe_bolourchi_45_bend():
    r = bathe_bolourchi(1.0)
    # published range (Bathe-Bolourchi, Simo-Vu-Quoc, Crisfield, ...)
    assert 15.5 < r[0] < 15.95 and 46.8 < r[1] < 47.25 and 53.3 < r[2] < 53.75, r


def test_schwab_meijaard_runs():
    r, R = schwab_meijaard_23()
    r2, R2 = schwab_meijaard_23(method="matrix")
    assert np.max(np.abs(r - r2)) < 1e-9 and np.max(np.abs(R - R2)) < 1e-9


# ----------------------------------------------------------------------------------------
def _fmt(v, d):
    return "(" + ", ".join(f"{x:.{d}f}" for x in np.atleast_1d(v)) + ")"


def main():
    np.set_printoptions(precision=12)
    print("roll-up (L=1, EI_y=2): tip error vs exact circle")
    for lam in (0.25, 1.0, 2.0):
        phi = 2 * math.pi * lam
        r, R = pure_end_moments(1.0, (3.0, 2.0, 5.0), (0.0, phi * 2.0, 0.0))
        ex = np.array([math.sin(phi) / phi, 0.0, -(1 - math.cos(phi)) / phi])
        print(f"  lambda={lam}: r_tip={_fmt(r, 12)}  |err|={np.max(np.abs(r - ex)):.2e}")

    print("Mattiasson elastica (u/L, w/L, tip rotation):")
    for k, ref in MATTIASSON_TABLE.items():
        got = mattiasson(k)
        ex = elastica_tip_force_exact(k)
        print(
            f"  k={k:2d} shooting {_fmt(got, 10)}  exact elastica {_fmt(ex, 10)}  "
            f"table {ref}  max|shoot-table|={np.max(np.abs(np.array(got) - ref)):.1e}"
        )

    print("Bathe-Bolourchi 45-degree bend, tip position:")
    for kfac, name in ((1.0, "k=1  "), (5.0 / 6.0, "k=5/6")):
        print(f"  dead     {name}: {_fmt(bathe_bolourchi(kfac), 7)}")
    for kfac, name in ((1.0, "k=1  "), (5.0 / 6.0, "k=5/6")):
        print(f"  follower {name}: {_fmt(bathe_bolourchi(kfac, follower=True), 7)}")

    print("Schwab-Meijaard 2.3 (m = (25, 100, 0)):")
    r, R = schwab_meijaard_23()
    axis, angle = rotation_to_axis_angle(R)
    print(f"  tip displacement {_fmt(r - np.array([1.0, 0, 0]), 10)}")
    print(f"  axis {_fmt(axis, 10)}  angle {angle:.10f} rad")
    print(f"  rotation vector {_fmt(rotation_vector(R), 10)}")


if __name__ == "__main__":
    main()
