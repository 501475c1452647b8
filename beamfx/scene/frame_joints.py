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
"""

import numpy as np

from ..geometry.frames import frame_from_tangent
from ..spec import Release

RELEASES = ("rx", "ry", "rz")
JOINT_TYPES = ("rigid", "pinned")


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


def read_joints(frame, sub_tables, groups, mesh, name, beams):
    """The :class:`~beamfx.spec.Release` of the ``[[frames.joints]]`` of one frame.

    Args:
        frame: the ``[[frames]]`` Table.
        sub_tables: ``sub_tables(frame, key)``, its sub-tables.
        groups: ``groups(t, key, mesh_groups, kind) -> (name, indices)`` (a missing group fails).
        mesh: the frame's :class:`~beamfx.geometry.line_mesh.LineMesh`.
        name: the frame's name.
        beams: its members (``name.k``), in file order.
    """
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
                        f"{name}.{k + 1}:{('start', 'end')[end]}",
                        released,
                        tuple(tuple(float(v) for v in r) for r in rows),
                        f"{name} node {n + 1} (group {group!r})",
                    )
                )
    return out


__all__ = ["JOINT_TYPES", "RELEASES", "read_joints"]
