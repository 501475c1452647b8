r"""Critical points on an arc-length path: classified by the inertia of the tangent, located,
and the secondary branch entered by mode injection.

A simple critical point of a conservative path R(w, λ) = 0 is where one eigenvalue μ of the
symmetric tangent K crosses zero, so the number of negative eigenvalues (the inertia,
:mod:`beamfx.solvers.inertia`) changes by one across it. Along the path (w(s), λ(s)),
K w' = λ' f; with φ the null vector at the point:

* a **limit point** has φᵀf ≠ 0, so λ' = 0 there and λ' changes sign: the load factor has
  an extremum. The arc-length predictor's sign rule (keep moving forward) flips with it;
* a **bifurcation point** has φᵀf = 0: λ' keeps its sign, and another branch crosses.

So a step whose inertia changes while the predictor sign does not has passed a bifurcation.

**Location** (:func:`locate`): by the arc length x of a point from the state before the step,
the step is redone to x (same constraint, same predictor) and the eigenvalue μ(x) of K nearest
zero computed by inverse iteration with the factorisation (:func:`smallest_eigenpair`). The
root of μ(x) is sought by regula falsi with the Illinois modification inside a bracket that
the inertia keeps (a probe belongs to the side whose count it has); bisection when μ does not
change sign across the bracket (another eigenvalue is nearer zero). A probe whose μ has the
sign of the other side is at round-off from the root and ends the search. Not an extended
system.

**Branch switching** (mode injection): from the located point (w_c, λ_c), the first step on
the secondary branch starts from the predictor Δw = ξ φ, Δλ = 0 with ξ φ of arc length
``switch_amplitude``, and the arc-length corrector (a sphere about w_c) converges onto the
branch whose tangent is φ (Wriggers & Simo 1990; Wagner & Wriggers 1988).

References:
    P. Wriggers, J. C. Simo, "A general procedure for the direct computation of turning and
    bifurcation points", Int. J. Numer. Meth. Engng. 30 (1990) 155–176.
    W. Wagner, P. Wriggers, "A simple method for the calculation of postcritical branches",
    Engineering Computations 5 (1988) 103–109.
"""

from typing import NamedTuple

KINDS = ("limit", "bifurcation")


class CriticalPoint(NamedTuple):
    """A critical point passed by an arc-length step.

    Attributes:
        kind: "limit" (the load factor turns back) or "bifurcation".
        step: the step that passed it (between the accepted states ``step - 1`` and ``step``).
        interval: load factors (before, after) of that step.
        negative_before, negative_after: negative eigenvalues of the tangent at both ends.
        load_factor: located load factor (bifurcations; None for a limit point, whose
            extremum the path's parabola gives: :func:`beamfx.analyses.continuation.limit_points`).
        eigenvalue: the eigenvalue of K nearest zero at the located point (Euclidean).
        probes: solves spent locating it.
        switched: the trace left the primary path here along the secondary branch.
        bracket: (λ, λ) of the nearest probes on either side of the located point: the
            inertia says the point lies between them (its precision).
    """

    kind: str
    step: int
    interval: tuple
    negative_before: int
    negative_after: int
    load_factor: float | None = None
    eigenvalue: float | None = None
    probes: int = 0
    switched: bool = False
    bracket: tuple | None = None


def classify(before, after, forward_before, forward_after):
    """The kind of critical point a step passed: "limit", "bifurcation" or None.

    Args:
        before: the inertia (negative eigenvalues) at the step's start.
        after: the inertia at its end.
        forward_before: the predictor's load direction (±1) at the start.
        forward_after: the same at the end.
    """
    if before is None or after is None or before == after:
        return None
    return "limit" if forward_before != forward_after else "bifurcation"


