"""Line meshes of frames (towers, domes, lattices) read from a mesh file: nodes, straight
members and the named groups of members and nodes.

A gmsh ``.msh`` file (format 2.2 or 4.1, ASCII or binary) is read with meshio's gmsh reader,
which needs no gmsh session: its physical groups of dimension 1 name groups of members, those
of dimension 0 groups of nodes. Each two-node line element is one straight member. Knows nothing of sections or supports (:mod:`beamfx.scene.frames`
maps the groups to them).
"""

from typing import NamedTuple

import numpy as np

#: meshio cell types read as members and as named nodes
LINE_TYPES, POINT_TYPES = ("line",), ("vertex",)
CURVED_TYPES = ("line3", "line4")
#: nodes closer than MERGE_TOL of the frame's size are one (as beamfx.geometry.mesh joins
#: vertices); closer than NEAR_TOL but not one: duplicate nodes left unmerged, refused
MERGE_TOL, NEAR_TOL = 1e-9, 1e-6


class LineMesh(NamedTuple):
    """Nodes, members and named groups of a line mesh."""

    points: np.ndarray  # (n, 3) node coordinates
    members: np.ndarray  # (m, 2) node indices of each member, in file order, no duplicates
    member_groups: dict  # {group name: member indices}
    node_groups: dict  # {group name: node indices}
    curves: tuple = ()  # per member: None (straight) or (k, 3) points along it (a .geo curve)


def _group_names(field_data):
    """{(dimension, tag): name} of the gmsh physical groups."""
    out = {}
    for name, value in field_data.items():
        value = np.asarray(value).ravel()
        if len(value) >= 2:
            out[(int(value[1]), int(value[0]))] = name
    return out


def _blocks(mesh, path):
    """(cell type, connectivity, physical tags or None) of each cell block."""
    tags = mesh.cell_data.get("gmsh:physical")
    out = []
    for i, block in enumerate(mesh.cells):
        if block.type in CURVED_TYPES:
            raise ValueError(
                f"{path}: {block.type} elements (curved members) are not supported yet; "
                "write a first-order mesh (two-node lines)"
            )
        out.append((block.type, np.asarray(block.data), None if tags is None else tags[i]))
    return out


def read_line_mesh(path):
    """The :class:`LineMesh` of the file at ``path``: a gmsh ``.msh`` mesh (each line element
    a straight member) or a gmsh ``.geo`` geometry (:func:`read_geo_frame`).

    Nodes at one point are merged (:func:`coincident_nodes`).

    Raises:
        ValueError: naming the file, if it does not parse, holds no line element, has
            non-finite coordinates, zero-length members or nearly coincident nodes.
    """
    if str(path).lower().endswith(".geo"):
        return coincident_nodes(read_geo_frame(path), path)
    return coincident_nodes(_read_msh(path), path)


