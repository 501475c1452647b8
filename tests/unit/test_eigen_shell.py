"""The eigen solves with massless unknowns (beamfx.solvers.eigen_shell) on a small saddle-point
problem: K = [[A, Bᵀ], [B, −s I]] with M and G zero on the last rows (the mixed formulation's
shape). As s → 0 the problem tends to the constrained one, B u = 0, whose eigenvalues dense
linear algebra gives directly (u = N z, N a basis of the null space of B); they differ from
the s-problem's by O(s) relative for matrices of unit size."""

import numpy as np
import pytest
import scipy.linalg as sla
from mpi4py import MPI

from beamfx.solvers.eigen_shell import solve_eigen_massless, solve_quadratic_massless

N_U, N_F, S = 8, 3, 1e-10
pytestmark = pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="a serial toy problem")


def _problem():
    rng = np.random.default_rng(7)
    X = rng.standard_normal((N_U, N_U))
    A = X @ X.T + N_U * np.eye(N_U)
    Y = rng.standard_normal((N_U, N_U))
    M = Y @ Y.T / N_U + np.eye(N_U)
    Z = rng.standard_normal((N_U, N_U))
    G = 0.5 * (Z - Z.T)
    B = rng.standard_normal((N_F, N_U))
    return A, M, G, B


def _petsc(dense):
    from petsc4py import PETSc

    n = dense.shape[0]
    rows, cols = np.nonzero(np.ones_like(dense))
    indptr = np.arange(0, n * n + 1, n, dtype=np.int32)
    mat = PETSc.Mat().createAIJ(
        (n, n), csr=(indptr, cols.astype(np.int32), dense[rows, cols]), comm=MPI.COMM_SELF
    )
    mat.assemble()
    return mat


def _full(A, M, G, B):
    n = N_U + N_F
    K, Mf, Gf = np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n))
    K[:N_U, :N_U], K[:N_U, N_U:], K[N_U:, :N_U] = A, B.T, B
    K[N_U:, N_U:] = -S * np.eye(N_F)
    Mf[:N_U, :N_U], Gf[:N_U, :N_U] = M, G
    return [_petsc(x) for x in (K, Gf, Mf)]


def test_the_generalised_problem_is_the_constrained_one():
    A, M, G, B = _problem()
    Nb = sla.null_space(B)
    exact = np.sort(sla.eigh(Nb.T @ A @ Nb, Nb.T @ M @ Nb, eigvals_only=True))[:3]
    K, _, Mp = _full(A, M, G, B)
    pairs = solve_eigen_massless(K, Mp, 3, "test_shell_", np.arange(N_U, N_U + N_F))
    got = pairs.values[:3].real  # nearest 0 first
    assert np.allclose(got, exact, rtol=1e-8), (got, exact)
    assert np.all(pairs.residuals[:3] < 1e-12)


def test_the_quadratic_problem_is_the_constrained_one():
    A, M, G, B = _problem()
    Nb = sla.null_space(B)
    Ar, Mr, Gr = (Nb.T @ X @ Nb for X in (A, M, G))
    m = Ar.shape[0]
    L = np.block([[np.zeros((m, m)), np.eye(m)], [-sla.solve(Mr, Ar), -sla.solve(Mr, Gr)]])
    exact = sla.eigvals(L)
    exact = exact[np.argsort(np.abs(exact))][:4]
    K, Gp, Mp = _full(A, M, G, B)
    pairs = solve_quadratic_massless(K, Gp, Mp, 4, "test_shell_", np.arange(N_U, N_U + N_F))
    got = pairs.values[:4]
    for lam in exact:
        assert np.min(np.abs(got - lam)) <= 1e-8 * abs(lam), (got, exact)
    assert np.all(pairs.residuals[:4] < 1e-12)
