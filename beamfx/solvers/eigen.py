"""Generalised eigenproblems A x = λ B x with SLEPc: Krylov–Schur and shift-and-invert (MUMPS).

Knows nothing of beams. Constrained rows are expected as identity in A and zero in B, which puts
them at λ = ∞, away from any finite target (DOLFINx notes §5).
"""

import time
from typing import NamedTuple

import numpy as np

from .options import petsc_options

DEFAULT_OPTIONS = {
    "eps_type": "krylovschur",
    "eps_tol": 1e-10,
    "eps_max_it": 200,
    "st_type": "sinvert",
    "st_ksp_type": "preonly",
    "st_pc_type": "lu",
    "st_pc_factor_mat_solver_type": "mumps",
}


class EigenPairs(NamedTuple):
    """Converged eigenpairs with their residuals, iterations and wall time."""

    values: np.ndarray  # complex eigenvalues, nearest to the target first
    vectors: tuple  # real parts of the eigenvectors (PETSc Vec)
    residuals: np.ndarray  # ‖A x − λ B x‖ / (|λ| ‖x‖) per pair (SLEPc's relative error)
    iterations: int
    seconds: float


def _reason_name(solver):
    """The SLEPc name of the solver's converged reason (EPS or PEP)."""
    code = solver.getConvergedReason()
    names = vars(type(solver).ConvergedReason)
    return next((k for k, v in names.items() if v == code and not k.startswith("_")), str(code))


def _too_few(solver, n, nev, prefix, asked=None):
    """The :class:`~beamfx.solvers.snes.SolveFailed` of a solve that converged ``n`` < ``nev``
    pairs, with the values it got; the solver is destroyed. ``asked``: what the user asked
    for, in words (e.g. "193 modes"), when it is not the ``nev`` pairs sought."""
    from .snes import SolveFailed

    got = [complex(solver.getEigenvalue(i)) for i in range(n)]
    reason, its = _reason_name(solver), solver.getIterationNumber()
    solver.destroy()
    values = [v.real if v.imag == 0 else [v.real, v.imag] for v in got]
    asked = asked or f"{nev} eigenpairs"
    remedy = (
        "ask for fewer modes ([analysis] modes; the model may have fewer finite eigenvalues "
        "than asked: refine it) or give SLEPc more iterations ([solver] eps_max_it, default 200)"
    )
    return SolveFailed(
        f"eigen solve ({prefix}): found {n} of the {asked} asked ({n} of {nev} eigenpairs "
        f"converged after {its} iterations, SLEPc {reason}); cause: eigen solve; remedy: "
        f"{remedy}",
        cause="eigen solve",
        remedy=remedy,
        details={"requested": nev, "converged": n, "eigenvalues": values, "reason": reason},
    )


def solve_and_collect(solver, A, nev, prefix, keep, least=None, asked=None):
    """Run a configured SLEPc EPS or PEP ``solver`` (operators of the size of ``A``), check
    that ``least`` (default ``nev``) pairs converged, and return (values, [keep(vr, vi) per
    pair], errors, iterations); the solver is destroyed. ``asked``: what the user asked for,
    for the message (:func:`_too_few`).

    Fewer than ``nev`` but at least ``least`` pairs are accepted only when SLEPc ended
    converged (the pairs it found are all it could find); when it stopped on a divergence
    (its iteration limit, a breakdown) the shortfall is a numerical failure.

    Raises:
        SolveFailed: if fewer than ``least`` pairs converged, or fewer than ``nev`` after a
            divergence (cause "eigen solve"; ``details`` holds the eigenvalues it found).
    """
    solver.solve()
    n = solver.getConverged()
    diverged = n < nev and solver.getConvergedReason() < 0
    if n < (nev if least is None else least) or diverged:
        raise _too_few(solver, n, nev, prefix, asked)
    values, vectors, errors = [], [], []
    vr, vi = A.createVecs()
    for i in range(n):
        values.append(solver.getEigenpair(i, vr, vi))
        vectors.append(keep(vr, vi))
        errors.append(solver.computeError(i))
    its = solver.getIterationNumber()
    for obj in (solver, vr, vi):
        obj.destroy()
    return values, vectors, errors, its


def solve_eigen(
    A, B, nev, target, prefix, options=None, hermitian=True, shift=None, least=None, asked=None
):
    """The ``nev`` eigenpairs of A x = λ B x nearest to ``target``.

    Args:
        A: assembled PETSc matrix (stiffness side).
        B: assembled PETSc matrix (may be singular: its null rows go to λ = ∞).
        nev: number of eigenpairs wanted.
        target: where to look; the spectral transform shifts to ``shift`` (default: ``target``).
        prefix: PETSc options prefix.
        options: PETSc options (without the prefix) that override :data:`DEFAULT_OPTIONS`.
        hermitian: GHEP (A, B symmetric, B semi-definite) or GNHEP.
        shift: shift of the spectral transform; None: ``target``.
        least: the fewest converged pairs accepted (default ``nev``); more may be returned.
        asked: what the caller's user asked for, in words, for the failure's message.

    Raises:
        SolveFailed: if fewer than ``least`` pairs converged.
    """
    from slepc4py import SLEPc

    t = time.perf_counter()
    eps = SLEPc.EPS().create(A.getComm())
    eps.setOptionsPrefix(prefix)
    eps.setOperators(A, B)
    kind = SLEPc.EPS.ProblemType
    eps.setProblemType(kind.GHEP if hermitian else kind.GNHEP)
    eps.setDimensions(nev=nev)
    eps.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_MAGNITUDE)
    eps.setTarget(target)
    eps.getST().setShift(target if shift is None else shift)
    with petsc_options(prefix, {**DEFAULT_OPTIONS, **(options or {})}):
        eps.setFromOptions()
    values, vectors, errors, its = solve_and_collect(
        eps, A, nev, prefix, lambda vr, vi: vr.copy(), least, asked
    )
    order = np.argsort(np.abs(np.asarray(values) - target), kind="stable")
    return EigenPairs(
        np.asarray(values)[order],
        tuple(vectors[i] for i in order),
        np.asarray(errors)[order],
        its,
        time.perf_counter() - t,
    )


def frequencies_by_kind(K, M, w, targets, kind_of, per_target, prefix):
    """For each name → (kind, ω_target): ω of the mode of that kind among the ``per_target``
    eigenpairs nearest ω_target² (shift-and-invert there, so rigid modes at 0 are never
    reached); NaN if none is of that kind. Each eigenvector is put into the Function ``w``
    for ``kind_of()`` to classify (collective); ``w`` is zero afterwards."""
    out = {}
    for name, (kind, omega) in targets.items():
        pairs = solve_eigen(K, M, per_target, omega**2, prefix)
        found = []
        for lam, x in zip(pairs.values.real, pairs.vectors):
            w.vector.array[:] = x.array
            w.x.scatter_forward()
            found.append((abs(lam - omega**2), np.sqrt(abs(lam)), kind_of()))
            x.destroy()
        match = sorted(f for f in found if f[2] == kind)
        out[name] = match[0][1] if match else float("nan")
    w.x.array[:] = 0.0
    return out