def _read_msh(path):
    """The :class:`LineMesh` of a gmsh ``.msh`` file (:func:`read_line_mesh`)."""
    import meshio.gmsh

    try:  # the format's reader itself: meshio.read would print and sys.exit on a bad file
        mesh = meshio.gmsh.read(str(path))
    except Exception as e:  # noqa: BLE001 (meshio readers raise ReadError, KeyError, ...)
        raise ValueError(f"{path}: not a mesh meshio can read ({type(e).__name__}: {e})") from None
    points = np.asarray(mesh.points, float)
    if points.ndim != 2 or not np.all(np.isfinite(points)):
        raise ValueError(f"{path}: node coordinates are not finite numbers")
    points = np.c_[points, np.zeros((len(points), 3 - points.shape[1]))][:, :3]
    names = _group_names(mesh.field_data)
    members, member_of, node_groups = {}, {}, {}
    for kind, cells, tags in _blocks(mesh, path):
        for k, cell in enumerate(cells):
            tag = None if tags is None else int(tags[k])
            if kind in LINE_TYPES:
                key = tuple(int(v) for v in cell)
                if key[::-1] in members:  # the same member twice would overlap itself
                    nodes = [n + 1 for n in key]  # numbered from 1, as in the file
                    raise ValueError(f"{path}: nodes {nodes} are joined by two members")
                index = members.setdefault(key, len(members))
                name = names.get((1, tag))
                if name is not None:
                    member_of.setdefault(name, []).append(index)
            elif kind in POINT_TYPES and names.get((0, tag)) is not None:
                node_groups.setdefault(names[(0, tag)], []).append(int(cell[0]))
    if not members:
        raise ValueError(f"{path}: no line elements (members) in the mesh")
    lines = np.array(list(members), np.int64)
    lengths = np.linalg.norm(points[lines[:, 1]] - points[lines[:, 0]], axis=1)
    if np.any(lengths <= 1e-12 * max(np.ptp(points), 1e-300)):
        i = int(np.argmin(lengths))
        nodes = (lines[i] + 1).tolist()  # numbered from 1, as the file and _describe do
        raise ValueError(f"{path}: member {i + 1} (nodes {nodes}) has zero length")
    return LineMesh(
        points,
        lines,
        {k: np.unique(v) for k, v in member_of.items()},
        {k: np.unique(v) for k, v in node_groups.items()},
    )


def _describe(mesh, node):
    """``node k (groups [...], members [...])`` for messages (numbers from 1)."""
    groups = sorted(g for g, idx in mesh.node_groups.items() if node in idx)
    members = [k + 1 for k, m in enumerate(mesh.members) if node in m]
    return f"node {node + 1} (groups {groups}, members {members})"


def coincident_nodes(mesh, path):
    """``mesh`` with nodes at the same point (closer than MERGE_TOL of its size, where
    :mod:`beamfx.geometry.mesh` joins vertices anyway) merged into the first, in members and
    node groups; members on merged nodes must stay distinct and of non-zero length.

    Raises:
        ValueError: naming the nodes, if two nodes of members are nearly but not exactly
            coincident (closer than NEAR_TOL of the size): the members there would not be
            joined (a mesh exported without merging its duplicate nodes).
    """
    from scipy.spatial import cKDTree

    used = np.unique(mesh.members)
    size = max(float(np.ptp(mesh.points[used], axis=0).max()), 1e-300)
    pairs = cKDTree(mesh.points[used]).query_pairs(NEAR_TOL * size, output_type="ndarray")
    target = np.arange(len(mesh.points))
    for i, j in sorted(map(tuple, np.sort(pairs, axis=1))):
        a, b = int(used[i]), int(used[j])
        d = float(np.linalg.norm(mesh.points[a] - mesh.points[b]))
        if d > MERGE_TOL * size:
            raise ValueError(
                f"{path}: {_describe(mesh, a)} and {_describe(mesh, b)} are {d:.3g} apart "
                f"({d / size:.1e} of the frame's size): nearly coincident, so the members there "
                "are not joined. Merge duplicate nodes (gmsh: Coherence Mesh) or move them apart"
            )
        target[b] = target[a] if target[b] == b else target[b]
    while np.any(target[target] != target):
        target = target[target]
    if np.all(target == np.arange(len(target))):
        return mesh
    members = target[mesh.members]
    keys = [tuple(sorted(m)) for m in members.tolist()]
    if any(a == b for a, b in keys) or len(set(keys)) != len(keys):
        raise ValueError(f"{path}: merging coincident nodes leaves members on one node or twice")
    groups = {k: np.unique(target[v]) for k, v in mesh.node_groups.items()}
    return mesh._replace(members=members, node_groups=groups)


def read_geo_frame(path, samples=201):
    """The :class:`LineMesh` of a gmsh ``.geo`` file (read by
    :func:`~beamfx.geometry.curves.read_gmsh`, no meshing): each curve (1D entity) is one
    member between its two end points, straight or curved (then sampled along gmsh's
    parametrisation); physical groups of curves and points name member and node groups."""
    from .curves import read_gmsh

    return read_gmsh(path, lambda gmsh: _geo_frame(gmsh, str(path), samples))


