"""``[[frames]]``: frames (towers, domes, lattices) read from a line mesh file whose groups
name the sections, orientations, supports, loads and probes.

Each two-node line of a ``.msh`` mesh, and each curve (straight or curved) of a ``.geo``
geometry, becomes a beam ``<name>.<k>`` (k = 1, 2, ... in file order) with the frame's
``elements`` and ``degree``; members meet at shared nodes, where the joint is rigid
(displacement and rotation are continuous fields) unless ``[[frames.joints]]`` pins it or
releases rotation components (:mod:`beamfx.scene.frame_joints`). A node group names points: each of its
nodes becomes the end of one member meeting there, so supports, point loads and probes of a
group are ordinary ``[[supports]]``, ``[[loads]]`` and ``[[probes]]`` entries of
the model. Example (docs/scenes.md, "Frames from mesh files")::

    [[frames]]
    name = "tower"
    mesh = "tower.msh"        # gmsh .msh or .geo (physical groups), beside the scene file
    elements = 2              # per member
    degree = 2
    [[frames.members]]
    group = "legs"            # a physical group of lines
    section = { type = "tube", d = 0.2, d_inner = 0.18 }
    orientation = [1, 0, 0]   # optional: the section's local z (default: as for [[beams]])
    [[frames.supports]]
    group = "base"            # a physical group of points
    fix = "all"
    [[frames.loads]]
    group = "top"
    force = [5e3, 0, 0]       # at every node of the group
    [[frames.probes]]
    group = "top"             # probes "top" (one node) or "top.1", "top.2", ...
    [[frames.joints]]
    group = "knees"           # a node group whose joints are not rigid
    type = "pinned"           # or releases = ["rz"], axes = "member" (frame_joints)
    [[frames.offsets]]
    group = "legs"            # eccentric ends: rigid arms from the nodes (frame_joints)
    offset = [0, 0, 0.1]
"""

from typing import NamedTuple

import numpy as np

from ..geometry.curves import Line, SampledCurve
from ..spec import LOAD_KINDS, Beam, PointLoad, Support
from .files import named_file
from .frame_joints import end_points, offset_line, read_joints, read_offsets, rigid_arms
from .limits import unknowns
from .loads import read_fix
from .table import SceneError, Table

MESH_SUFFIXES = (".msh", ".geo")
#: the analyses that take released joints (the others read two fields of the unknowns)
RELEASE_ANALYSES = ("static", "linear_static", "modal", "arclength")


class FrameParts(NamedTuple):
    """What the ``[[frames]]`` tables add to the model: beams, supports, point loads, probes
    and the releases of their non-rigid joints."""

    beams: list
    supports: list
    point_loads: list
    probes: dict
    releases: list  # :class:`~beamfx.spec.Release` of member ends at non-rigid joints


def _mesh_path(t, base, limits):
    """The mesh file of ``t['mesh']``: a regular ``.msh`` file inside the scene's folder
    (:func:`~beamfx.scene.files.named_file`)."""
    return named_file(
        base, t.get("mesh", str), limits, lambda message: t.fail("mesh", message), MESH_SUFFIXES
    )


def _groups(t, key, mesh_groups, kind):
    """The group named by ``t[key]``; a group the mesh lacks fails, listing those it has."""
    name = t.get(key, str)
    if name not in mesh_groups:
        t.fail(key, f"the mesh has no {kind} group {name!r}; it has {sorted(mesh_groups)}")
    return name, mesh_groups[name]


def _members(frame, mesh, name, read_section):
    """Beams of the mesh's lines, with the section and orientation of their group."""
    section = [None] * len(mesh.members)
    orientation, twist = [None] * len(mesh.members), [0.0] * len(mesh.members)
    for t in _sub_tables(frame, "members"):
        _, idx = _groups(t, "group", mesh.member_groups, "member (line)")
        s = read_section(t.table("section"))
        if getattr(s, "varies", False):  # values of s would mean nothing per member
            t.fail("section", "a frame member's section must be constant (numbers only)")
        o, tw = t.get("orientation", "vec3", None), t.get("twist_deg", float, 0.0)
        t.done()
        for m in idx:
            if section[m] is not None:
                t.fail("group", f"member {name}.{m + 1} already has a section (two groups)")
            section[m], orientation[m], twist[m] = s, o, tw
            _check_orientation(t, mesh, m, o)
    missing = [m for m, s in enumerate(section) if s is None]
    if missing:
        groups = sorted({g for g, idx in mesh.member_groups.items() if set(idx) & set(missing)})
        frame.fail(
            "members",
            f"{len(missing)} member(s) of the mesh have no section (first: {name}.{missing[0] + 1}"
            f"; their groups: {groups or 'none'}); give [[frames.members]] for every line",
        )
    return section, orientation, twist


def _check_orientation(t, mesh, m, o):
    """The orientation vector must not be parallel to member ``m``."""
    if o is None:
        return
    a, b = mesh.points[mesh.members[m]]
    d = (b - a) / np.linalg.norm(b - a)
    n = np.linalg.norm(o)
    if n == 0 or np.linalg.norm(np.cross(d, np.asarray(o) / n)) < 1e-6:
        t.fail("orientation", f"{list(o)} is parallel to member {m + 1}; give a normal vector")


def _member_curve(mesh, k):
    """Member ``k``: a :class:`Line` between its nodes, or the curve through the points of a
    curved member of a ``.geo`` file (its ends at the nodes)."""
    a, b = mesh.points[mesh.members[k]]
    if not mesh.curves or mesh.curves[k] is None:
        return Line(tuple(a), tuple(b))
    xyz = np.array(mesh.curves[k])
    xyz[0], xyz[-1] = a, b
    return SampledCurve(tuple(map(tuple, xyz)))


