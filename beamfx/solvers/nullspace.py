"""The rigid-body near-null space of a 3D beam's tangent, for smoothed-aggregation AMG (GAMG).

A free beam frame moves rigidly without strain: three translations (u = e_i, no rotation) and
three rotations ω (u = ω × x, the rotation field turned by ω). Smoothed aggregation builds its
coarse spaces from these six vectors per aggregate of nodes; without them (the default, one
constant vector) its coarse spaces miss the bending modes and CG's iterations grow with the
frame.

The rotation unknowns enter as

* a rotation vector θ (linear kinematics): δθ = ω;
* a quaternion q of any norm (finite kinematics): a superposed spatial rotation ω changes it
  by δq = ½ (0, ω) ⊗ q, since the spatial rate 2 Im(δq q̄)/|q|² is then ω
  (:func:`beamfx.physics.rotations.spatial_rate`); the displacement by δu = ω × (X + u).
  The strain energy is invariant under every superposed rigid motion, so at an unloaded
  state these six vectors span the tangent's kernel; under load the tangent differs by the
  load-stiffness terms and they are near-null vectors, recomputed at each tangent.

The scaling of a quaternion (δq ∝ q) is also strain-free but the penalty on |q|² − 1 makes it
stiff, so it is not a near-null vector. Hinge unknowns of released joints (DG0 relative
rotations) do not move in a rigid motion: they are zero in the six vectors.
"""

import numpy as np


def beam_node_dofs(W):
    """The nodes of a 3D beam's mixed space ``W`` = (displacement P_k³, rotation P_k³ or P_k⁴,
    ...): (u dofs (nodes, 3), rotation dofs (nodes, r)), local indices (ghosts included), one
    row per local node, sorted by the first u dof; None if ``W`` is not such a space."""
    if W.num_sub_spaces < 2:
        return None
    U, R = W.sub(0), W.sub(1)
    nu, nr = U.num_sub_spaces, R.num_sub_spaces
    if nu != 3 or nr not in (3, 4) or U.ufl_element().degree() != R.ufl_element().degree():
        return None
    u = U.dofmap.list.array.reshape(-1, 3)  # cell-major, node-major, component
    r = R.dofmap.list.array.reshape(-1, nr)
    if len(u) != len(r):
        return None
    _, rows = np.unique(u[:, 0], return_index=True)
    return u[rows], r[rows]


def node_positions(W, u_dofs):
    """The reference positions of the nodes of ``u_dofs`` (rows of :func:`beam_node_dofs`)."""
    V0, collapsed = W.sub(0).collapse()
    first = np.asarray(collapsed)[0::3]  # the W dof of component 0 of each collapsed node
    node = np.empty(_local_size(W), np.int64)
    node[first] = np.arange(len(first))
    return V0.tabulate_dof_coordinates()[node[u_dofs[:, 0]]]


def rigid_modes(W, u_dofs, r_dofs, x=None, X=None):
    """The six rigid-body motions on the local array of ``W`` (ghosts included), (6, size):
    translations e_i, then rotations about e_i through the centroid of the nodes. ``x``: the
    current local array (its displacement and quaternion enter the rotations); None: the
    reference state (u = 0, q = (1, 0, 0, 0)). ``X``: the nodes' :func:`node_positions`, if
    already known."""
    X = node_positions(W, u_dofs) if X is None else X
    size = len(x) if x is not None else _local_size(W)
    if x is not None:
        X = X + x[u_dofs]
    X = X - _centroid(X, W)
    modes = np.zeros((6, size))
    for i in range(3):
        modes[i, u_dofs[:, i]] = 1.0
        omega = np.eye(3)[i]
        modes[3 + i, u_dofs] = np.cross(omega, X)
        modes[3 + i, r_dofs] = _rotation_part(omega, r_dofs, x)
    return modes


def _rotation_part(omega, r_dofs, x):
    """The change of the rotation unknowns under the spatial rotation ``omega``."""
    if r_dofs.shape[1] == 3:
        return np.broadcast_to(omega, r_dofs.shape)
    q = np.tile([1.0, 0.0, 0.0, 0.0], (len(r_dofs), 1)) if x is None else x[r_dofs]
    q0, v = q[:, 0], q[:, 1:]
    dq0 = -v @ omega  # ½ (0, ω) ⊗ (q0, v) = ½ (−ω·v, q0 ω + ω × v)
    dv = q0[:, None] * omega + np.cross(omega, v)
    return 0.5 * np.column_stack([dq0, dv])


def _local_size(W):
    im = W.dofmap.index_map
    return (im.size_local + im.num_ghosts) * W.dofmap.index_map_bs


def _centroid(X, W):
    """The mean node position over all ranks (ghost nodes counted twice: any point near the
    frame will do, it only keeps the rotations' vectors well scaled)."""
    from mpi4py import MPI

    comm = W.mesh.comm
    return comm.allreduce(X.sum(axis=0), op=MPI.SUM) / max(comm.allreduce(len(X)), 1)


def node_permutation(W):
    """The owned local dofs of ``W`` node by node: (indices (owned,), block size), each node's
    displacement then rotation unknowns; None unless every owned dof belongs to a beam node
    on every rank (e.g. not with hinge unknowns, nor for other spaces). Collective."""
    from mpi4py import MPI

    nodes = beam_node_dofs(W)
    comm = W.mesh.comm
    ok, perm, bs = nodes is not None, None, 0
    if ok:
        n_owned = W.dofmap.index_map.size_local * W.dofmap.index_map_bs
        u, r = nodes
        owned = u[:, 0] < n_owned
        perm = np.hstack([u[owned], r[owned]]).ravel()
        bs = u.shape[1] + r.shape[1]
        ok = len(perm) == n_owned and perm.max(initial=-1) < n_owned
        ok = ok and len(np.unique(perm)) == n_owned
    if not comm.allreduce(bool(ok), op=MPI.LAND):
        return None
    return perm.astype(np.int32), bs
