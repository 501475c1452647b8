"""Values at named points (mesh vertices): position, rotation, section frame, force, moment.

Each rank evaluates the named points whose vertex it owns, on one adjacent local cell, with
the section expression of the frames (:func:`~beamfx.io.fields.local_fields`: the cell's
nodes ξ = 0, 1/k, ..., 1, so one form is compiled for both; the end's values are bitwise those
of an expression at the ends alone, checked for k = 1 to 4); the answers are allgathered so
that every rank returns the same dictionary. The lookup of the points (which cell, which end,
on which rank) is made once per model and list of names and cached on the model: a transient
asks for the same probes at every step.
"""

import math
import weakref

import numpy as np

from ..physics.rotations import axis_angle, unwrap_rotation_vector
from ._sections import cell_nodes, evaluate, section_evaluator

_plans = weakref.WeakKeyDictionary()  # model -> {names: (found, cells)}
_ZERO = (0.0, 0.0, 0.0)  # the rotation before the first step


def _locate(model, name):
    """(cell, end) of the named point's vertex if this rank owns it, else None.

    Of the cells at the vertex, the one first in the input order is used (for a point inside
    a beam: the cell before it), so that serial and parallel runs report the same cell.
    """
    import dolfinx.cpp.mesh

    m = model.mesh.mesh
    tag = model.mesh.points[name][0]
    vertices = model.mesh.point_tags.find(tag)
    owned = vertices[vertices < m.topology.index_map(0).size_local]
    if len(owned) == 0:
        return None
    v = int(owned[0])
    cells = m.topology.connectivity(0, 1).links(v)
    original = np.asarray(m.topology.original_cell_index)
    c = int(cells[np.argmin(original[cells])])
    node = dolfinx.cpp.mesh.entities_to_geometry(m._mesh, 0, np.array([v], np.int32), False)[0, 0]
    ends = m.geometry.dofmap.links(c)[:2]
    if node not in ends:
        raise RuntimeError(f"vertex of point {name!r} is not an end of its cell {c}")
    return c, int(np.flatnonzero(ends == node)[0])


def _plan(model, names):
    """[(name, end)] of the named points this rank evaluates and their cells (int32), cached
    per model and tuple of names (the mesh of a model does not change)."""
    per_model = _plans.setdefault(model, {})
    key = tuple(names)
    if key not in per_model:
        model.mesh.mesh.topology.create_connectivity(0, 1)
        located = [(n, _locate(model, n)) for n in dict.fromkeys(names)]
        located = [(n, loc) for n, loc in located if loc is not None]
        cells = np.array([c for _, (c, _) in located], dtype=np.int32)
        per_model[key] = ([(n, end) for n, (_, end) in located], cells)
    return per_model[key]


def kinematics_plan(model, names, recover):
    """(rows [(name, node)], cells, compiled expression, its values' buffer, a (cells,
    points, quantities) view of it, slices of X, u and the rotation) of the named points
    this rank evaluates: cached per model, names and ``recover`` (the expression's points)."""
    per_model = _plans.get(model)
    key = ("kinematics", tuple(names), recover)
    plan = per_model.get(key) if per_model is not None else None
    if plan is None:
        found, cells = _plan(model, names)
        expr, layout, sample = section_evaluator(model, cell_nodes(model.degree), recover)
        rows = [(n, end * model.degree) for n, end in found]  # ξ = 0 or 1
        parts = tuple(layout[k] for k in ("X", "u", "rot"))
        # the values' array, made once: the compiled expression writes every entry of it
        buffer = np.zeros((len(cells), expr.X().shape[0] * expr.value_size), expr.dtype)
        values = buffer.reshape(len(rows), len(sample), expr.value_size)  # a view of it
        plan = _plans[model][key] = (rows, cells, expr, buffer, values, parts)
    return plan


def _kinematics(model, names, recover):
    """{name: :func:`_kinematic_values`} of the named points this rank evaluates: the compiled
    expression of :func:`~beamfx.io._sections.evaluate` (the same numbers) without its
    per-call set-up; what a history asks at every step. Its plan is cached per model,
    names and ``recover`` (the expression's points)."""
    rows, cells, expr, buffer, values, (X, u, rot) = kinematics_plan(model, names, recover)
    if not rows:
        return {}
    expr.eval(cells, buffer)  # into the kept array (Expression.eval's values argument)
    finite = model.kin.finite
    out = {}
    for i, (n, node) in enumerate(rows):
        v = values[i, node]
        out[n] = _kinematic_values(finite, v.tolist(), (X, u, rot), v[rot])
    return out


def _point_values(finite, v):
    """The documented dictionary of one point from the evaluated quantities ``v``."""
    X, u, rot = v["X"], v["u"], v["rot"]
    out = {"position": (X + u).tolist(), "displacement": u.tolist()}
    if finite:
        axis, angle = axis_angle(rot)
        out["quaternion"] = (rot / np.linalg.norm(rot)).tolist()
        out["rotation_vector"] = _principal(axis, angle).tolist()
    else:
        angle = float(np.linalg.norm(rot))
        axis = rot / angle if angle > 0 else np.array([1.0, 0.0, 0.0])
        out["rotation_vector"] = rot.tolist()
    out["axis"], out["angle"] = np.asarray(axis).tolist(), float(angle)
    out["section_axes"] = v["axes"].tolist()
    out["section_force"], out["section_moment"] = v["N"].tolist(), v["M"].tolist()
    return out


