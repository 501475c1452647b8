"""The mixed formulation's saddle-point tangent K = [[A, Bᵀ], [B, −S]] (S ≥ 0 the compliance,
B of full rank) on small dense matrices: its inertia is the condensed stiffness's plus one
negative eigenvalue per force unknown (:func:`beamfx.solvers.arclength.inertia_offset`), and
inverse iteration in the kinematic metric (:func:`beamfx.solvers.bifurcation.smallest_eigenpair`)
finds the condensed stiffness's eigenvalue nearest zero, not one of the force block's."""

import numpy as np
import pytest


def _saddle(n, m, S_diag, seed, shift):
    """(K, the condensed stiffness) with A symmetric indefinite (eigenvalues shifted by
    ``shift``), B (m × n) of full rank, S = diag(S_diag) ≥ 0."""
    rng = np.random.default_rng(seed)
    Q = rng.standard_normal((n, n))
    A = Q @ Q.T / n - shift * np.eye(n)
    B = rng.standard_normal((m, n))
    S = np.diag(S_diag)
    K = np.block([[A, B.T], [B, -S]])
    if np.all(S_diag > 0):
        return K, A + B.T @ np.linalg.solve(S, B)
    Z = np.linalg.svd(B)[2][m:].T  # ker B (S = 0)
    return K, Z.T @ A @ Z


def _negative(M):
    return int(np.sum(np.linalg.eigvalsh(M) < 0))


@pytest.mark.parametrize("S_diag", [np.full(3, 1e-3), np.full(3, 0.5), np.zeros(3)])
@pytest.mark.parametrize("shift", [0.0, 0.3, 0.8])
def test_negative_count_is_the_condensed_ones_plus_the_force_unknowns(S_diag, shift):
    K, condensed = _saddle(8, 3, S_diag, 1, shift)
    assert _negative(K) == _negative(condensed) + 3


def test_inverse_iteration_in_the_kinematic_metric_finds_the_condensed_eigenvalue():
    from petsc4py import PETSc

    from beamfx.solvers.bifurcation import smallest_eigenpair

    n, m = 8, 3
    K, condensed = _saddle(n, m, np.full(m, 1e-2), 2, 0.4)
    values = np.linalg.eigvalsh(condensed)
    nearest = values[np.argmin(np.abs(values))]
    # the force block's eigenvalues are nearer zero than the condensed one: Euclidean inverse
    # iteration finds one of them
    assert np.abs(np.linalg.eigvalsh(K)).min() < abs(nearest)
    A = PETSc.Mat().createDense(K.shape, array=K.copy(), comm=PETSc.COMM_SELF)
    A.assemble()
    ksp = PETSc.KSP().create(PETSc.COMM_SELF)
    ksp.setOperators(A)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.setUp()
    x = A.createVecRight()
    x.setArray(np.random.default_rng(0).standard_normal(n + m))
    metric = np.r_[np.ones(n), np.zeros(m)]
    mu, _ = smallest_eigenpair(A, ksp.solve, x, its=500, rtol=1e-12, metric=metric)
    assert mu == pytest.approx(nearest, rel=1e-8)
    u = x.getArray()[:n]
    assert np.linalg.norm(condensed @ u - mu * u) <= 1e-8 * np.abs(values).max()
    plain, _ = smallest_eigenpair(A, ksp.solve, x, its=500, rtol=1e-12)
    assert abs(plain) < abs(nearest)  # without the metric: the force block's
    for obj in (ksp, A, x):
        obj.destroy()


def test_inertia_offset_sums_the_ranks_force_unknowns():
    from mpi4py import MPI

    from beamfx.solvers.arclength import inertia_offset

    assert inertia_offset(MPI.COMM_SELF, 7) == 7
    assert inertia_offset(MPI.COMM_WORLD, 2) == 2 * MPI.COMM_WORLD.size
