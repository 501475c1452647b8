"""Body-centred cubic (BCC) lattice blocks of n × n × n cells as line meshes, for any n.

The block of demos/scenes/lattice.toml (3 × 3 × 3 cells) at any size: the cube edges of
every cell, and in every cell the eight half-diagonals ("struts") from its corners to a
centre node. Built with NumPy in O(nodes) (no gmsh session), so a block of 10⁶ unknowns
(22³ cells, 1.2·10⁵ members) takes a fraction of a second.

Counts for n cells along an edge: (n + 1)³ + n³ nodes, 3n(n + 1)² edges and 8n³ struts.
With one element of degree p per member each member adds p − 1 interior nodes, and every
node carries 7 unknowns in the finite-rotation model (3 displacements, 4 quaternion
components) or 6 in the linear one (3 displacements, 3 rotations).
"""

from typing import NamedTuple

import numpy as np

from .line_mesh import LineMesh


class LatticeCounts(NamedTuple):
    """Sizes of a BCC block: nodes and members of the line mesh, and the mesh nodes and
    unknowns of a model with one element of degree ``degree`` per member."""

    nodes: int
    members: int
    mesh_nodes: int
    unknowns: int


def bcc_counts(cells, degree=2, dofs_per_node=7):
    """:class:`LatticeCounts` of a ``cells``³ BCC block (no mesh is built)."""
    n = int(cells)
    nodes = (n + 1) ** 3 + n**3
    members = 3 * n * (n + 1) ** 2 + 8 * n**3
    mesh_nodes = nodes + (degree - 1) * members
    return LatticeCounts(nodes, members, mesh_nodes, dofs_per_node * mesh_nodes)


def cells_for(unknowns, degree=2, dofs_per_node=7):
    """The smallest number of cells along an edge whose block has at least ``unknowns``."""
    n = 1
    while bcc_counts(n, degree, dofs_per_node).unknowns < unknowns:
        n += 1
    return n


def _edges(n):
    """(m, 2) node pairs of the cube edges of an (n + 1)³ grid, x- then y- then z-edges."""
    idx = np.arange((n + 1) ** 3).reshape(n + 1, n + 1, n + 1)  # [k, j, i]
    pairs = [
        (idx[:, :, :-1], idx[:, :, 1:]),  # along x
        (idx[:, :-1, :], idx[:, 1:, :]),  # along y
        (idx[:-1, :, :], idx[1:, :, :]),  # along z
    ]
    return np.vstack([np.c_[a.ravel(), b.ravel()] for a, b in pairs])


def _struts(n):
    """(8n³, 2) node pairs from each cell's eight corners to its centre node."""
    idx = np.arange((n + 1) ** 3).reshape(n + 1, n + 1, n + 1)
    centre = (n + 1) ** 3 + np.arange(n**3).reshape(n, n, n)
    out = [
        np.c_[idx[dk : dk + n, dj : dj + n, di : di + n].ravel(), centre.ravel()]
        for dk, dj, di in np.ndindex(2, 2, 2)
    ]
    return np.vstack(out)


def bcc_lattice(cells, size=0.01):
    """The :class:`~beamfx.geometry.line_mesh.LineMesh` of a ``cells``³ BCC block of cell edge
    ``size`` with its corner at the origin: member groups ``edges`` and ``struts``, node groups
    ``bottom`` (z = 0) and ``top`` (z = cells·size) of the grid nodes, and ``corner`` (the
    node at the top corner x = y = z = cells·size, e.g. for a probe).

    Each strut runs from the corner to the centre node, each edge in the +x, +y or +z
    direction, so members are oriented consistently.
    """
    n = int(cells)
    if n < 1:
        raise ValueError(f"cells = {cells}: a lattice needs at least one cell")
    k, j, i = np.meshgrid(*(np.arange(n + 1),) * 3, indexing="ij")
    grid = np.c_[i.ravel(), j.ravel(), k.ravel()].astype(float)
    k, j, i = np.meshgrid(*(np.arange(n),) * 3, indexing="ij")
    centres = np.c_[i.ravel(), j.ravel(), k.ravel()] + 0.5
    points = np.vstack([grid, centres]) * size
    edges, struts = _edges(n), _struts(n)
    layer = (n + 1) ** 2
    return LineMesh(
        points,
        np.vstack([edges, struts]).astype(np.int64),
        {
            "edges": np.arange(len(edges)),
            "struts": np.arange(len(edges), len(edges) + len(struts)),
        },
        {
            "bottom": np.arange(layer),
            "top": np.arange(n * layer, (n + 1) * layer),
            "corner": np.array([(n + 1) ** 3 - 1]),
        },
    )


def write_bcc_lattice(path, cells, size=0.01):
    """Write :func:`bcc_lattice` as a gmsh 2.2 ``.msh`` file for ``[[frames]]``."""
    from .line_mesh import write_line_mesh

    m = bcc_lattice(cells, size)
    write_line_mesh(path, m.points, m.members, m.member_groups, m.node_groups)
    return m


__all__ = ["LatticeCounts", "bcc_counts", "bcc_lattice", "cells_for", "write_bcc_lattice"]
