"""``[[frames.joints]]``: joints of a frame that are not rigid (pinned, or with released
rotation components in the joint's axes), as :class:`~beamfx.spec.Release` of member ends.

At each node of the group the ends of the members meeting there are released, except the
first member in file order (its end carries the node's rotation), unless ``members`` names
the member group whose ends are released (all of them, then: a node whose every member end
is released has a free rotation, which the mechanism check reports)::

    [[frames.joints]]
    group = "knees"            # a node group
    type = "pinned"            # "rigid" (the default joint), "pinned": rx, ry, rz released
    [[frames.joints]]
    group = "eaves"
    releases = ["rz"]          # instead of type: the released components
    axes = "member"            # "global" (default), "member" (each member end's section
                               # axes: x along the member), or { x = [...], y = [...] }
    members = "rafters"        # optional: release only these members' ends

``[[frames.offsets]]``: eccentric connections. The ends of a member group sit at ``offset``
(global axes) from their nodes, joined to them by rigid arms (stiff massless beams, so
rigid at any rotation up to a compliance 1e-6 of the member's); a release at such an end
acts at the node, between the arm and the node. Why stiff beams and not an exact tie: the
member's end and the node are two mesh vertices, and a UFL form cannot couple two vertices
(DOLFINx 0.5.2 has no multipoint constraints); a stiff geometrically exact beam is rigid at
any rotation, needs no other code, and works in every analysis::

    [[frames.offsets]]
    group = "beams"
    end = "both"               # "start", "end" or "both" (default)
    offset = [0, 0, 0.2]       # from the node to the member's end
"""

import numpy as np

from ..geometry.curves import Line
from ..geometry.frames import frame_from_tangent
from ..physics.sections import Section
from ..spec import Beam, Release

RELEASES = ("rx", "ry", "rz")
JOINT_TYPES = ("rigid", "pinned")
ENDS = ("start", "end")
#: a rigid arm's stiffnesses over its member's largest (its compliance is 1e-6 of theirs)
ARM_STIFFNESS = 1e6
#: the longest offset, in lengths of its member (a longer rigid arm is surely a mistake)
MAX_OFFSET = 10.0


def _released(t):
    """The released components of a joint table: ``type`` or ``releases``."""
    if "releases" in t.data:
        if "type" in t.data:
            t.fail("type", "give either type or releases, not both")
        rel = t.get("releases", list)
        bad = [r for r in rel if not isinstance(r, str) or r not in RELEASES]
        if bad or not rel or len(set(rel)) != len(rel):
            t.fail("releases", f"{rel}: give distinct components of {list(RELEASES)}")
        return tuple(r for r in RELEASES if r in rel)
    kind = t.get("type", str, choices=JOINT_TYPES)
    return RELEASES if kind == "pinned" else ()


def _explicit_axes(t):
    """Rows x, y, z of ``axes = { x = [...], y = [...] }`` (y made normal to x)."""
    table = t.table("axes")
    x, y = np.array(table.get("x", "vec3")), np.array(table.get("y", "vec3"))
    table.done()
    scale = np.abs(np.r_[x, y]).max()
    if not 0 < scale < 1e300 or np.abs(x).max() == 0:
        table.fail("x", f"{list(x)}: give a non-zero axis of moderate size (with y)")
    x, y = x / scale, y / scale  # no overflow in the norms below
    x = x / np.linalg.norm(x)
    size = np.linalg.norm(y)
    y = y - np.dot(y, x) * x
    if np.linalg.norm(y) <= 1e-9 * size or size == 0:
        table.fail("y", f"is zero or parallel to {table.path}.x; give a direction normal to x")
    y = y / np.linalg.norm(y)
    return (tuple(x), tuple(y), tuple(np.cross(x, y)))


def _axes(t):
    """``axes``: "global", "member" (None: per member end) or explicit rows."""
    value = t.data.get("axes", "global")
    if isinstance(value, dict):
        return _explicit_axes(t)
    kind = t.get("axes", str, "global", choices=("global", "member"))
    return np.eye(3) if kind == "global" else None


def _member_axes(beam, end):
    """Rows of the section axes of ``beam`` at its end 0 (start) or 1 (end)."""
    L = beam.curve.length
    s = [0.0, 1e-6 * L] if end == 0 else [L - 1e-6 * L, L]
    a, b = beam.curve.points(s)
    return frame_from_tangent((b - a) / np.linalg.norm(b - a), beam.orientation, beam.twist_deg).T


def _ends_at(mesh, node):
    """(member, end 0|1) of the member ends at ``node``, members in file order."""
    return [(k, e) for k, m in enumerate(mesh.members) for e in (0, 1) if int(m[e]) == node]


