r"""A condition estimate of the tangent of a small model (issue 16).

The round-off of a solve grows with the condition number κ of its tangent: a penalty or a
stiff term (EA, GA ≫ EI/L²) raises κ by the stiffness ratio, and a symmetric diagonal
scaling D K D (D = diag |K_ii|^(-1/2), each field measured by its own stiffness) removes only
what the choice of units adds, not that ratio. The estimate is computed on the free dofs (the
constrained rows and columns, identity in the assembled tangent, removed), gathered on rank 0:

* up to :data:`DENSE_LIMIT` free unknowns: κ₂ = σ_max/σ_min, the ratio of the extreme singular
  values (dense SVD, exact);
* up to :data:`LIMIT` unknowns: κ₁ = ‖K‖₁‖K⁻¹‖₁ by Higham and Tisseur's block 1-norm estimator
  (``scipy.sparse.linalg.onenormest``, ‖K⁻¹‖₁ through a sparse LU), within a small factor of
  κ₂ (κ₁/n ≤ κ₂ ≤ n κ₁, in practice within 10);
* above: none (the gather and the factorisation would cost more than the solve).
"""

import numpy as np

#: largest number of free unknowns for the dense SVD (about 0.1 s at 300, 3 s at 1000)
DENSE_LIMIT = 400
#: largest number of unknowns for any estimate
LIMIT = 2000
#: what :func:`condition_estimate` reports as its scaling
SCALING = "symmetric diagonal D K D, D = diag(|K_ii|)^(-1/2) on the free dofs"


def gather_dense(A, fixed_rows):
    """(K, free) on rank 0, (None, None) elsewhere: the dense matrix ``A`` (PETSc, global
    size n) and the global indices of its free rows (``fixed_rows``: the owned local indices
    of the constrained rows on each rank). Collective."""
    comm = A.getComm().tompi4py()
    n = A.getSize()[0]
    start = A.getOwnershipRange()[0]
    ai, aj, av = A.getValuesCSR()  # owned rows, global columns
    parts = comm.gather((start, ai, aj, av, np.asarray(fixed_rows, np.int64) + start), root=0)
    if comm.rank != 0:
        return None, None
    K = np.zeros((n, n))
    fixed = []
    for first, indptr, cols, vals, rows in parts:
        owned = np.repeat(np.arange(len(indptr) - 1), np.diff(indptr)) + first
        K[owned, cols] = vals
        fixed.append(rows)
    free = np.setdiff1d(np.arange(n), np.concatenate(fixed))
    return K, free


def scaled(K):
    """D K D with D = diag(|K_ii|)^(-1/2) (a zero diagonal entry left unscaled)."""
    d = np.abs(np.diag(K))
    d = 1.0 / np.sqrt(np.where(d > 0, d, 1.0))
    return d[:, None] * K * d[None, :]


def condition(K):
    """(κ, norm name) of the square matrix ``K``: κ₂ by SVD up to :data:`DENSE_LIMIT` rows,
    else the 1-norm estimate; inf when K is singular to working precision."""
    if len(K) <= DENSE_LIMIT:
        s = np.linalg.svd(K, compute_uv=False)
        return (float(s[0] / s[-1]) if s[-1] > 0 else np.inf), "2"
    import scipy.sparse as sp
    from scipy.sparse.linalg import LinearOperator, onenormest, splu

    S = sp.csc_matrix(K)
    try:
        lu = splu(S)
    except RuntimeError:  # exactly singular
        return np.inf, "1 (estimate)"
    n = len(K)
    inverse = LinearOperator(
        (n, n), matvec=lu.solve, rmatvec=lambda y: lu.solve(y, trans="T"), dtype=float
    )
    return float(onenormest(S) * onenormest(inverse)), "1 (estimate)"


def condition_estimate(A, fixed_rows, limit=LIMIT):
    """The condition estimate of the tangent ``A`` on its free dofs, scaled and unscaled, as
    a dict for results.json (same on every rank), or None above ``limit`` unknowns.
    Collective."""
    comm = A.getComm().tompi4py()
    if A.getSize()[0] > limit:
        return None
    K, free = gather_dense(A, fixed_rows)
    out = None
    if comm.rank == 0:
        K = K[np.ix_(free, free)]
        value, norm = condition(scaled(K))
        unscaled, _ = condition(K)
        out = {
            "value": _finite(value),
            "unscaled": _finite(unscaled),
            "scaling": SCALING,
            "norm": norm,
            "free_unknowns": len(free),
        }
    return comm.bcast(out, root=0)


def _finite(value):
    """``value``, or None when infinite (singular to working precision: JSON has no inf)."""
    return float(value) if np.isfinite(value) else None
