r"""Inertia of a symmetric tangent: how many of its eigenvalues are negative.

By Sylvester's law of inertia, a symmetric K = L D Lᵀ (L unit lower triangular, D block
diagonal with 1×1 and 2×2 pivots) has as many negative eigenvalues as D. MUMPS's symmetric
indefinite factorisation (PETSc's "cholesky" with MUMPS, SYM = 2) reports that number as
INFOG(12). On several ranks the root front must not go to ScaLAPACK (ICNTL(13) = 1), whose
pivots MUMPS does not count; PETSc's own ``MatGetInertia`` insists on it too.

A stable equilibrium of a conservative system has a positive definite tangent (count 0); the
count rises by one at every simple critical point (limit or bifurcation) the path passes.
Dirichlet rows (identity) add positive eigenvalues only.

The LDLᵀ factor also solves: a solver that factorises the tangent anyway (arc length) gets
the count for free with :func:`negative_pivots` on its own KSP; otherwise
:class:`InertiaCounter` factorises once more.
"""

import time

from .options import petsc_options

#: a direct symmetric indefinite factorisation: LDLᵀ by MUMPS, root front not on ScaLAPACK
DEFAULT_OPTIONS = {
    "ksp_type": "preonly",
    "pc_type": "cholesky",
    "pc_factor_mat_solver_type": "mumps",
}


def counts_inertia(ksp):
    """Whether ``ksp`` factorises with MUMPS's symmetric LDLᵀ (so INFOG(12) is the inertia)."""
    pc = ksp.getPC()
    return pc.getType() == "cholesky" and pc.getFactorSolverType() == "mumps"


def prepare(ksp):
    """Before the first factorisation of ``ksp`` (operators set): keep MUMPS's root front off
    ScaLAPACK, ICNTL(13) = 1, so that INFOG(12) counts every pivot (the options database
    does not reach the factor through the KSP's prefix in PETSc 3.18)."""
    if counts_inertia(ksp):
        pc = ksp.getPC()
        pc.setFactorSetUpSolverType()
        pc.getFactorMatrix().setMumpsIcntl(13, 1)


def negative_pivots(ksp):
    """Number of negative eigenvalues of the matrix ``ksp`` has just factorised (set up).

    Raises:
        ValueError: if ``ksp`` is not a MUMPS LDLᵀ (:func:`counts_inertia`).
    """
    if not counts_inertia(ksp):
        raise ValueError("the inertia needs a MUMPS LDLᵀ factorisation (pc_type cholesky)")
    return int(ksp.getPC().getFactorMatrix().getMumpsInfog(12))


class InertiaCounter:
    """Counts the negative eigenvalues of symmetric matrices by an LDLᵀ factorisation.

    The symbolic analysis is kept between calls on matrices of the same nonzero pattern, so
    each :meth:`count` costs one numeric factorisation.

    Args:
        comm: the communicator of the matrices.
        prefix: PETSc options prefix (mandatory, e.g. "beamfx_inertia_").
        options: PETSc options without the prefix, merged over :data:`DEFAULT_OPTIONS`.
    """

    def __init__(self, comm, prefix="beamfx_inertia_", options=None):
        from petsc4py import PETSc

        self.ksp = PETSc.KSP().create(comm)
        self.ksp.setOptionsPrefix(prefix)
        with petsc_options(prefix, {**DEFAULT_OPTIONS, **(options or {})}):
            self.ksp.setFromOptions()
        self.seconds = 0.0
        self.calls = 0

    def count(self, A):
        """The number of negative eigenvalues of the assembled symmetric matrix ``A``."""
        t = time.perf_counter()
        self.ksp.setOperators(A)
        if self.calls == 0:
            prepare(self.ksp)
        self.ksp.setUp()
        n = negative_pivots(self.ksp)
        self.seconds += time.perf_counter() - t
        self.calls += 1
        return n

    def destroy(self):
        """Free the factorisation."""
        self.ksp.destroy()


class TangentInertia:
    """Negative eigenvalues of a compiled tangent form at the current state of its
    coefficients: assembled into a matrix of its own (identity Dirichlet rows, and a
    coupling's entries if given), then one LDLᵀ factorisation; the matrix and the symbolic
    analysis are kept between calls."""

    def __init__(self, comm, prefix="beamfx_inertia_", options=None):
        self.counter = InertiaCounter(comm, prefix, options)
        self.A = None
        self.seconds = 0.0  # assembly and factorisation

    def count(self, J, bcs, coupling=None):
        """Assemble ``J`` (compiled) and count."""
        import dolfinx.fem.petsc as fp

        from .assembly import assemble_tangent

        t = time.perf_counter()
        if self.A is None:
            self.A = fp.create_matrix(J)
        assemble_tangent(self.A, J, bcs)
        if coupling:
            coupling.add_to_tangent(self.A)
        n = self.counter.count(self.A)
        self.seconds += time.perf_counter() - t
        return n

    def destroy(self):
        """Free the matrix and the factorisation."""
        self.counter.destroy()
        if self.A is not None:
            self.A.destroy()


def tangent_inertia(J, bcs, comm, prefix="beamfx_inertia_", options=None):
    """Negative eigenvalues of the tangent form ``J`` (compiled) with identity Dirichlet rows,
    at the current state of its coefficients. One assembly and one factorisation."""
    counter = TangentInertia(comm, prefix, options)
    try:
        return counter.count(J, bcs)
    finally:
        counter.destroy()


__all__ = [
    "DEFAULT_OPTIONS",
    "InertiaCounter",
    "TangentInertia",
    "counts_inertia",
    "negative_pivots",
    "tangent_inertia",
]
