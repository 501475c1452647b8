"""Quadratic eigenproblems (λ² M + λ G + K) x = 0 with SLEPc PEP: TOAR with shift-and-invert
(MUMPS).

Knows nothing of beams. Constrained rows are expected as identity in K and zero in G and M:
they then have no finite eigenvalue (their polynomial is the constant 1), like the massless
directions of M, and shift-and-invert maps all of them to 0, far from any finite target.
"""

import time
from typing import NamedTuple

import numpy as np

from .eigen import solve_and_collect, solve_eigen
from .options import petsc_options

DEFAULT_OPTIONS = {
    "pep_type": "toar",
    "pep_tol": 1e-10,
    "pep_max_it": 300,
    # λ is scaled by a factor (see solve_quadratic); SLEPc's own, sqrt(‖K‖/‖M‖), is set by the
    # stiffest term (penalties, EA/h) and lies orders of magnitude above the wanted |λ|
    "pep_scale": "scalar",
    "st_type": "sinvert",
    "st_ksp_type": "preonly",
    "st_pc_type": "lu",
    "st_pc_factor_mat_solver_type": "mumps",
}


class QuadraticPairs(NamedTuple):
    """Converged pairs of the quadratic eigenproblem with residuals, iterations and wall time."""

    values: np.ndarray  # complex eigenvalues λ, nearest to the target first
    vectors: tuple  # (real part, imaginary part) of each eigenvector, NumPy arrays (local)
    residuals: np.ndarray  # SLEPc's backward error of each pair
    iterations: int
    seconds: float


def scale_estimate(K, M, nev, prefix):
    """sqrt|θ| of the ``nev``-th eigenvalue of K x = θ M x nearest to 0: the size of the wanted
    |λ| when G is a perturbation of the same order (gyroscopic terms), to scale λ by.

    TOAR's accuracy depends on that scale: with sqrt(‖K‖/‖M‖), 1e6 times the lowest frequency
    of a shear-stiff beam, the lowest λ lost five digits (relative error 5e-5 on a cantilever
    of 32 quartic elements); with any factor within two decades of the wanted |λ| they agree
    with the generalised problem to 1e-12.
    """
    pairs = solve_eigen(K, M, nev, 0.0, prefix + "scale_", hermitian=False)
    for x in pairs.vectors:
        x.destroy()
    theta = np.abs(pairs.values[:nev])
    return float(np.sqrt(np.max(theta))) if np.max(theta) > 0 else 1.0


def solve_quadratic(K, G, M, nev, target, prefix, options=None, scale=None):
    """The ``nev`` eigenpairs of (λ² M + λ G + K) x = 0 nearest to the real ``target``.

    Args:
        K: assembled stiffness matrix.
        G: assembled gyroscopic (or damping) matrix.
        M: assembled mass matrix (may be singular: its null directions go to λ = ∞).
        nev: number of eigenpairs wanted.
        target: where to look (real); shift-and-invert factorises λ² M + λ G + K there, so K
            must be regular for the default target 0.
        prefix: PETSc options prefix.
        options: PETSc options (without the prefix) that override :data:`DEFAULT_OPTIONS`.
        scale: the factor λ is scaled by (``pep_scale_factor``); default :func:`scale_estimate`
            with ``nev`` // 2 pairs (eigenvalues of the undamped problem come as ±iω).

    Returns:
        :class:`QuadraticPairs`; in real arithmetic a complex λ comes with its conjugate.

    Raises:
        SolveFailed: if fewer than ``nev`` pairs converged.
    """
    from slepc4py import SLEPc

    t = time.perf_counter()
    options = dict(options or {})
    if "pep_scale_factor" not in options:
        options["pep_scale_factor"] = scale or scale_estimate(K, M, max(nev // 2, 1), prefix)
    pep = SLEPc.PEP().create(K.getComm())
    pep.setOptionsPrefix(prefix)
    pep.setOperators([K, G, M])
    pep.setProblemType(SLEPc.PEP.ProblemType.GENERAL)
    pep.setDimensions(nev=nev)
    pep.setWhichEigenpairs(SLEPc.PEP.Which.TARGET_MAGNITUDE)
    pep.setTarget(target)
    with petsc_options(prefix, {**DEFAULT_OPTIONS, **options}):
        pep.setFromOptions()
    values, vectors, errors, its = solve_and_collect(
        pep, K, nev, prefix, lambda vr, vi: (vr.getArray().copy(), vi.getArray().copy())
    )
    values = np.asarray(values, dtype=complex)
    order = np.argsort(np.abs(values - target), kind="stable")
    return QuadraticPairs(
        values[order],
        tuple(vectors[i] for i in order),
        np.asarray(errors)[order],
        its,
        time.perf_counter() - t,
    )
