"""Where the unknowns sit: dofs of subspaces and of named points, owned ranges, constrained
dofs, and the dof names of the planar model.

Indices are local (into a Function's ``x.array``, ghosts included) unless a name says
"owned": the first :func:`owned_size` entries of a local array are this rank's, the rest are
ghosts, so a reduction over ranks counts a dof once when it looks at owned entries only.
"""

import numpy as np

from ..spec import DOF_NAMES

#: dofs that the planar model does not have, per plane
OUT_OF_PLANE = {"xy": ("uz", "rx", "ry"), "yz": ("ux", "ry", "rz"), "xz": ("uy", "rx", "rz")}


def owned_size(V):
    """Number of owned local dofs of the space ``V`` (index map size times block size)."""
    return V.dofmap.index_map.size_local * V.dofmap.index_map_bs


def global_size(V):
    """Number of dofs of the space ``V`` over all ranks."""
    return V.dofmap.index_map.size_global * V.dofmap.index_map_bs


def subspace_dofs(V, *path):
    """Local dofs (ghosts included) of the subspace ``V.sub(path[0]).sub(path[1])…``, as
    indices into ``x.array`` of a Function on ``V``. E.g. ``subspace_dofs(model.W, 0)``: the
    displacement dofs of the mixed space, ``subspace_dofs(model.W, 0, 1)`` its component 1."""
    for i in path:
        V = V.sub(i)
    return np.asarray(V.collapse()[1])


def displacement_components(kin):
    """{dof name: component of the displacement subspace} of the kinematics ``kin``; the
    planar model lacks the out-of-plane name (:data:`OUT_OF_PLANE`)."""
    return {name: comp for name, sub, comp in kin.dofs() if sub == 0}


def constrained_dofs(bcs):
    """Local indices (ghosts included) of the dofs constrained by ``bcs``."""
    if not bcs:
        return np.empty(0, np.int32)
    return np.unique(np.concatenate([bc.dof_indices()[0] for bc in bcs]))


def point_displacement_dofs(model, at):
    """Owned local dofs of u_x, u_y, u_z at the named point ``at`` of a formulation with the
    mixed space ``model.W`` = (displacement, rotation): three arrays, each with one dof on the
    rank that owns the point and empty elsewhere (and empty for a planar model's out-of-plane
    component, which is zero by construction). Collective: DOLFINx exchanges the dofs found on
    shared vertices, so all ranks must look up the same points in the same order.

    Raises:
        ValueError: if ``at`` is not a named point of the model.
    """
    from dolfinx import fem

    points = model.mesh.points
    if at not in points:
        raise ValueError(
            f"{at!r} is not a named point of the model; named points are "
            f"{sorted(points)} (supports, loads and springs)"
        )
    verts = model.mesh.point_tags.find(points[at][0])
    owned = owned_size(model.W)
    components = displacement_components(model.kin)
    out = []
    for name in DOF_NAMES[:3]:
        if name not in components:  # out of the planar model's plane: always zero
            out.append(np.empty(0, np.int32))
            continue
        d = fem.locate_dofs_topological(model.W.sub(0).sub(components[name]), 0, verts)
        out.append(d[d < owned][:1])
    return out


def point_displacement(model, dofs, values=None):
    """Displacement u at a point from :func:`point_displacement_dofs` (collective), of
    ``model.w`` or of another array of the same space (``values``)."""
    values = model.w.x.array if values is None else values
    local = np.array([values[d].sum() for d in dofs])
    count = np.array([len(d) for d in dofs], float)
    from mpi4py import MPI

    total = model.comm.allreduce(local, op=MPI.SUM)
    n = model.comm.allreduce(count, op=MPI.SUM)
    return total / np.maximum(n, 1)
