r"""Linearised buckling: det(K* + μ K_g) = 0 about a state (w*, λ*) on a load path.

The path direction dw/dλ solves K* dw = −∂F/∂λ (the load vector), with the rate of any
prescribed values on the constrained dofs. Two choices of K_g (``kg``):

* ``"stress"`` (default, the classical one): the stress (initial-stress) stiffness of the
  section force and moment rates Ṅ = C_N Γ̇, Ṁ = C_M K̇ along the path,
  K_σ(δw, Δw) = ∫ Ṅ·δ²Γ[δw, Δw] + Ṁ·δ²K[δw, Δw] ds at w*, plus the load-stiffness rate
  (tangent at λ* + 1 minus tangent at λ*, exact because the residual is affine in λ). Only
  second derivatives of the strains: it compiles like the tangent. The expansion is
  SPACAR's det(K0 + λ K_g) = 0 (Schwab & Meijaard 2009).
* ``"path"``: the full derivative dK/dλ along w(λ* + h) = w* + h dw by a central difference
  of compiled tangents (a third UFL derivative of the rotation energy takes minutes to compile,
  DOLFINx notes §5). It also holds the initial-displacement matrix Ḃᵀ C B + Bᵀ C Ḃ, which
  scales with the section stiffness; the first-order expansion then drops terms of the same
  size at second order. Right when the pre-buckling path has no rotation (Euler buckling;
  error ~ P/EA), and as λ* → λ_cr; wrong far from the critical point when the path rotates
  (lateral buckling: a spurious root ∝ 1/sqrt(GA)). The quaternion penalty's share (its stiff
  rank-one k_p q qᵀ turns with q) is removed: on an equilibrium path its multiplier is zero.

:func:`solve_buckling` with ``about="undeformed"``: the classical linear buckling analysis,
pre-stress from one linear solve under the reference load (load factor 1) about the
undeformed state, critical load factors = μ. ``about="current"``: about the current
(pre-loaded, deformed) ``model.w`` at the current load factor λ*, critical factors λ* + μ.

``sign``: the roots μ > 0 (loads increased, the default), μ < 0 (loads reversed: a column in
tension buckles at −P_cr) or both, nearest zero first. The inertia of K* (its negative
eigenvalues, :mod:`beamfx.solvers.inertia`) says how many critical points the state has
passed: beyond one, the lowest positive root is not the first buckling load, and the roots
below λ* (μ < 0) are those passed.
"""

import time
from typing import NamedTuple

import numpy as np
import ufl

from ..geometry.mesh import mesh_size
from ..physics import coupled, energy, mixed
from ..physics.kinematics import strains
from ..solvers.eigen import solve_eigen
from ..solvers.forms import compile_form
from .dofs import constrained_dofs, subspace_dofs
from .mixed import force_unknowns
from .modal import to_functions

SIGNS = ("positive", "negative", "both")


class BucklingResult(NamedTuple):
    """Critical load factors, their modes and the pre-stress path of a buckling analysis."""

    load_factors: np.ndarray  # critical load factors λ* + μ, smallest |μ| of the sign first
    increments: np.ndarray  # μ: load factor beyond the state analysed
    modes: tuple  # dolfinx Functions on model.W
    residuals: np.ndarray
    path: object  # dolfinx Function: dw/dλ at the state analysed (the linear pre-stress state
    # per unit load factor for about="undeformed")
    seconds: dict
    negative_eigenvalues: int | None = None  # of K* (None: non-conservative loads, not counted)
    sought: int = 0  # eigenpairs asked of SLEPc (roots of both signs and complex ones)
    converged: int = 0  # eigenpairs SLEPc converged (fewer than sought: all it could find)
    other_sign: tuple = ()  # real finite roots λ* + μ of the other sign, nearest first