def _geo_frame(gmsh, path, samples):
    """:func:`read_geo_frame` on the open gmsh model."""
    nodes, points, members, curves, index = {}, [], [], [], {}

    def node(tag):
        if tag not in nodes:
            nodes[tag] = len(points)
            points.append(np.reshape(gmsh.model.getValue(0, tag, []), 3))
        return nodes[tag]

    for _, tag in gmsh.model.getEntities(1):
        ends = [t for _, t in gmsh.model.getBoundary([(1, tag)], combined=False, oriented=False)]
        if len(ends) != 2 or ends[0] == ends[1]:
            raise ValueError(f"{path}: curve {tag} is closed; split it into members with two ends")
        lo, hi = gmsh.model.getParametrizationBounds(1, tag)
        xyz = np.reshape(gmsh.model.getValue(1, tag, np.linspace(lo[0], hi[0], samples)), (-1, 3))
        a, b = node(ends[0]), node(ends[1])
        if np.linalg.norm(xyz[0] - points[a]) > np.linalg.norm(xyz[0] - points[b]):
            a, b = b, a  # members run along the parametrisation
        chord = xyz[-1] - xyz[0]
        off = np.cross(xyz - xyz[0], chord / max(np.linalg.norm(chord), 1e-300))
        straight = np.abs(off).max() <= 1e-9 * np.linalg.norm(chord)
        index[tag] = len(members)
        members.append((a, b))
        curves.append(None if straight else xyz)
    if not members:
        raise ValueError(f"{path}: no curves (members) in the file")
    groups = {1: {}, 0: {}}
    for dim, ptag in gmsh.model.getPhysicalGroups():
        name = gmsh.model.getPhysicalName(dim, ptag) or str(ptag)
        tags = gmsh.model.getEntitiesForPhysicalGroup(dim, ptag)
        if dim in groups:
            ids = [index[t] for t in tags] if dim == 1 else [node(t) for t in tags]
            groups[dim][name] = np.unique(np.asarray(ids, np.int64))
    lines = np.array(members, np.int64)
    return LineMesh(np.array(points), lines, groups[1], groups[0], tuple(curves))


def write_line_mesh(path, points, members, member_groups, node_groups):
    """Write a gmsh 2.2 ASCII ``.msh`` with the groups as physical groups (the examples in
    meshes/ are made with it): ``member_groups`` {name: member indices}, ``node_groups``
    {name: node indices}; a member in no group is written without one."""
    import meshio

    line_cells, line_tags, vertex_cells, vertex_tags, field_data = [], [], [], [], {}
    grouped = np.zeros(len(members), bool)
    for tag, (name, idx) in enumerate(member_groups.items(), start=1):
        field_data[name] = np.array([tag, 1])
        line_cells += [members[i] for i in idx]
        line_tags += [tag] * len(idx)
        grouped[list(idx)] = True
    line_cells += [m for m, g in zip(members, grouped) if not g]
    line_tags += [0] * int(np.count_nonzero(~grouped))
    for tag, (name, idx) in enumerate(node_groups.items(), start=len(member_groups) + 1):
        field_data[name] = np.array([tag, 0])
        vertex_cells += [[i] for i in idx]
        vertex_tags += [tag] * len(idx)
    cells = [("line", np.array(line_cells, np.int64))]
    tags = [np.array(line_tags, np.int32)]
    if vertex_cells:
        cells.append(("vertex", np.array(vertex_cells, np.int64)))
        tags.append(np.array(vertex_tags, np.int32))
    mesh = meshio.Mesh(
        np.asarray(points, float),
        cells,
        cell_data={"gmsh:physical": tags, "gmsh:geometrical": tags},
        field_data=field_data,
    )
    meshio.write(str(path), mesh, file_format="gmsh22", binary=False)


__all__ = [
    "LineMesh",
    "coincident_nodes",
    "read_geo_frame",
    "read_line_mesh",
    "write_line_mesh",
]