def _principal(axis, angle):
    """:func:`~beamfx.physics.rotations.principal_rotation_vector` from the quaternion's
    :func:`~beamfx.physics.rotations.axis_angle` found already (the same operations)."""
    if angle > np.pi:
        axis, angle = -axis, 2 * np.pi - angle
    return angle * axis


def _section_values(v):
    """``position`` and the section's ``section_axes``, ``section_force`` and
    ``section_moment`` of one point: :func:`_point_values` without the rotation's values."""
    return {
        "position": (v["X"] + v["u"]).tolist(),
        "section_axes": v["axes"].tolist(),
        "section_force": v["N"].tolist(),
        "section_moment": v["M"].tolist(),
    }


def _kinematic_values(finite, row, parts, rot):
    """``position``, ``displacement`` and the rotation (``quaternion`` of finite kinematics,
    else ``rotation_vector``) of one point: :func:`_point_values` without the rest. ``row``:
    the point's quantities as a list, ``parts`` the slices of X, u and the rotation in it,
    ``rot`` the rotation's array. In plain floats (the same IEEE sums and quotients as the
    arrays'), the norm through the array's ``dot`` (:func:`numpy.linalg.norm`'s, bitwise)."""
    X, u, r = (row[p] for p in parts)
    out = {"position": [a + b for a, b in zip(X, u)], "displacement": u}
    if finite:
        norm = math.sqrt(rot.dot(rot))
        out["quaternion"] = [c / norm for c in r]
    else:
        out["rotation_vector"] = r
    return out


def evaluate_points(model, names=None, recover=True, full=True):
    """Evaluate the solution at named points. Collective.

    Args:
        model: :class:`~beamfx.analyses.model.BeamModel` (its current ``w``).
        names: names of ``model.mesh.points`` (all of them if None).
        recover: N and M extrapolated from the cell's Gauss points (default) rather than
            taken pointwise at the vertex, see :func:`beamfx.io._sections.evaluate`.
        full: all the values below; if False only ``position``, ``displacement`` and the
            ``quaternion`` (finite kinematics) or ``rotation_vector`` (linear), the same
            numbers, for a history that records them at every step; if ``"sections"`` only
            ``position``, ``section_axes``, ``section_force`` and ``section_moment`` (the
            condensed model's reactions at every step).

    Returns:
        ``{name: values}`` on every rank, where ``values`` holds plain lists and floats:
        ``position`` x = X + u and ``displacement`` u (global axes); ``rotation_vector``, the
        principal one (|θ| ≤ π) for finite rotations, θ itself for linear kinematics (global
        axes); ``axis`` and ``angle`` (angle in [0, 2π], the angle the quaternion encodes);
        ``quaternion`` (unit, finite kinematics only); ``section_axes``, the 3×3 matrix R·Λ0
        whose columns are the current section axes (t, e2, e3) in global axes;
        ``section_force`` N = C_N Γ and ``section_moment`` M = C_M K (section axes, Simo 1985
        eq. 2.12) from one adjacent cell, the first in input order (N and M jump at a point
        load; only that side is reported).

    Raises:
        ValueError: if a name is not a named point of the model.
    """
    comm, finite = model.comm, model.kin.finite
    names = list(model.mesh.points) if names is None else list(names)
    unknown = [n for n in names if n not in model.mesh.points]
    if unknown:
        raise ValueError(f"no named points {unknown}; the model has {sorted(model.mesh.points)}")
    model.sync()  # derived fields (the condensed model integrates its displacement)
    if full:
        found, cells = _plan(model, names)
        values = evaluate(model, cell_nodes(model.degree), cells, recover)
        local = {}
        for i, (n, end) in enumerate(found):
            node = end * model.degree  # ξ = 0 or 1
            v = {k: a[i, node] for k, a in values.items()}
            local[n] = _section_values(v) if full == "sections" else _point_values(finite, v)
    else:
        local = _kinematics(model, names, recover)

    if comm.size == 1:
        result = local
    else:
        result = {}
        for part in comm.allgather(local):
            for n, v in part.items():
                result.setdefault(n, v)
    missing = [n for n in names if n not in result]
    if missing:  # every rank sees the same gathered result, so all raise together
        raise RuntimeError(f"named points {missing} were found on no rank")
    return {n: result[n] for n in names}


def track_rotations(previous, current):
    """Add ``rotation_vector_unwrapped`` and ``angle_unwrapped`` to ``current``, in place.

    Follows each point's rotation along a load or time path: of the rotation vectors
    equivalent to the current quaternion ((φ + 2πk) n, k integer), the one closest to the
    previous unwrapped value is kept (:func:`~beamfx.physics.rotations.unwrap_rotation_vector`), so a roll-up to two turns reports an
    angle of 4π. The path must be sampled finely enough that a point turns by less than π
    between calls.

    Args:
        previous: an earlier result of :func:`evaluate_points` (already tracked), or None or
            ``{}`` for the first step (the path then starts from the undeformed state, θ = 0).
        current: the new result of :func:`evaluate_points`.

    Returns:
        ``current``.
    """
    previous = previous or {}
    for name, v in current.items():
        before = previous.get(name, {})
        prev = before.get("rotation_vector_unwrapped")
        if prev is None:
            prev = before.get("rotation_vector", _ZERO)
        if "quaternion" in v:
            theta = unwrap_rotation_vector(v["quaternion"], prev)
        else:  # linear kinematics: θ is already the field
            theta = np.asarray(v["rotation_vector"], float)
        v["rotation_vector_unwrapped"] = theta.tolist()
        v["angle_unwrapped"] = math.sqrt(theta.dot(theta))  # = np.linalg.norm, bitwise
    return current


__all__ = ["evaluate_points", "track_rotations"]
