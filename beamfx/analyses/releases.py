r"""Joints that are not rigid: member ends released (hinged, pinned) at their node.

Where members share a mesh vertex their displacement and rotation are one continuous field
(a rigid joint). A release frees some rotation components of one member end relative to the
node, in the joint's axes e_i (columns of E, rows of :attr:`~beamfx.spec.Release.axes`):

    member end rotation = node rotation ∘ relative rotation about Σ_{i released} φ_i e_i.

Implementation (chosen for DOLFINx 0.5.2, which has no multipoint constraints, and for the
energy-first model): the element of the member next to the joint is *enriched* by the
relative rotation. Its rotation field is the node field composed with ψ(s)·g, where
g = E φ (φ: DG0 unknowns of that cell, one per released component and end) and ψ the
degree-p Lagrange basis function of the joint's vertex in that cell (1 there, 0 at the
cell's other nodes). This is exactly the space of a duplicated rotation node: the member's
rotation at the joint is the node's plus the free components, everywhere else it is
unchanged; displacements stay continuous. Nothing is penalised, so a linear release is
exact (to round-off), and no solver or assembly changes: the forms just see a third
sub-space ``W.sub(2)`` (DG0, 6 components: 3 per cell end), whose unused components are
fixed to zero by Dirichlet conditions.

* Linear kinematics: θ_member = θ + ψ g.
* Finite kinematics (quaternions): q_member = q ⊗ (1, ψ g / 2), the relative rotation by
  2 atan(|ψ g|/2) about g, applied on the right: about the joint axes carried by the node's
  rotation, so a release stays a release under large rotations (angles of the relative
  rotation below 180°; the quaternion product of a unit and a non-unit quaternion is a
  rotation for :func:`~beamfx.physics.rotations.rotation`, the norm penalty acts on q only).
* Planar model: angle_member = angle + ψ φ about the plane's normal (a joint axis must be
  normal to the plane; releases of in-plane axes change nothing in a plane).

The rotary inertia of an enriched element follows the node field (φ carries no mass). The
mechanism check (:mod:`beamfx.analyses.mechanisms`) runs before a solve.
"""

from typing import NamedTuple

import numpy as np
import ufl

from ..spec import resolve_point

RELEASE_NAMES = ("rx", "ry", "rz")
#: components of the hinge unknowns per cell: 3 at its vertex 0, 3 at its vertex 1
HINGE_SIZE = 6


class HingeFields(NamedTuple):
    """The data of the enriched elements (:func:`hinge_fields`)."""

    psi: tuple  #: (ψ_0, ψ_1): DG_p basis functions of the cell's vertex 0 and 1
    axes: tuple  #: (E_0, E_1): DG0 9-vectors, released joint axes as columns (0 elsewhere)
    free: list  #: (local cell, slot, component, release index) of each free hinge unknown


def release_cells(disc, releases):
    """(local cell, slot, release index) of each released member end on this rank (with
    ghosts): the cell of the member at the end, and which of its vertices (0, 1) is there.

    Raises:
        ValueError: if a release names no member end (``beam:start`` or ``beam:end``).
    """
    spec, mesh = disc.spec, disc.mesh
    m, p = mesh.mesh, mesh.degree
    n = len(mesh.cell_beam)
    nodes = m.geometry.dofmap.array.reshape(-1, p + 1)[:n]
    out = []
    for r, rel in enumerate(releases):
        if not str(rel.at).endswith((":start", ":end")):
            raise ValueError(f"release {rel.at!r}: name a member end, 'beam:start' or 'beam:end'")
        b, s, xyz = resolve_point(spec, rel.at)
        span = mesh.cell_span
        on = np.flatnonzero(
            (mesh.cell_beam == b) & np.isclose(span.min(axis=1) if s == 0 else span.max(axis=1), s)
        )
        for c in on:
            ends = m.geometry.x[nodes[c, :2]]
            out.append((int(c), int(np.argmin(np.linalg.norm(ends - xyz, axis=1))), r))
    return out


