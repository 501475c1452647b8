r"""A condition estimate of the tangent of a small model (issue 16).

The round-off of a solve grows with the condition number κ of its tangent: a penalty or a
stiff term (EA, GA ≫ EI/L²) raises κ by the stiffness ratio, and a symmetric diagonal
scaling D K D (D = diag |K_ii|^(-1/2), each field measured by its own stiffness) removes only
what the choice of units adds, not that ratio. The estimate is computed on the free dofs (the
constrained rows and columns, identity in the assembled tangent, removed), gathered on rank 0
as a sparse matrix:

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
SADDLE_SCALING = "symmetric equilibration D K D (Ruiz, 10 sweeps) on the free dofs"


def gather(A, fixed_rows, dense=False):
    """(K, free) on rank 0, (None, None) elsewhere: the PETSc matrix ``A`` as a SciPy CSR
    matrix (a NumPy array if ``dense``: SciPy's construction costs more than a small model's
    whole estimate) and the global indices of its free rows (``fixed_rows``: the owned local
    indices of the constrained rows on each rank). Collective."""
    comm = A.getComm().tompi4py()
    n = A.getSize()[0]
    start = A.getOwnershipRange()[0]
    ai, aj, av = A.getValuesCSR()  # owned rows, global columns
    part = (start, ai, aj, av, np.asarray(fixed_rows, np.int64) + start)
    parts = comm.gather(part, root=0) if comm.size > 1 else [part]
    if comm.rank != 0:
        return None, None
    rows = np.concatenate(
        [np.repeat(np.arange(len(p[1]) - 1), np.diff(p[1])) + p[0] for p in parts]
    )
    cols, values = np.concatenate([p[2] for p in parts]), np.concatenate([p[3] for p in parts])
    if dense:  # (PETSc's rows hold each column once: the entries are placed, not summed)
        K = np.zeros((n, n))
        K[rows, cols] = values
    else:
        import scipy.sparse as sp

        K = sp.csr_matrix((values, (rows, cols)), shape=(n, n))
    free = np.setdiff1d(np.arange(n), np.concatenate([p[4] for p in parts]))
    return K, free


def scaled(K):
    """D K D with D = diag(|K_ii|)^(-1/2) (a zero diagonal entry left unscaled); K sparse, or
    a dense array (then dense, the same numbers: (d_i K_ij) d_j either way; SciPy, whose
    import costs 0.1 s of a small run's process, is not imported then)."""
    d = np.abs(K.diagonal())
    D = 1.0 / np.sqrt(np.where(d > 0, d, 1.0))
    if isinstance(K, np.ndarray):
        return D[:, None] * K * D[None, :]
    import scipy.sparse as sp

    D = sp.diags(D)
    return (D @ K @ D).tocsc()


def equilibrated(K, sweeps=10):
    """D K D with D from ``sweeps`` of Ruiz's symmetric equilibration (each sweep divides row
    and column i by sqrt(max_j |K_ij|)): the scaling of a saddle-point tangent (the mixed
    formulation), whose force rows have a small or zero diagonal, so that :func:`scaled`
    would blow them up by 1/sqrt(compliance). K sparse, or a dense array (then dense)."""
    dense = isinstance(K, np.ndarray)
    if not dense:
        import scipy.sparse as sp

        K = sp.csr_matrix(K)
    else:
        K = np.array(K, float)
    for _ in range(sweeps):
        r = np.abs(K).max(axis=1) if dense else abs(K).max(axis=1).toarray().ravel()
        d = 1.0 / np.sqrt(np.where(r > 0, r, 1.0))
        K = d[:, None] * K * d[None, :] if dense else sp.diags(d) @ K @ sp.diags(d)
    return K if dense else K.tocsc()


def condition(K):
    """(κ, norm name) of the square matrix ``K`` (sparse; or dense, of at most
    :data:`DENSE_LIMIT` rows): κ₂ by a dense SVD up to :data:`DENSE_LIMIT` rows, else the
    1-norm estimate; inf when K is singular to working precision."""
    if K.shape[0] <= DENSE_LIMIT:
        s = np.linalg.svd(K.toarray() if hasattr(K, "toarray") else K, compute_uv=False)
        return (float(s[0] / s[-1]) if s[-1] > 0 else np.inf), "2"
    from scipy.sparse.linalg import LinearOperator, onenormest, splu

    S = K.tocsc()
    try:
        lu = splu(S)
    except RuntimeError:  # exactly singular
        return np.inf, "1 (estimate)"
    inverse = LinearOperator(
        S.shape, matvec=lu.solve, rmatvec=lambda y: lu.solve(y, trans="T"), dtype=float
    )
    return float(onenormest(S) * onenormest(inverse)), "1 (estimate)"


def condition_estimate(A, fixed_rows, limit=LIMIT, saddle=False):
    """The condition estimate of the tangent ``A`` on its free dofs, scaled and unscaled, as
    a dict for results.json (same on every rank), or None above ``limit`` unknowns.
    ``saddle``: a saddle-point tangent, scaled by :func:`equilibrated`. Collective."""
    comm = A.getComm().tompi4py()
    if A.getSize()[0] > limit:
        return None
    # a matrix of at most DENSE_LIMIT rows dense: SciPy's sparse indexing and products cost
    # more than the SVD there
    dense = A.getSize()[0] <= DENSE_LIMIT
    K, free = gather(A, fixed_rows, dense)
    out = None
    if comm.rank == 0:
        K = K[np.ix_(free, free)] if dense else K[free][:, free]
        value, norm = condition(equilibrated(K) if saddle else scaled(K))
        unscaled, _ = condition(K)
        out = {
            "value": _finite(value),
            "unscaled": _finite(unscaled),
            "scaling": SADDLE_SCALING if saddle else SCALING,
            "norm": norm,
            "free_unknowns": len(free),
        }
    return comm.bcast(out, root=0)


def _finite(value):
    """``value``, or None when infinite (singular to working precision: JSON has no inf)."""
    return float(value) if np.isfinite(value) else None