def _tangent(A, J_form, bcs, diagonal):
    import dolfinx.fem.petsc as fp

    A.zeroEntries()
    fp.assemble_matrix(A, J_form, bcs=bcs, diagonal=diagonal)
    A.assemble()
    return A


def path_tangent(model, J_form, F_form):
    """dw/dλ at the current state: K dw = −∂F/∂λ, with the rate of the prescribed values on the
    constrained dofs (both with the load factor unchanged on return); the solve is refined
    iteratively (:func:`refined_solve`: the mixed form's redundant forces)."""
    import dolfinx.fem.petsc as fp
    from dolfinx import fem
    from petsc4py import PETSc

    from ..solvers.assembly import assemble_load

    lam = float(model.load_factor.value)
    # rate of the prescribed values, by a central difference of their (smooth) definitions
    g = []
    for h in (1e-3, -1e-3):
        x = fp.create_vector(F_form)
        x.set(0.0)
        model.set_load_factor(lam + h)
        fp.set_bc(x, model.bcs)
        g.append(x)
    model.set_load_factor(lam)
    dg = g[0]
    dg.axpy(-1.0, g[1])
    dg.scale(1 / 2e-3)
    g[1].destroy()

    f = fp.create_vector(F_form)
    assemble_load(f, F_form, model.load_factor, model.bcs)
    A = fp.assemble_matrix(J_form)  # without conditions: lifting of the prescribed rates
    A.assemble()
    f.axpy(-1.0, A * dg)
    fixed = constrained_dofs(model.bcs)
    with f.localForm() as f_local, dg.localForm() as g_local:
        f_local.array[fixed] = g_local.array[fixed]
    _tangent(A, J_form, model.bcs, 1.0)

    ksp = PETSc.KSP().create(model.comm)
    ksp.setOperators(A)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    dw = fem.Function(model.W, name="path_tangent")
    refined_solve(ksp, A, f, dw.vector)
    dw.x.scatter_forward()
    for obj in (ksp, A, f, dg):
        obj.destroy()
    return dw


#: iterative refinement of the path solve: at most this many corrections, each from the
#: residual of the last (:func:`refined_solve`)
REFINE_STEPS = 4


def refined_solve(ksp, A, b, x, steps=None):
    """Solve A x = b by the factorisation of ``ksp``, then refine: x += A⁻¹ (b − A x)
    while the residual falls by at least half (at most ``steps`` times); returns the number
    of corrections kept.

    The mixed form's tangent of a stiff frame whose pinned truss is statically indeterminate
    (posts and struts of a lattice) is nearly singular: its redundant axial forces n_s
    (Bᵀ n_s = 0) are fixed by the compliance alone, −S n_s = …, with S ~ 1/EA, so one solve
    leaves them an error of about eps·‖K‖/S (1e-5 of the post force at EA × 1e8 on the
    lattice, which moved its buckling load by 2e-6). Their residual b − A x is computed
    accurately (the displacements are O(S) there), so a few corrections recover them."""
    steps = REFINE_STEPS if steps is None else steps
    ksp.solve(b, x)
    r = b.duplicate()
    dx = b.duplicate()
    A.mult(x, r)
    r.aypx(-1.0, b)
    norm, kept = r.norm(), 0
    for _ in range(steps):
        if norm == 0.0:
            break
        ksp.solve(r, dx)
        x.axpy(1.0, dx)
        A.mult(x, r)
        r.aypx(-1.0, b)
        new = r.norm()
        if new > 0.5 * norm:
            if new > norm:  # no better: undo
                x.axpy(-1.0, dx)
            else:
                kept += 1
            break
        norm, kept = new, kept + 1
    r.destroy()
    dx.destroy()
    return kept


