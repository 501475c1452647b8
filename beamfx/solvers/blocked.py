"""Algebraic multigrid on a beam's unknowns ordered node by node (a PETSc python PC).

DOLFINx numbers a mixed space's unknowns in groups of the sub-elements (3 displacements at a
node here, 3 or 4 rotation unknowns there), not node by node, so the matrix has block size 1
and AMG treats every unknown as a node of its own. :class:`NodeBlockedPC` hands the
preconditioner a copy of the matrix with each rank's rows permuted into node blocks
[u_x, u_y, u_z, rotation...] and the block size set (6, or 7 with a quaternion): BoomerAMG
(hypre) then coarsens each kind of unknown over the nodes (its "unknown approach" for
systems), GAMG aggregates whole nodes and gets the six rigid-body motions as its near-null
space (:mod:`beamfx.solvers.nullspace`). The permutation stays on each rank (a node's unknowns
have one owner), so it costs a copy of the matrix and two local gathers per application.
"""

import numpy as np

from .nullspace import beam_node_dofs, node_permutation, node_positions, rigid_modes

#: preconditioners that get the node-blocked matrix
BLOCKED = ("hypre", "gamg")


class NodeBlockedPC:
    """The python-PC context: an inner PC (``inner``, of the type the options asked for) on
    the node-permuted copy of the operator. ``w``: the unknowns (their current values give
    the rigid-body modes of the finite kinematics)."""

    def __init__(self, inner, w, perm, bs):
        self.inner, self.w, self.perm, self.bs = inner, w, perm, bs
        self.P = self.xp = self.yp = self._is = self._nodes = None
        self._comm = w.function_space.mesh.comm

    def setUp(self, pc):
        """Permute the operator into node blocks and set up the inner PC on the copy (with
        the rigid-body modes at the current state, for GAMG)."""
        from petsc4py import PETSc

        _, P = pc.getOperators()
        if self._is is None:
            start = P.getOwnershipRange()[0]
            self._is = PETSc.IS().createGeneral(self.perm + start, comm=self._comm)
            self._is.setBlockSize(self.bs)
        if self.P is not None:  # a new copy each time: reusing its storage (MAT_REUSE_MATRIX)
            self.P.destroy()  # gave wrong values on 2 ranks (CG failed at Newton's 2nd step)
        self.P = P.createSubMatrix(self._is, self._is)
        if self.P.getBlockSize() != self.bs:
            self.P.setBlockSize(self.bs)
        if self.inner.getType() == "gamg":
            self.P.setNearNullSpace(self._near_nullspace())
        self.inner.setOperators(self.P, self.P)
        self.inner.setUp()
        if self.xp is None:
            self.xp, self.yp = self.P.createVecs()

    def _near_nullspace(self):
        """The six rigid-body modes at the current state, permuted and orthonormalised."""
        W = self.w.function_space
        if self._nodes is None:  # the same at every tangent: found once
            u, r = beam_node_dofs(W)
            self._nodes = (u, r, node_positions(W, u))
        modes = rigid_modes(W, *self._nodes[:2], self.w.x.array, X=self._nodes[2])[:, self.perm]
        vectors = []
        for q in orthonormal(modes, self._comm).T:
            v = self.P.createVecLeft()
            v.array[:] = q
            vectors.append(v)
        from petsc4py import PETSc

        return PETSc.NullSpace().create(vectors=vectors)

    def apply(self, pc, x, y):
        """Apply the inner PC to ``x`` through the node-ordered copy, into ``y``."""
        self.xp.array[:] = x.array_r[self.perm]
        self.inner.apply(self.xp, self.yp)
        y.array[self.perm] = self.yp.array_r

    def destroy(self, pc=None):
        """Free the copy, the vectors and the inner PC."""
        for obj in (self.P, self.xp, self.yp, self._is, self.inner):
            if obj is not None:
                obj.destroy()
        self.P = self.xp = self.yp = self._is = None


def orthonormal(modes, comm):
    """Columns spanning ``modes`` (k, owned) orthonormal over all ranks: (owned, k)
    (Cholesky of the Gram matrix, twice, for round-off)."""
    from mpi4py import MPI

    Q = np.array(modes.T, float)
    for _ in range(2):
        G = comm.allreduce(Q.T @ Q, op=MPI.SUM)
        L = np.linalg.cholesky(G)
        Q = np.linalg.solve(L, Q.T).T
    return Q


def use_node_blocks(ksp, w):
    """Put the AMG preconditioner of ``ksp`` (set from the options, see :data:`BLOCKED`) on the
    node-blocked matrix of the beam unknowns ``w``; call it where the options are in the
    database (the inner PC reads them). Returns the context, or None where nothing changes
    (another PC, or a space whose unknowns are not all beam nodes, e.g. with hinges)."""
    from petsc4py import PETSc

    pc = ksp.getPC()
    if pc.getType() not in BLOCKED:
        return None
    found = node_permutation(w.function_space)
    if found is None:
        return None
    inner = PETSc.PC().create(pc.getComm())
    inner.setOptionsPrefix(pc.getOptionsPrefix())
    inner.setType(pc.getType())
    inner.setFromOptions()
    context = NodeBlockedPC(inner, w, *found)
    pc.setType(PETSc.PC.Type.PYTHON)
    pc.setPythonContext(context)
    return context