def read_offsets(frame, sub_tables, groups, mesh):
    """{(member, end 0|1): offset (3,)} of the ``[[frames.offsets]]`` of one frame: the vector
    from the node to the member's end (global axes), bridged by a rigid arm."""
    out = {}
    for t in sub_tables(frame, "offsets"):
        group, members = groups(t, "group", mesh.member_groups, "member (line)")
        end = t.get("end", str, "both", choices=(*ENDS, "both"))
        offset = np.array(t.get("offset", "vec3"))
        t.done()
        if not np.any(offset):
            continue
        for k in (int(x) for x in members):
            if mesh.curves and mesh.curves[k] is not None:
                t.fail("group", f"member {k + 1} of {group!r} is curved: offsets need lines")
            length = np.linalg.norm(np.diff(mesh.points[mesh.members[k]], axis=0))
            if np.linalg.norm(offset) > MAX_OFFSET * length:
                t.fail(
                    "offset",
                    f"{list(offset)} is longer than {MAX_OFFSET:g} times member {k + 1} "
                    f"({length:.3g} long)",
                )
            for e in (0, 1) if end == "both" else (ENDS.index(end),):
                if (k, e) in out:
                    t.fail("group", f"member {k + 1} of {group!r} has two offsets at its {ENDS[e]}")
                out[(k, e)] = offset
    return out


def end_points(name, offsets):
    """``point(k, e)``: the point name of member k's end e at its node: the member's end, or
    the node end of its rigid arm (``<name>.<k>.arm_<end>:start``)."""

    def point(k, e):
        if (k, e) in offsets:
            return f"{name}.{k + 1}.arm_{ENDS[e]}:start"
        return f"{name}.{k + 1}:{ENDS[e]}"

    return point


def offset_line(t, mesh, k, offsets):
    """The straight member k between its offset ends (None if it has no offset)."""
    if not any((k, e) in offsets for e in (0, 1)):
        return None
    a, b = (mesh.points[mesh.members[k][e]] + offsets.get((k, e), 0.0) for e in (0, 1))
    if np.linalg.norm(b - a) <= 1e-9 * max(np.linalg.norm(mesh.points[mesh.members[k]]), 1.0):
        t.fail("offsets", f"member {k + 1}'s offsets bring its ends together")
    return Line(tuple(a), tuple(b))


def rigid_arms(name, beams, mesh, offsets, degree):
    """The rigid arms of the offset member ends: beams ``<name>.<k>.arm_<end>`` from the node
    to the member's end, one element, massless, isotropic, :data:`ARM_STIFFNESS` times
    stiffer than their member (a stiff Simo–Reissner beam: rigid in the limit, at any
    rotation)."""
    arms = []
    for (k, e), offset in sorted(offsets.items(), key=lambda x: x[0]):
        node = mesh.points[mesh.members[k][e]]
        C = beams[k].section.stiffnesses()
        f, m = ARM_STIFFNESS * C[:3].max(), ARM_STIFFNESS * C[3:].max()
        section = Section(f, f, f, m, m, m)
        line = Line(tuple(node), tuple(node + offset))
        arms.append(Beam(f"{name}.{k + 1}.arm_{ENDS[e]}", line, section, 1, degree))
    return arms


def read_joints(frame, sub_tables, groups, mesh, name, beams, point=None):
    """The :class:`~beamfx.spec.Release` of the ``[[frames.joints]]`` of one frame.

    Args:
        frame: the ``[[frames]]`` Table.
        sub_tables: ``sub_tables(frame, key)``, its sub-tables.
        groups: ``groups(t, key, mesh_groups, kind) -> (name, indices)`` (a missing group fails).
        mesh: the frame's :class:`~beamfx.geometry.line_mesh.LineMesh`.
        name: the frame's name.
        beams: its members (``name.k``), in file order.
        point: ``point(k, end)``, the point name of a member end at its node
            (:func:`end_points`); default: the member's end.
    """
    point = point or end_points(name, {})
    out, seen = [], {}
    for t in sub_tables(frame, "joints"):
        group, nodes = groups(t, "group", mesh.node_groups, "node (point)")
        released, axes = _released(t), _axes(t)
        only = None
        if "members" in t.data:
            only = set(groups(t, "members", mesh.member_groups, "member (line)")[1].tolist())
        t.done()
        for n in (int(x) for x in nodes):
            ends = _ends_at(mesh, n)
            if not ends:
                t.fail("group", f"node {n + 1} of group {group!r} belongs to no member")
            chosen = [e for e in ends if e[0] in only] if only is not None else ends[1:]
            for k, end in chosen:
                if (k, end) in seen:
                    t.fail("group", f"member {name}.{k + 1} at node {n + 1} is in {seen[(k, end)]}")
                seen[(k, end)] = f"group {group!r}"
                if not released:
                    continue
                rows = _member_axes(beams[k], end) if axes is None else axes
                out.append(
                    Release(
                        point(k, end),
                        released,
                        tuple(tuple(float(v) for v in r) for r in rows),
                        f"{name} node {n + 1} (group {group!r})",
                    )
                )
    return out


__all__ = [
    "ARM_STIFFNESS",
    "JOINT_TYPES",
    "RELEASES",
    "end_points",
    "offset_line",
    "read_joints",
    "read_offsets",
    "rigid_arms",
]