def penalty_tangent(model):
    """Second variation of the quaternion penalty alone (None where the residual has none: the
    linear kinematics and the planar model, whose rotation is an angle), on the model's
    penalty measure (the one of its residual)."""
    if not model.kin.finite or model.kin.plane:
        return None
    rot = ufl.split(model.w)[1]
    Pi = energy.quaternion_penalty(rot, model.k_penalty, model.penalty_measure())
    v, dw = ufl.TestFunction(model.W), ufl.TrialFunction(model.W)
    return ufl.derivative(ufl.derivative(Pi, model.w, v), model.w, dw)


def stress_stiffness_ufl(model, w_star, dw):
    """K_σ (UFL): second variation at ``model.w`` of ∫ Ṅ·Γ(w) + Ṁ·K(w) ds, with the section
    force and moment rates Ṅ = C_N Γ̇, Ṁ = C_M K̇ (C Γ̇ for a matrix section) at ``w_star`` in the path direction ``dw``
    (both Functions, held fixed). In the mixed form Ṅ is the force part of ``dw``: no EA or
    GA multiplies a small strain rate."""
    kin, d = model.kin, model.discretisation
    G_star, K_star = strains(kin, *ufl.split(w_star)[:2], d.t0, d.Lam0)
    G_dot, K_dot = ufl.derivative(G_star, w_star, dw), ufl.derivative(K_star, w_star, dw)
    Gamma, K = strains(kin, *ufl.split(model.w)[:2], d.t0, d.Lam0)
    if getattr(model, "mixed", False):  # Ṅ is the path's own section force rate
        C = None if d.matrices is None else d.matrices.C
        N_dot = model.section_force(dw)
        Pi = mixed.stress_work(N_dot, K_dot, Gamma, K, d.C_M, d.dx_shear, d.dx, C)
    elif d.matrices is None:
        N, M = d.C_N * G_dot, d.C_M * K_dot
        Pi = ufl.dot(N, Gamma) * d.dx_shear + ufl.dot(M, K) * d.dx
    else:  # the same split of the coupled energy as the model's (physics/coupled.py)
        Pi = coupled.strain_bilinear(G_dot, K_dot, Gamma, K, d.matrices.C, d.dx_shear, d.dx)
    v, dw_ = ufl.TestFunction(model.W), ufl.TrialFunction(model.W)
    return ufl.derivative(ufl.derivative(Pi, model.w, v), model.w, dw_)


def stress_stiffness(model, J_form, S_form):
    """K_σ plus the load-stiffness rate, with zero constrained rows and columns."""
    import dolfinx.fem.petsc as fp

    lam = float(model.load_factor.value)
    Kg = fp.assemble_matrix(S_form, bcs=model.bcs, diagonal=0.0)
    Kg.assemble()
    for value, sign in ((lam + 1.0, 1.0), (lam, -1.0)):
        model.load_factor.value = value  # only the loads: the conditions do not enter J
        A = fp.assemble_matrix(J_form, bcs=model.bcs, diagonal=0.0)
        A.assemble()
        Kg.axpy(sign, A)
        A.destroy()
    model.load_factor.value = lam
    return Kg


def geometric_stiffness(model, J_form, P_form, dw, eps=1e-4):
    """K_g = dK/dλ along w(λ* + h) = w* + h dw, load factor λ* + h, by a central difference.

    h = eps / max|dw| (displacements over the model's size, quaternion components as they
    are), so the perturbation is small in rotation and in strain but far above round-off.
    Constrained rows and columns are zero. The penalty's share (``P_form``) is removed.
    """
    import dolfinx.fem.petsc as fp

    w, lam = model.w, float(model.load_factor.value)
    w_star = w.x.array.copy()
    h = eps / max(_scaled_max(model, dw), 1e-300)
    mats = []
    for sign in (1.0, -1.0):
        w.x.array[:] = w_star + sign * h * dw.x.array
        w.x.scatter_forward()
        model.set_load_factor(lam + sign * h)
        A = fp.assemble_matrix(J_form, bcs=model.bcs, diagonal=0.0)
        A.assemble()
        if P_form is not None:
            Ap = fp.assemble_matrix(P_form, bcs=model.bcs, diagonal=0.0)
            Ap.assemble()
            A.axpy(-1.0, Ap)
            Ap.destroy()
        mats.append(A)
    w.x.array[:] = w_star
    w.x.scatter_forward()
    model.set_load_factor(lam)
    Kg, minus = mats
    Kg.axpy(-1.0, minus)
    Kg.scale(1 / (2 * h))
    minus.destroy()
    return Kg