def smallest_eigenpair(A, solve, x, its=60, rtol=1e-9, metric=None):
    """The eigenvalue of the symmetric ``A`` nearest zero and its vector, by inverse iteration
    x ← A⁻¹x / ‖A⁻¹x‖ with the factorisation in ``solve(rhs, out)``; μ = xᵀAx.

    With ``metric`` (local 0/1 weights m of the owned entries) the pencil A x = μ M x,
    M = diag(m), instead: x ← A⁻¹Mx / ‖A⁻¹Mx‖_M. For a saddle-point tangent
    [[K_uu, Bᵀ], [B, −S]] with m = 1 on the kinematic unknowns and 0 on the force unknowns,
    its finite eigenvalues are those of the condensed stiffness K_uu + BᵀS⁻¹B (of K_uu on
    ker B where S = 0): the displacement form's μ, not the force block's (other units).

    Args:
        A: the assembled matrix (PETSc Mat).
        solve: ``solve(rhs, out)``: out = A⁻¹ rhs with A's factorisation.
        x: PETSc Vec, the starting vector; holds the eigenvector on return (unit in the
            metric's norm).
        its: at most this many iterations.
        rtol: stop when ‖Ax − μMx‖ ≤ rtol ‖A‖∞.
        metric: numpy array of the weights m, or None (M = I).

    Returns:
        (μ, iterations)
    """
    from petsc4py import PETSc

    y, r, b = x.duplicate(), x.duplicate(), x.duplicate()

    def weigh(v, out):  # out = M v
        v.copy(out)
        if metric is not None:
            out.setArray(v.getArray(readonly=True) * metric)

    scale = A.norm(PETSc.NormType.NORM_INFINITY)
    weigh(x, b)
    b.copy(x)
    x.normalize()
    mu = 0.0
    for k in range(1, its + 1):
        weigh(x, b)
        solve(b, y)
        if metric is None:
            y.normalize()
            A.mult(y, r)
            mu = y.dot(r)
            r.axpy(-mu, y)
        else:  # A y = M x: μ = yᵀMx / yᵀMy and the residual M x − μ M y, without yᵀAy
            # (whose force part cancels: B u = S n holds only to round-off, times n)
            weigh(y, r)
            size = y.dot(r) ** 0.5
            mu = y.dot(b) / size**2
            r.aypx(-mu, b)  # r = b − μ M y
            r.scale(1.0 / size)
            y.scale(1.0 / size)
        y.copy(x)
        if r.norm() <= rtol * scale:
            break
    for v in (y, r, b):
        v.destroy()
    return mu, k


def locate(probe, end, before, tol, max_probes=40):
    """The arc length x_c in (0, ``end``) where the inertia changes from ``before``.

    Args:
        probe: ``probe(x) -> (count, μ)``: inertia and eigenvalue nearest zero at the point of
            the path at arc length x from the start of the step (collective).
        end: the step's arc length; probe(0) has count ``before``, probe(end) another.
        before: the inertia at the step's start.
        tol: stop when the bracket, or the last move of the estimate, is below tol · end.
        max_probes: at most this many probes.

    Returns:
        (x_c, probes): the last estimate, at which ``probe`` was evaluated last.
    """
    a, b = 0.0, end
    (_, fa), (_, fb) = probe(a), probe(b)
    n, x_old, stale = 2, None, None
    while n < max_probes:
        secant = fa > 0 > fb or fa < 0 < fb
        x = b - fb * (b - a) / (fb - fa) if secant else 0.5 * (a + b)
        count, mu = probe(x)
        n += 1
        if (count == before) != (mu > 0) and (fa > 0) == (count == before):
            return x, n  # μ's sign disagrees with the inertia: it is at round-off, zero
        if count == before:
            a, fa = x, mu
            fb = 0.5 * fb if stale == "b" else fb  # Illinois: the end kept twice weighs less
            stale = "b"
        else:
            b, fb = x, mu
            fa = 0.5 * fa if stale == "a" else fa
            stale = "a"
        if b - a <= tol * end or (x_old is not None and abs(x - x_old) <= tol * end):
            return x, n
        x_old = x
    return x, n


__all__ = ["KINDS", "CriticalPoint", "classify", "locate", "smallest_eigenpair"]
