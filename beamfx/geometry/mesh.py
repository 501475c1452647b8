"""Interval meshes of one or more beams embedded in 3D, with named points.

Beams that share a point (within a tolerance) share the mesh vertex there: the joint is rigid
because displacement and rotation are continuous fields. Only rank 0 builds the node list;
DOLFINx distributes the cells.
"""

from dataclasses import dataclass, field
from itertools import pairwise
from typing import NamedTuple

import numpy as np


@dataclass(frozen=True)
class BeamSpec:
    """One beam of a model: a curve, its element count and the arc lengths that need vertices."""

    name: str
    curve: object
    elements: int
    breaks: tuple = ()  # arc lengths of named points inside the beam
    cell_data: dict = field(default_factory=dict)  # per-beam values copied to its cells


class BeamMesh(NamedTuple):
    """The interval mesh of a model's beams with the cells' beams and spans and the named points."""

    mesh: object  # dolfinx.mesh.Mesh, P_k geometry
    degree: int
    specs: tuple
    cell_beam: np.ndarray  # beam index of each local cell (with ghosts)
    cell_span: np.ndarray  # (n_local_cells, 2): arc lengths (s_a, s_b) of each cell in its beam
    point_tags: object  # dolfinx MeshTags on vertices, value = point id
    points: dict  # name -> (id, xyz)


def _element_breaks(spec):
    """Arc lengths of all cell vertices of one beam: kinks and breaks are vertices."""
    L = spec.curve.length
    cuts = sorted({0.0, L, *spec.curve.kinks, *spec.breaks})
    cuts = [c for i, c in enumerate(cuts) if i == 0 or c - cuts[i - 1] > 1e-12 * L]
    spans = np.diff(cuts)
    n = np.maximum(1, np.round(spans / L * spec.elements)).astype(int)
    while n.sum() > max(spec.elements, len(spans)):  # keep the requested total, ≥ 1 per span
        n[np.argmax(np.where(n > 1, n / spans, -np.inf))] -= 1
    while n.sum() < spec.elements:
        n[np.argmax(spans / n)] += 1
    return np.concatenate(
        [np.linspace(a, b, k + 1)[:-1] for a, b, k in zip(cuts[:-1], cuts[1:], n)] + [[L]]
    )


def _vertex_keys(xyz, tol):
    """The keys under which vertices at the points ``xyz`` (n, 3) are one node: their
    coordinates rounded to ``tol`` (:func:`tolerance`), as tuples."""
    return list(map(tuple, np.round(np.asarray(xyz, float) / tol).astype(np.int64)))


def _nodes_and_cells(specs, degree, tol, breaks=None):
    """Rank-0 node coordinates, cells (DOLFINx order), beam of each cell and its (s_a, s_b);
    ``breaks``: :func:`_element_breaks` of each spec, if known."""
    pts, cells, beam_of, spans = [], [], [], []
    vertex_ids = {}  # rounded coordinate -> node index, merges shared vertices

    def vertex(x):
        [key] = _vertex_keys([x], tol)
        if key not in vertex_ids:
            vertex_ids[key] = len(pts)
            pts.append(x)
        return vertex_ids[key]

    for b, spec in enumerate(specs):
        s_v = _element_breaks(spec) if breaks is None else breaks[b]
        for sa, sb in pairwise(s_v):
            local = np.linspace(sa, sb, degree + 1)
            xyz = spec.curve.points(local)
            ends = [vertex(xyz[0]), vertex(xyz[-1])]
            inner = list(range(len(pts), len(pts) + degree - 1))
            pts.extend(xyz[1:-1])
            cells.append(ends + inner)
            beam_of.append(b)
            spans.append((sa, sb))
    return np.array(pts, float), np.array(cells, np.int64), np.array(beam_of), np.array(spans)


def node_count(specs, degree):
    """The nodes of the mesh :func:`build_mesh` makes of ``specs`` at ``degree`` (shared
    vertices merged by the same keys, :func:`_vertex_keys`), without building it (NumPy
    only)."""
    tol = tolerance(specs)
    keys, cells = set(), 0
    for spec in specs:
        s_v = _element_breaks(spec)
        cells += len(s_v) - 1
        keys.update(_vertex_keys(spec.curve.points(s_v), tol))
    return len(keys) + cells * (degree - 1)


def tolerance(specs):
    """The distance under which two mesh vertices are one (1e-9 of the model's size)."""
    size = max(np.ptp(np.vstack([s.curve.points([0, s.curve.length]) for s in specs])), 1.0)
    return 1e-9 * size


def mesh_size(mesh):
    """The model's size: the largest extent along x, y or z of the nodes of the (distributed)
    DOLFINx ``mesh`` over all ranks, the same on every rank. Collective.

    Each rank holds a part of the mesh (its cells and ghosts), so the box of its own nodes is
    not the model's: the bounds are reduced over the ranks before the extent is taken.
    """
    from mpi4py import MPI

    x = mesh.geometry.x
    bounds = np.full(6, -np.inf)  # (−min, max) per axis: one reduction with MAX
    if len(x):
        bounds = np.r_[-x.min(axis=0), x.max(axis=0)]
    mesh.comm.Allreduce(MPI.IN_PLACE, bounds, op=MPI.MAX)
    extent = bounds[3:] + bounds[:3]
    return float(extent.max()) if np.isfinite(extent).all() else 0.0