def _free_components(kin, rel):
    """Indices (0, 1, 2) of the joint axes whose relative rotation is free."""
    idx = [RELEASE_NAMES.index(x) for x in rel.released]
    if not kin.plane:
        return idx
    from ..physics.kinematics import PLANES

    n = np.zeros(3)
    n[PLANES[kin.plane][2]] = 1.0
    along = np.abs(np.asarray(rel.axes, float) @ n)
    if along.max() < 1 - 1e-9:
        raise ValueError(
            f"release {rel.at!r}: in the planar model {kin.plane} a joint axis must be "
            "normal to the plane"
        )
    i = int(np.argmax(along))
    return [i] if i in idx else []


def hinge_fields(disc, kin, releases):
    """The :class:`HingeFields` of ``releases`` on the discretisation ``disc``."""
    from .discretisation import cell_field

    p, n = disc.degree, len(disc.mesh.cell_beam)
    E = np.zeros((2, n, 3, 3))
    free = []
    for c, slot, r in release_cells(disc, releases):
        rel = releases[r]
        axes = np.asarray(rel.axes, float)
        for i in _free_components(kin, rel):
            E[slot, c, :, i] = axes[i]
            free.append((c, slot, i, r))
    psi = []
    for slot in (0, 1):  # basix order of the DG_p nodes: vertex 0, vertex 1, then interior
        values = np.zeros((n, p + 1))
        values[:, slot] = 1.0
        psi.append(cell_field(disc.mesh.mesh, p, values))
    axes = tuple(cell_field(disc.mesh.mesh, 0, E[k].reshape(n, 1, 9)) for k in (0, 1))
    return HingeFields(tuple(psi), axes, free)


def hinge_rotation(fields, phi):
    """The relative rotation g = Σ_k ψ_k E_k φ_k (vector, reference global axes) at each
    point of the enriched cells, zero elsewhere."""
    g = 0
    for k in (0, 1):
        E = ufl.as_matrix([[fields.axes[k][3 * a + b] for b in range(3)] for a in range(3)])
        g += fields.psi[k] * E * ufl.as_vector([phi[3 * k + i] for i in range(3)])
    return g


def quaternion_product(a, b):
    """The Hamilton product a ⊗ b (scalar part first): R(a ⊗ b) = R(a) R(b)."""
    va, vb = ufl.as_vector([a[1], a[2], a[3]]), ufl.as_vector([b[1], b[2], b[3]])
    v = a[0] * vb + b[0] * va + ufl.cross(va, vb)
    return ufl.as_vector([a[0] * b[0] - ufl.dot(va, vb), v[0], v[1], v[2]])


def member_rotation(kin, rot, phi, fields):
    """The rotation unknown of the members: the node field ``rot`` with the released
    relative rotations of the enriched cells (module doc)."""
    g = hinge_rotation(fields, phi)
    if kin.plane:
        from ..physics.kinematics import plane_normal

        return ufl.as_vector([rot[0] + ufl.dot(g, plane_normal(kin))])
    if not kin.finite:
        return rot + g
    return quaternion_product(rot, ufl.as_vector([1.0, g[0] / 2, g[1] / 2, g[2] / 2]))


def hinge_bcs(W, fields):
    """Dirichlet conditions (zero) on the hinge unknowns that no release frees."""
    from dolfinx import fem
    from petsc4py import PETSc

    m = W.mesh
    n = m.topology.index_map(1).size_local + m.topology.index_map(1).num_ghosts
    fixed = np.ones((n, HINGE_SIZE), bool)
    for c, slot, i, _ in fields.free:
        fixed[c, 3 * slot + i] = False
    bcs = []
    for j in range(HINGE_SIZE):
        V = W.sub(2).sub(j)
        dofs = fem.locate_dofs_topological(V, 1, np.flatnonzero(fixed[:, j]).astype(np.int32))
        bcs.append(fem.dirichletbc(PETSc.ScalarType(0), dofs, V))
    return bcs


def hinge_dofs(W, fields):
    """{release index: local dof indices (in ``W``) of its free hinge unknowns}."""
    out = {}
    for c, slot, i, r in fields.free:
        dof = W.sub(2).sub(3 * slot + i).dofmap.cell_dofs(c)[0]
        out.setdefault(r, []).append(int(dof))
    return out


__all__ = [
    "HINGE_SIZE",
    "RELEASE_NAMES",
    "HingeFields",
    "hinge_bcs",
    "hinge_dofs",
    "hinge_fields",
    "member_rotation",
    "release_cells",
]
