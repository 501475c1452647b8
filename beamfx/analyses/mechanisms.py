r"""Mechanisms left by released joints, found before any solve.

A release pattern can leave a motion that strains no member: a member pinned at both ends
with its torsion released too spins about its own axis; pinned joints in a frame that is not
triangulated let it fold. The linear stiffness K at the reference state is then singular in
directions that move the hinge unknowns (:mod:`beamfx.analyses.releases`), while the
rigid-body motions of a free structure (which :func:`~beamfx.analyses.checks.check_supported`
answers for) leave them at zero.

The check: K with unit section stiffnesses (:func:`unit_stiffness`) and without its
Dirichlet rows and columns, Jacobi-scaled to S = D^{-1/2} K D^{-1/2} (unit
diagonal, so the threshold is scale-free), gathered on rank 0 and decomposed densely
(``scipy.linalg.eigh``, the eigenpairs below the threshold only); its null space N = eigenvectors with λ < 1e-10 (round-off of a
unit-diagonal matrix is ~1e-15, the smallest eigenvalue of a sound slender frame ~1e-8 or
more). The number of mechanisms is the rank of N restricted to the hinge rows, and the joints
named are the releases whose rows carry them. Dense: kept to models of at most
:data:`MAX_DENSE` unknowns (a frame of a few hundred members); larger ones are not checked.
"""

from contextlib import contextmanager

import numpy as np

#: largest number of unknowns decomposed densely (about 1 s for eigh at 3000)
MAX_DENSE = 4000
#: eigenvalues of the unit-diagonal stiffness below this are null
NULL_TOL = 1e-10


def _gather_dense(A, comm):
    """The assembled PETSc matrix ``A`` as a dense array on rank 0 (None elsewhere)."""
    n = A.getSize()[0]
    lo, _ = A.getOwnershipRange()
    indptr, indices, data = A.getValuesCSR()
    rows = np.repeat(np.arange(lo, lo + len(indptr) - 1), np.diff(indptr))
    parts = comm.gather((rows, indices, data), root=0)
    if comm.rank != 0:
        return None
    K = np.zeros((n, n))
    for r, c, v in parts:
        np.add.at(K, (r, c), v)
    return K


def null_space(K, tol=NULL_TOL):
    """Orthonormal basis (columns) of the null space of the symmetric ``K``, Jacobi-scaled:
    returned in the unscaled unknowns (not orthonormal there). Only the eigenpairs below
    ``tol`` are computed (LAPACK's MRRR on a value range)."""
    from scipy.linalg import eigh

    d = np.sqrt(np.maximum(np.abs(np.diag(K)), 1e-300))
    _, V = eigh(K / np.outer(d, d), subset_by_value=(-np.inf, tol), driver="evr")
    return V / d[:, None]


def mechanisms(N, rows):
    """(number of mechanisms, indices of the releases that move in them) of the null space
    ``N`` given the hinge rows {release index: global rows}."""
    if N.shape[1] == 0 or not rows:
        return 0, []
    H = np.vstack([N[r] for r in rows.values()])
    scale = np.abs(H).max(initial=0.0)
    if scale == 0.0:
        return 0, []
    sv = np.linalg.svd(H / scale, compute_uv=False)
    count = int(np.sum(sv > 1e-8))
    moving = [k for k, r in rows.items() if np.abs(N[r]).max() > 1e-8 * scale]
    return count, moving


def _constrained(W, bcs):
    """Global indices of the owned Dirichlet dofs of ``bcs`` (their rows are identity),
    gathered on rank 0 (None elsewhere)."""
    imap = W.dofmap.index_map
    rows = [np.empty(0, np.int64)]
    for bc in bcs:
        dofs, owned = bc.dof_indices()
        rows.append(np.asarray(imap.local_to_global(dofs[:owned].astype(np.int32)), np.int64))
    parts = W.mesh.comm.gather(np.concatenate(rows), root=0)
    return None if parts is None else np.unique(np.concatenate(parts))


def _free_part(K, fixed, rows):
    """K without the Dirichlet rows and columns (decoupled identity), and the hinge rows
    {release: indices} renumbered into it."""
    keep = np.setdiff1d(np.arange(len(K)), fixed)
    at = np.full(len(K), -1)
    at[keep] = np.arange(len(keep))
    return K[np.ix_(keep, keep)], {r: at[g][at[g] >= 0] for r, g in rows.items()}


def _global_rows(W, local):
    """{release: global indices} of local dofs of ``W`` (owned ones; ghosts are owned
    elsewhere), gathered on every rank."""
    imap = W.dofmap.index_map
    size = imap.size_local * W.dofmap.index_map_bs
    out = {}
    for r, dofs in local.items():
        owned = [d for d in dofs if d < size]
        out[r] = list(imap.local_to_global(np.asarray(owned, np.int32))) if owned else []
    merged = {}
    for part in W.mesh.comm.allgather(out):
        for r, g in part.items():
            merged.setdefault(r, []).extend(int(x) for x in g)
    return {r: sorted(set(g)) for r, g in merged.items() if g}


@contextmanager
def unit_stiffness(model):
    """Within: every section stiffness (and the quaternion norm penalty) 1. Whether a
    mechanism exists depends on the joints and the geometry, not on the stiffness values;
    with them, a rigid arm (1e6 times stiffer than its member) or a stiff member next to a
    slender one would push genuine eigenvalues of the scaled stiffness to the round-off."""
    d = model.discretisation
    if d.matrices is not None:  # 6×6 section matrices: kept as they are
        yield
        return
    saved, penalty = d.stiffness.x.array.copy(), float(model.k_penalty.value)
    d.stiffness.x.array[:] = 1.0
    model.k_penalty.value = 1.0
    try:
        yield
    finally:
        d.stiffness.x.array[:] = saved
        model.k_penalty.value = penalty


def check_mechanisms(model):
    """Raise ValueError naming the joints if the releases of ``model`` (a
    :class:`~beamfx.analyses.model.BeamModel` at its reference state) leave a mechanism.
    Collective. Models of more than :data:`MAX_DENSE` unknowns are not checked.

    Returns:
        The number of unknowns checked (0 if none were).
    """
    import dolfinx.fem.petsc as fp

    from ..solvers.assembly import assemble_tangent
    from ..solvers.forms import compile_form
    from .releases import hinge_dofs

    comm = model.comm
    n = model.unknowns()
    if not model.spec.releases or n > MAX_DENSE:
        return 0
    J = compile_form(model.J)
    A = fp.create_matrix(J)
    with unit_stiffness(model):
        assemble_tangent(A, J, model.bcs)
    K = _gather_dense(A, comm)
    A.destroy()
    rows = _global_rows(model.W, hinge_dofs(model.W, model.hinges))
    fixed = _constrained(model.W, model.bcs)
    found = None
    if comm.rank == 0:
        K, rows = _free_part(K, fixed, rows)
        found = mechanisms(null_space(K), {r: g for r, g in rows.items() if len(g)})
    count, moving = comm.bcast(found, root=0)
    if count:
        releases = model.spec.releases
        names = list(dict.fromkeys(releases[r].joint or releases[r].at for r in moving))
        ends = [f"{releases[r].at} {list(releases[r].released)}" for r in moving]
        raise ValueError(
            f"the joint releases leave {count} mechanism(s): joints {names} move without "
            f"straining a member (released member ends: {ends}). Keep a rotation of one "
            "member end rigid there, release fewer components, or triangulate the frame"
        )
    return n


__all__ = ["MAX_DENSE", "check_mechanisms", "mechanisms", "null_space"]
