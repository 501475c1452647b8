"""The inertia of the tangent from MUMPS's LDLᵀ pivots against the eigenvalues of the same
tangent as a dense matrix (numpy.linalg.eigvalsh).

A clamped-free column of rectangular section (EI_z = EI_y / 4) under a compressive end load
on its straight (primary) path: below the first Euler load the tangent is positive definite,
between the first and the second (the stiff plane's, 4 times higher) it has one negative
eigenvalue, beyond the second two; the count must equal eigvalsh's at every load.
"""

import numpy as np
import pytest
from mpi4py import MPI


def dense(A):
    """The PETSc matrix ``A`` as a dense array on every rank (collective)."""
    comm = A.getComm().tompi4py()
    r0, r1 = A.getOwnershipRange()
    indptr, cols, vals = A.getValuesCSR()
    rows = np.repeat(np.arange(r0, r1), np.diff(indptr))
    parts = comm.allgather((rows, cols, vals))
    n = A.getSize()[0]
    out = np.zeros((n, n))
    for r, c, v in parts:
        out[r, c] = v
    return out


def test_symmetric_indefinite_matrix():
    """A dense random symmetric matrix with 5 negative eigenvalues of 40, spread over ranks."""
    from petsc4py import PETSc

    from beamfx.solvers.inertia import InertiaCounter

    comm, n = MPI.COMM_WORLD, 40
    rng = np.random.default_rng(0)
    Q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    M = (Q * np.r_[-np.arange(1.0, 6.0), np.arange(1.0, n - 4)]) @ Q.T
    A = PETSc.Mat().createAIJ((n, n), comm=comm)
    A.setUp()
    r0, r1 = A.getOwnershipRange()
    for i in range(r0, r1):
        A.setValues(i, range(n), M[i])
    A.assemble()
    counter = InertiaCounter(comm)
    assert counter.count(A) == np.sum(np.linalg.eigvalsh(M) < 0) == 5
    A.scale(-1.0)
    assert counter.count(A) == n - 5
    counter.destroy()
    A.destroy()


@pytest.mark.parametrize("factor, expected", [(0.5, 0), (1.5, 1), (5.0, 2)])
def test_column_tangent_inertia_matches_eigvalsh(factor, expected):
    import dolfinx.fem.petsc as fp

    from beamfx.analyses.model import BeamModel
    from beamfx.analyses.static import solve_static
    from beamfx.bench._builders import cantilever, straight
    from beamfx.physics import sections
    from beamfx.solvers.assembly import assemble_tangent
    from beamfx.solvers.forms import compile_form
    from beamfx.solvers.inertia import InertiaCounter

    # E = 1, b = 0.2, h = 0.1: EI_y = 4 EI_z; P_e = π² EI_z / (4 L²) about the weak axis
    s = sections.rectangle(1e4, 4e3, 1.0, 0.02, 0.01)
    P_e = np.pi**2 * min(s.EI_y, s.EI_z) / 4
    model = BeamModel(cantilever(straight(1.0), s, 4, 3, force=(-factor * P_e, 0, 0)))
    solve_static(model, steps=1)
    J = compile_form(model.J)
    A = fp.create_matrix(J)
    assemble_tangent(A, J, model.bcs)
    K = dense(A)
    assert np.allclose(K, K.T, atol=1e-9 * np.abs(K).max())  # a conservative system
    eig = np.linalg.eigvalsh(K)
    counter = InertiaCounter(model.comm)
    count = counter.count(A)
    # the count is meaningful: no eigenvalue near round-off
    assert np.abs(eig).min() > 1e-8 * np.abs(eig).max()
    assert count == np.sum(eig < 0) == expected
    counter.destroy()
    A.destroy()
