r"""Helpers of a saddle-point tangent (the mixed formulation's, with force unknowns): the
kinematic metric that leaves the force block out, the deflation of a null vector in it, and the
negative eigenvalues the force block adds to the inertia (:func:`inertia_offset`).
"""

import numpy as np


def _deflate(v, phi, metric=None):
    """Remove the φ component of v: v ← v − (φᵀMv) φ, φ a unit vector in the metric M
    (the weights ``metric``, None: M = I; :func:`~.bifurcation.smallest_eigenpair`);
    nothing for φ None."""
    if phi is None:
        return
    if metric is None:
        v.axpy(-v.dot(phi), phi)
        return
    from mpi4py import MPI

    a = v.getArray(readonly=True) * metric
    local = float(np.dot(a, phi.getArray(readonly=True)))
    v.axpy(-v.getComm().tompi4py().allreduce(local, op=MPI.SUM), phi)


def _kinematic(comm, n_owned, force_dofs):
    """(weights 1 on the owned kinematic unknowns and 0 on the force unknowns, or None
    without force unknowns; their global number :func:`inertia_offset`)."""
    if force_dofs is None:
        return None, 0
    d = np.asarray(force_dofs)
    d = d[d < n_owned]
    weights = np.ones(n_owned)
    weights[d] = 0.0
    return weights, inertia_offset(comm, len(d))


def inertia_offset(comm, owned_forces):
    r"""The negative eigenvalues the force block adds to the inertia of a saddle-point
    tangent: its number of force unknowns (``owned_forces`` on this rank, summed).

    The mixed tangent is K = [[A, Bᵀ], [B, −S]] with the compliance S ≥ 0. For S > 0 the
    congruence K = Lᵀ diag(A + BᵀS⁻¹B, −S) L, L = [[I, 0], [−S⁻¹B, I]], and Sylvester's law
    of inertia give neg(K) = neg(A + BᵀS⁻¹B) + n_f: the condensed stiffness (the
    displacement form's tangent with its reduced axial and shear integration) plus one per
    force unknown. For S = 0 (rigid limits) and B of full rank n_f (the strains at the
    reduced points are independent), neg(K) = neg(ZᵀAZ) + n_f, Z a basis of ker B (the
    constrained stiffness); a mixed S with zero and positive entries combines both. So the
    count less n_f is the inertia the displacement form would report (zero on the
    constrained rows, whose diagonal is 1)."""
    from mpi4py import MPI

    return comm.allreduce(int(owned_forces), op=MPI.SUM)