def overlapping_cells(specs, tol=None, breaks=None):
    """(index of the spec, why) if the element vertices of ``specs`` would make a broken
    mesh, or None.

    Vertices closer than :func:`tolerance` are merged (that is how beams share a joint, and a
    closed curve closes). A curve that runs over itself (an arc of 720°) would then give two
    cells on the same two vertices, or a cell whose two ends are one vertex. ``tol`` and
    ``breaks`` (:func:`_element_breaks` of each spec): given by a caller that has them.
    """
    tol = tolerance(specs) if tol is None else tol
    ids, seen = {}, {}
    for index, spec in enumerate(specs):
        s_v = _element_breaks(spec) if breaks is None else breaks[index]
        keys = np.round(np.asarray(spec.curve.points(s_v), float) / tol).astype(np.int64)
        v = [ids.setdefault(tuple(k), len(ids)) for k in keys]
        for i, (a, b) in enumerate(pairwise(v)):
            where = f"beam {spec.name!r}, element {i} (arc length {s_v[i]:.6g} to {s_v[i + 1]:.6g})"
            if a == b:
                return index, f"{where} has both ends at one point: elements shorter than {tol:.1e}"
            other = seen.setdefault((min(a, b), max(a, b)), where)
            if other != where:
                return index, (
                    f"{where} lies on {other} (the same two end points): the curve runs over "
                    "itself, or two one-element beams join the same points (give more elements)"
                )
    return None


def _serial_partitioner(comm, n_parts, tdim, cells, ghost_mode):
    """DOLFINx's cell partitioner for one process: the destination of every cell is rank 0."""
    import dolfinx.cpp

    return dolfinx.cpp.graph.AdjacencyList_int32(np.zeros(cells.num_nodes, np.int32))


def build_mesh(comm, specs, degree, named_points=None):
    """Mesh of all beams with isoparametric P_degree geometry on the exact curves.

    Args:
        comm: MPI communicator.
        specs: sequence of :class:`BeamSpec`.
        degree: polynomial degree of the geometry (and of the fields built on it).
        named_points: ``{name: xyz}`` of points that must be mesh vertices (probes, loads).

    Returns:
        :class:`BeamMesh`.
    """
    import dolfinx
    import ufl
    from mpi4py import MPI

    tol = tolerance(specs)
    # a curve over itself gives duplicated cells, on which DOLFINx's topology aborts the
    # process (munmap_chunk, SIGABRT) or fails on some ranks only: refuse it on every rank
    # each beam's element breaks once on rank 0, for the overlap check and the node list
    breaks = [_element_breaks(s) for s in specs] if comm.rank == 0 else None
    problem = comm.bcast(overlapping_cells(specs, tol, breaks) if comm.rank == 0 else None, root=0)
    if problem:
        raise ValueError(problem[1])
    if comm.rank == 0:
        x, cells, beam_of, spans = _nodes_and_cells(specs, degree, tol, breaks)
        del breaks
    else:
        x, cells = np.empty((0, 3)), np.empty((0, degree + 1), np.int64)
        beam_of, spans = None, None
    beam_of, spans = comm.bcast((beam_of, spans), root=0)

    cell = ufl.Cell("interval", geometric_dimension=3)
    # variant="equispaced": FFCx would set it anyway and then miss the JIT cache (notes, P5)
    domain = ufl.Mesh(ufl.VectorElement("Lagrange", cell, degree, variant="equispaced"))
    # cells as the adjacency list the C++ takes: an array makes DOLFINx try and fail first
    # (a TypeError whose message prints the arrays), then convert
    adjacency = dolfinx.cpp.graph.AdjacencyList_int64(np.asarray(cells, np.int64))
    if comm.size == 1:  # one part: every cell stays, without a call to the graph partitioner
        ghosts = dolfinx.mesh.GhostMode.shared_facet  # DOLFINx's default
        mesh = dolfinx.mesh.create_mesh(comm, adjacency, x, domain, ghosts, _serial_partitioner)
    else:
        mesh = dolfinx.mesh.create_mesh(comm, adjacency, x, domain)

    original = np.asarray(mesh.topology.original_cell_index)
    tdim = mesh.topology.dim
    n_local = mesh.topology.index_map(tdim).size_local + mesh.topology.index_map(tdim).num_ghosts
    original = original[:n_local]

    named_points = dict(named_points or {})
    ids, vertices, values = {}, [], []
    for i, (name, xyz) in enumerate(named_points.items(), start=1):
        xyz = np.asarray(xyz, float)
        found = dolfinx.mesh.locate_entities(
            mesh, 0, lambda X, p=xyz: np.linalg.norm(X.T - p, axis=1) < 1e3 * tol
        )
        if comm.allreduce(len(found), op=MPI.SUM) == 0:
            raise ValueError(f"point {name!r} at {xyz.tolist()} is on no beam")
        ids[name] = (i, xyz)
        vertices.append(found)
        values.append(np.full(len(found), i, np.int32))
    if vertices:
        v = np.concatenate(vertices)
        order = np.argsort(v)
        point_tags = dolfinx.mesh.meshtags(
            mesh, 0, v[order].astype(np.int32), np.concatenate(values)[order]
        )
    else:
        point_tags = dolfinx.mesh.meshtags(mesh, 0, np.empty(0, np.int32), np.empty(0, np.int32))
    return BeamMesh(mesh, degree, tuple(specs), beam_of[original], spans[original], point_tags, ids)
