"""Assembly of residual, tangent and load vector with Dirichlet conditions (one place for all
solvers: Newton, arc length, load scaling)."""

import numpy as np


def assemble_residual(b, F, J, bcs, x, rows=None):
    """Residual b = F with lifting of ``bcs`` about ``x``, b = x - g on constrained rows (b zeroed).

    The Newton correction then drives the constrained dofs to their prescribed values g.
    ``rows``: owned local rows (the constrained ones) whose assembled F (the reactions) is
    measured before it is replaced; returns the local sum of their squares (0 without).
    """
    import dolfinx.fem.petsc as fp
    from petsc4py import PETSc

    with b.localForm() as local:
        local.set(0.0)
    fp.assemble_vector(b, F)
    fp.apply_lifting(b, [J], bcs=[bcs], x0=[x], scale=-1.0)
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    local = 0.0
    if rows is not None and len(rows):
        with np.errstate(over="ignore"):  # a diverging iterate: inf, the test says NaN/diverged
            local = float(np.sum(b.getArray(readonly=True)[rows] ** 2))
    fp.set_bc(b, bcs, x, -1.0)
    return local


def assemble_tangent(A, J, bcs):
    """A = J with identity rows and columns on the constrained dofs (A zeroed first)."""
    import dolfinx.fem.petsc as fp

    A.zeroEntries()
    fp.assemble_matrix(A, J, bcs=bcs)
    A.assemble()


def assemble_load(f, F, load_factor, bcs):
    """Load vector f = F(w, 0) - F(w, 1) = -∂F/∂λ at the current w, for F linear in the load factor
    (a ``fem.Constant``), zero on constrained dofs; the load factor is left unchanged."""
    import dolfinx.fem.petsc as fp
    from petsc4py import PETSc

    lam = float(load_factor.value)
    at_one = f.duplicate()
    for vec, value in ((f, 0.0), (at_one, 1.0)):
        load_factor.value = value
        with vec.localForm() as local:
            local.set(0.0)
        fp.assemble_vector(vec, F)
        vec.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    f.axpy(-1.0, at_one)
    at_one.destroy()
    fp.set_bc(f, bcs, scale=0.0)
    load_factor.value = lam
