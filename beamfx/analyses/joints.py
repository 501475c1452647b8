r"""Point loads at the joints of frames, where more than two elements meet.

DOLFINx 0.5 integrates a facet measure only over facets with one cell (``ds``) or two
(``dS``); at a vertex shared by three or more elements neither reaches (the facet is silently
skipped). A point force F there is applied instead as a density on one element next to the
joint: ψ F with ψ ∈ P_p the Riesz representer of the evaluation at the joint,

    ∫_e ψ w dx = w(x_joint)   for every w ∈ P_p(e),

so the work ∫_e ψ F·v dx equals F·v(x_joint) exactly for the P_p test functions, provided F
is constant on the element (a dead force; a moment with a linear or planar rotation field) and
the element is straight with evenly spaced nodes (dx = h dξ). On [0, 1], with Legendre
polynomials P_k, ψ(ξ) = Σ_{k≤p} (2k+1) P_k(2ξ−1) P_k(2ξ_j−1) / h, ξ_j ∈ {0, 1} the joint's end
(the reproducing kernel of P_p). The quadrature of ``dx`` (degree 2p) integrates ψ·w exactly.
"""

import numpy as np
from numpy.polynomial import legendre


def kernel(xi, end, degree):
    """ψ(ξ)·h at the reference points ``xi`` for the joint at ξ = ``end`` (0 or 1)."""
    k = np.arange(degree + 1)
    at_end = (-1.0) ** k if end == 0 else np.ones(degree + 1)
    return legendre.legval(2 * np.asarray(xi) - 1, (2 * k + 1) * at_end)


def _cell_at(m, vertex, original):
    """The element at ``vertex`` first in input order, and which end (0, 1) the vertex is (a
    cell's vertices are in the order of its first two geometry nodes)."""
    cells = m.topology.connectivity(0, 1).links(vertex)
    c = int(cells[np.argmin(original[cells])])
    return c, int(np.flatnonzero(m.topology.connectivity(1, 0).links(c) == vertex)[0])


def joint_cells(disc, at):
    """The nonzero rows of :func:`joint_density`: (local cell, ψ at its DG_p nodes) for each
    local vertex of the named point ``at`` (O(1) in the mesh size, so that many joint loads
    can share one field).

    Raises:
        ValueError: if that element is curved or its nodes are not evenly spaced.
    """
    m, p = disc.mesh.mesh, disc.degree
    m.topology.create_connectivity(0, 1)
    m.topology.create_connectivity(1, 0)
    original = np.asarray(m.topology.original_cell_index)
    xi = np.r_[0.0, 1.0, np.arange(1, p) / p]  # basix order of the DG and geometry nodes
    rows = []
    for v in disc.mesh.point_tags.find(disc.mesh.points[at][0]):
        c, end = _cell_at(m, int(v), original)
        x = m.geometry.x[m.geometry.dofmap.links(c)]
        h = np.linalg.norm(x[1] - x[0])
        affine = x[0] + np.outer(xi, x[1] - x[0])
        if np.abs(x - affine).max() > 1e-9 * h:
            raise ValueError(
                f"{at!r}: a point load where more than two elements meet needs a straight "
                "element with evenly spaced nodes next to it"
            )
        rows.append((c, kernel(xi, end, p) / h))
    return rows


def joint_density(disc, at):
    """The values of ψ of the module doc at the DG_p nodes of each local cell, (n_cells,
    p + 1), for the named point ``at`` of the
    :class:`~beamfx.analyses.discretisation.Discretisation` ``disc``: nonzero on one element
    next to the point (the one first in input order, so every rank picks the same).

    Raises:
        ValueError: if that element is curved or its nodes are not evenly spaced.
    """
    m = disc.mesh.mesh
    n_cells = m.topology.index_map(1).size_local + m.topology.index_map(1).num_ghosts
    values = np.zeros((n_cells, disc.degree + 1))
    for c, row in joint_cells(disc, at):
        values[c] = row
    return values


__all__ = ["joint_cells", "joint_density", "kernel"]