def _node_points(mesh, point):
    """The point name of each node: ``point(k, end)`` of the first member meeting there
    (``<name>.<k>:start|end``, or the node end of its rigid arm)."""
    at = {}
    for k, (a, b) in enumerate(mesh.members):
        at.setdefault(int(a), point(k, 0))
        at.setdefault(int(b), point(k, 1))
    return at


def _sub_tables(frame, key):
    """``[[frames.<key>]]`` as Tables whose errors name the whole key path."""
    items = frame.get(key, list, [])
    return [Table(item, f"{frame.path}.{key}[{i}]", frame.file) for i, item in enumerate(items)]


def _node_tables(frame, key, mesh, at, make):
    """``make(t, points)`` of each ``[[frames.<key>]]``: the points of its node group."""
    out = []
    for t in _sub_tables(frame, key):
        group, nodes = _groups(t, "group", mesh.node_groups, "node (point)")
        lone = [int(n) for n in nodes if int(n) not in at]
        if lone:
            t.fail("group", f"nodes {lone} of group {group!r} belong to no member")
        out.append(make(t, group, [at[int(n)] for n in nodes]))
        t.done()
    return out


def _frame(frame, base, limits, read_section):
    """The :class:`FrameParts` of one ``[[frames]]`` table."""
    from ..geometry.line_mesh import read_line_mesh

    name = frame.get("name", str)
    if ":" in name or not name:
        frame.fail("name", f"{name!r} must be a non-empty name without ':'")
    path = _mesh_path(frame, base, limits)
    try:
        mesh = read_line_mesh(path)
    except ValueError as e:
        frame.fail("mesh", str(e))
    if len(mesh.members) > limits.max_beams:
        frame.fail(
            "mesh",
            f"{len(mesh.members)} members; allowed: at most {limits.max_beams} "
            "([limits] max_beams raises it)",
        )
    elements = frame.get("elements", int, 1, positive=True)
    degree = frame.get("degree", int, 2, choices=(1, 2, 3, 4))
    section, orientation, twist = _members(frame, mesh, name, read_section)
    offsets = read_offsets(frame, _sub_tables, _groups, mesh)
    beams = [
        Beam(
            f"{name}.{k + 1}",
            offset_line(frame, mesh, k, offsets) or _member_curve(mesh, k),
            section[k],
            elements,
            degree,
            orientation[k],
            twist[k],
        )
        for k, m in enumerate(mesh.members)
    ]
    point = end_points(name, offsets)
    at = _node_points(mesh, point)

    def support(t, group, points):
        return [Support(p, read_fix(t)) for p in points]

    def load(t, group, points):
        kind = t.get("kind", str, "dead", choices=LOAD_KINDS[:2])
        f, m = t.get("force", "vec3", (0.0,) * 3), t.get("moment", "vec3", (0.0,) * 3)
        return [PointLoad(p, f, m, kind) for p in points]

    def probe(t, group, points):
        prefix = t.get("name", str, group)
        return (
            {prefix: points[0]}
            if len(points) == 1
            else {f"{prefix}.{i + 1}": p for i, p in enumerate(points)}
        )

    supports = [s for part in _node_tables(frame, "supports", mesh, at, support) for s in part]
    loads = [p for part in _node_tables(frame, "loads", mesh, at, load) for p in part]
    probes = {
        k: v for part in _node_tables(frame, "probes", mesh, at, probe) for k, v in part.items()
    }
    releases = read_joints(frame, _sub_tables, _groups, mesh, name, beams, point)
    arms = rigid_arms(name, beams, mesh, offsets, degree)
    frame.done()
    return FrameParts(beams + arms, supports, loads, probes, releases)


def read_frames(top, base, limits, read_section, beams=()):
    """The beams, supports, point loads and probes of the scene's ``[[frames]]`` tables.

    Args:
        top: the scene's top-level :class:`~beamfx.scene.table.Table`.
        base: the scene file's folder (mesh files are named relative to it, inside it).
        limits: the scene's :class:`~beamfx.scene.limits.Limits` (files, beams, unknowns).
        read_section: ``read_section(table) -> Section`` of a section table.
        beams: the scene's ``[[beams]]``, whose names the members must not take.
    """
    parts = FrameParts([], [], [], {}, [])
    names = {b.name.rpartition(".")[0] for b in beams}
    for frame in top.tables("frames"):
        one = _frame(frame, base, limits, read_section)
        name = one.beams[0].name.rpartition(".")[0]
        if name in names:
            frame.fail("name", "two frames, or a frame and a beam 'name.k', share the name")
        names.add(name)
        total = [*beams, *parts.beams, *one.beams]
        if len(total) > limits.max_beams or unknowns(total) > limits.max_unknowns:
            frame.fail(
                "elements",
                f"with the other beams: {len(total)} members, about {unknowns(total):.3g} "
                f"unknowns; allowed: at most {limits.max_beams} members and "
                f"{limits.max_unknowns} unknowns ([limits] max_beams, max_unknowns)",
            )
        parts.beams.extend(one.beams)
        parts.supports.extend(one.supports)
        parts.point_loads.extend(one.point_loads)
        parts.releases.extend(one.releases)
        twice = set(parts.probes) & set(one.probes)
        if twice:
            raise SceneError(f"{frame.where('probes')}: probe names {sorted(twice)} given twice")
        parts.probes.update(one.probes)
    return parts


__all__ = ["RELEASE_ANALYSES", "FrameParts", "read_frames"]