def _scaled_max(model, f):
    """The largest of |u| / model size and |rotation components| over the dofs. Collective."""
    from mpi4py import MPI

    size = mesh_size(model.mesh.mesh)  # the whole model's, not this rank's part's
    local = 0.0
    for sub, scale in ((0, 1.0 / max(size, 1e-300)), (1, 1.0)):
        dofs = subspace_dofs(model.W, sub)
        if len(dofs):
            local = max(local, scale * np.abs(f.x.array[dofs]).max())
    return model.comm.allreduce(local, op=MPI.MAX)


#: a root μ is real when |Im μ| ≤ max(REAL_TOL, its relative residual) |μ|, the allowance
#: capped at REAL_CAP: a real double root (bending in two planes) comes out of the unsymmetric
#: solve as a complex pair split by round-off, |Im μ|/|μ| = 2e-8 with EA, GA ×1e4 and 1e-5
#: with ×1e8 on SM 2.7's shaft, within the pair's own residual (3e-7, 7e-3); genuinely
#: complex roots (dead or follower torque) have |Im μ| of the order of |μ|
REAL_TOL, REAL_CAP = 1e-8, 1e-3


def is_real(mu, residual):
    """Whether the computed root ``mu`` with relative residual ``residual`` (SLEPc's
    ‖Ax − μBx‖/(|μ|‖x‖)) is real to round-off (:data:`REAL_TOL`)."""
    allowance = min(max(REAL_TOL, residual), REAL_CAP)
    return abs(mu.imag) <= allowance * abs(mu)


def _keep(mu, sign, n_modes, residuals):
    """Indices of the real finite roots μ of ``sign`` (:data:`SIGNS`), nearest zero first
    (:func:`is_real` with the roots' ``residuals``; their real parts are used). An infinite μ
    (a K_g without that direction: no load reaches it) is no buckling load."""
    real = [i for i in range(len(mu)) if np.isfinite(mu[i]) and is_real(mu[i], residuals[i])]
    wanted = {"positive": lambda m: m > 0, "negative": lambda m: m < 0, "both": lambda m: True}
    return sorted((i for i in real if wanted[sign](mu[i].real)), key=lambda i: abs(mu[i]))[:n_modes]


def solve_buckling(
    model,
    n_modes=4,
    about="undeformed",
    kg="stress",
    options=None,
    prefix="beamfx_buckling_",
    eps=1e-4,
    sign="positive",
    most=None,
):
    """The ``n_modes`` critical load factors of ``sign`` nearest the state, and their modes.

    Solves K* x = μ (−K_g) x (GNHEP: with non-conservative loads K_g is unsymmetric) by
    shift-and-invert at μ = 0 and keeps the real μ of ``sign`` ("positive", "negative" or
    "both"), nearest zero first. ``about``: "undeformed" (the classical linear buckling
    analysis; the model is left undeformed at load factor 0) or "current" (about ``model.w``
    at the current load factor, both left unchanged). ``kg``: "stress" or "path" (module doc);
    ``eps`` is the relative step of "path". The inertia of K* is counted for conservative
    loads (``negative_eigenvalues``). ``most``: the most eigenpairs the problem has (its free
    dofs, :mod:`.mode_count`), which caps the pairs asked of SLEPc. Fewer converged pairs than
    asked are not an error: the result holds the roots found (``sought``, ``converged``),
    possibly fewer than ``n_modes`` or none (loads that compress nothing).

    Raises:
        ValueError: for the linear kinematics (no geometric stiffness) or a bad option.
    """
    import dolfinx.fem.petsc as fp
    from dolfinx import fem

    _check(model, about, kg, sign)
    t0 = time.perf_counter()
    if about == "undeformed":
        model.reset()
        model.set_load_factor(0.0)
    J_form, F_form = compile_form(model.J), compile_form(model.F)
    t1 = time.perf_counter()
    dw = path_tangent(model, J_form, F_form)
    t2 = time.perf_counter()
    if kg == "stress":
        w_star = fem.Function(model.W)
        w_star.x.array[:] = model.w.x.array
        S_form = compile_form(stress_stiffness_ufl(model, w_star, dw))
    else:
        P = penalty_tangent(model)
        P_form = compile_form(P) if P is not None else None
    t3 = time.perf_counter()
    K = fp.assemble_matrix(J_form, bcs=model.bcs, diagonal=1.0)
    K.assemble()
    negative = _inertia(model, K)
    if kg == "stress":
        Kg = stress_stiffness(model, J_form, S_form)
    else:
        Kg = geometric_stiffness(model, J_form, P_form, dw, eps)
    Kg.scale(-1.0)
    t4 = time.perf_counter()
    nev = 2 * n_modes + 2  # roots of both signs come out; keep those of the sign asked
    nev = max(1, min(nev, most)) if most is not None else nev
    pairs = solve_eigen(K, Kg, nev, 0.0, prefix, options, hermitian=False, least=0)
    K.destroy()
    Kg.destroy()
    seconds = {
        "compile": (t1 - t0) + (t3 - t2),
        "assemble": (t2 - t1) + (t4 - t3),
        "solve": pairs.seconds,
    }
    return _result(model, pairs, sign, n_modes, (dw, seconds, negative, nev))


def _result(model, pairs, sign, n_modes, rest):
    """The :class:`BucklingResult` of the roots μ ``pairs`` (the vectors not kept destroyed);
    ``rest``: the path tangent, the seconds, the negative eigenvalues and the pairs sought."""
    dw, seconds, negative, nev = rest
    mu = pairs.values
    keep = _keep(mu, sign, n_modes, pairs.residuals)
    other = {"positive": "negative", "negative": "positive"}.get(sign)
    opposite = _keep(mu, other, n_modes, pairs.residuals) if other else []
    for i in sorted(set(range(len(mu))) - set(keep)):  # (destroy is collective: one order)
        pairs.vectors[i].destroy()
    lam = float(model.load_factor.value)
    return BucklingResult(
        lam + mu.real[keep],
        mu.real[keep],
        to_functions(model, [pairs.vectors[i] for i in keep]),
        pairs.residuals[keep],
        dw,
        seconds,
        negative,
        nev,
        len(mu),
        tuple((lam + mu.real[opposite]).tolist()),
    )


def _check(model, about, kg, sign):
    """Raise ValueError for a bad option or the linear kinematics."""
    if about not in ("undeformed", "current"):
        raise ValueError(f"about must be 'undeformed' or 'current', got {about!r}")
    if kg not in ("stress", "path"):
        raise ValueError(f"kg must be 'stress' or 'path', got {kg!r}")
    if sign not in SIGNS:
        raise ValueError(f"sign must be one of {SIGNS}, got {sign!r}")
    if not model.kin.finite:
        raise ValueError("buckling needs the finite kinematics: the linear model has no K_g")


def _inertia(model, K):
    """Negative eigenvalues of the tangent ``K`` (None for state-dependent loads, whose
    tangent is unsymmetric: no inertia)."""
    from ..solvers.inertia import InertiaCounter
    from .static import state_dependent_loads

    if state_dependent_loads(model):
        return None
    counter = InertiaCounter(model.comm, "beamfx_buckling_inertia_")
    try:
        return counter.count(K) - force_unknowns(model)
    finally:
        counter.destroy()
