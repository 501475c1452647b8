"""The supports, loads, springs and point masses of a scene (``[[supports]]``, ``[[loads]]``,
``[[springs]]``, ``[[masses]]``): every vector finite, every history a bounded function of time."""

from functools import partial

import numpy as np

from ..spec import (
    AXES,
    DOF_NAMES,
    LOAD_KINDS,
    DistributedLoad,
    PointLoad,
    PointMass,
    Spring,
    Support,
)
from .expr import compile_expression, table_function
from .sections import span_function
from .table import Table, is_number

FIX_WORDS = {"all": DOF_NAMES, "clamped": DOF_NAMES, "pinned": DOF_NAMES[:3]}


def _constant(value):
    """The vectorised function of one variable that is ``value`` everywhere (``text`` says it)."""
    f = partial(np.full_like, fill_value=value, dtype=float)
    f.text = str(value)
    return f


def _history(t, key="history"):
    """A function of time: a number, an expression of ``t`` or a table
    ``{ t = [...], values = [...] }`` (piecewise linear, constant beyond its ends); None if
    the key is absent."""
    if not t.has(key):
        return None
    raw = t.data.get(key)
    t.used.add(key)
    try:
        if isinstance(raw, bool):
            raise TypeError(f"{raw!r} is not a number")
        if isinstance(raw, (int, float)):
            f = _constant(float(raw))
        elif isinstance(raw, str):
            f = compile_expression(raw, "t")
        elif isinstance(raw, dict):
            sub = Table(raw, t.path + "." + key, t.file)
            f = table_function(sub.get("t", list), sub.get("values", list))
            sub.done()
        else:
            raise TypeError(f"{raw!r} is not a number, expression or table")
        values = f(np.linspace(0.0, 1.0, 11))
        if not np.all(np.isfinite(values)):
            raise ValueError("it is not finite on [0, 1]")
    except (ValueError, TypeError, ZeroDivisionError, FloatingPointError, OverflowError) as e:
        t.fail(key, f"{e} (write a number, an expression of t, or {{ t = [...], values = [...] }})")
    return f


def _arm(t, kind, moment_key):
    """The arm of a quasitangential moment (required for that kind, refused for the others)."""
    if kind != "quasitangential":
        if t.has("arm"):
            t.fail("arm", f"only a kind = 'quasitangential' moment has an arm, not {kind!r}")
        return None
    arm = np.asarray(t.get("arm", "vec3"))
    moment = np.asarray(t.get(moment_key, "vec3", (0.0,) * 3))
    norm = np.linalg.norm(arm)
    if norm == 0 or abs(arm @ moment) > 1e-9 * norm * np.linalg.norm(moment):
        t.fail("arm", f"must be a non-zero vector normal to '{moment_key}', got {list(arm)}")
    return tuple(arm)


def _point_mass(t):
    """A ``[[masses]]`` table: ``at``, ``mass`` and ``inertia`` ([Jxx, Jyy, Jzz] or 3x3)."""
    at = t.get("at", str)
    mass = t.get("mass", float, 0.0)
    if mass < 0:
        t.fail("mass", f"must not be negative, got {mass}")
    J = np.zeros((3, 3))
    if t.has("inertia"):
        raw = t.get("inertia", list)

        def numbers(row):
            return isinstance(row, list) and len(row) == 3 and all(map(is_number, row))

        if numbers(raw):
            J = np.diag(np.array(raw, float))
        elif len(raw) == 3 and all(numbers(row) for row in raw):
            J = np.array(raw, float)
        else:
            t.fail(
                "inertia", f"expected [Jxx, Jyy, Jzz] or a 3x3 list of finite numbers, got {raw!r}"
            )
        scale = np.abs(J).max()
        if np.abs(J - J.T).max() > 1e-12 * scale:
            t.fail("inertia", "must be symmetric")
        smallest = np.linalg.eigvalsh(J).min()
        if smallest < -1e-12 * scale:
            t.fail(
                "inertia",
                f"must be positive semi-definite; its smallest eigenvalue is {smallest:g}",
            )
    if mass == 0 and not J.any():
        t.fail("mass", "give a positive 'mass' and/or a non-zero 'inertia'")
    return PointMass(at, mass, tuple(tuple(float(x) for x in row) for row in J))


def _fix(t):
    allowed = f"allowed: {list(FIX_WORDS)} or a list of {list(DOF_NAMES)}"
    if t.has("fix") and not isinstance(t.data["fix"], (str, list)):
        t.fail("fix", f"{t.data['fix']!r} is not allowed; {allowed}")
    fix = t.get("fix", (str, list))
    if isinstance(fix, str):
        if fix not in FIX_WORDS:
            t.fail("fix", f"{fix!r} is not allowed; {allowed}")
        return tuple(FIX_WORDS[fix])
    bad = [d for d in fix if d not in DOF_NAMES]
    if bad or not fix:
        t.fail("fix", f"{bad or fix} not allowed; allowed: a list of {list(DOF_NAMES)}")
    return tuple(fix)


read_fix = _fix  # ``fix`` of a table: also [[frames.supports]] (beamfx.scene.frames)


def _check_support_histories(t, sup):
    """``displacement_history`` / ``rotation_history``: each scales a prescribed value of its
    own, in global axes, and not together with ``history`` (which would then scale nothing or
    be ambiguous)."""
    for key, values in (
        ("displacement_history", sup.displacement),
        ("rotation_history", sup.rotation),
    ):
        if getattr(sup, key) is None:
            continue
        part = key.split("_")[0]
        if not any(values):
            t.fail(key, f"there is no prescribed {part} to scale: give a non-zero '{part}'")
        if sup.history is not None:
            t.fail(key, "give either 'history' (both parts) or the per-part histories, not both")
        if sup.axes == "local":
            t.fail(key, "per-part histories need axes = 'global'")


def read_supports(top):
    """``[[supports]]``: fixed dofs, prescribed motion."""
    supports = []
    for t in top.tables("supports"):
        sup = Support(
            t.get("at", str),
            _fix(t),
            t.get("displacement", "vec3", (0.0,) * 3),
            t.get("rotation", "vec3", (0.0,) * 3),
            t.get("axes", str, "global", choices=AXES),
            _history(t),
            _history(t, "displacement_history"),
            _history(t, "rotation_history"),
        )
        _check_support_histories(t, sup)
        free = [
            DOF_NAMES[i] for i in range(3) if sup.displacement[i] and DOF_NAMES[i] not in sup.fix
        ]
        if free:
            t.fail(
                "displacement", f"prescribed on {free}, which 'fix' leaves free; add them to fix"
            )
        if any(sup.rotation) and not {"rx", "ry", "rz"} <= set(sup.fix):
            t.fail("rotation", "a prescribed rotation needs rx, ry and rz in fix")
        supports.append(sup)
        t.done()
    return supports


def _profile(t, lengths):
    """``profile`` of a distributed load: its force and moment per length times a function of
    the arc length along its beam (``beam`` is required: s and L are that beam's); None if
    absent."""
    if not t.has("profile"):
        return None
    beam = t.data.get("beam")
    if beam is None:
        t.fail("profile", "a profile runs along one beam: give 'beam' too")
    if beam not in lengths:
        t.fail("beam", f"{beam!r} is no beam; beams are {list(lengths)}")
    f = span_function(t, "profile", lengths[beam])
    return f if callable(f) else _constant(f)


def read_loads(top, lengths):
    """``[[loads]]``: point loads, distributed loads and gravity; ``lengths``: {beam: length}."""
    point_loads, distributed, gravity, gravity_at = [], [], (0.0, 0.0, 0.0), None
    for t in top.tables("loads"):
        if t.has("gravity"):
            if gravity_at is not None:
                t.fail("gravity", f"given twice (also in {gravity_at}); allowed: one per scene")
            gravity, gravity_at = t.get("gravity", "vec3"), t.path
            t.done()
            continue
        kind = t.get("kind", str, "dead", choices=LOAD_KINDS)
        if t.has("at"):
            point_loads.append(
                PointLoad(
                    t.get("at", str),
                    t.get("force", "vec3", (0.0,) * 3),
                    t.get("moment", "vec3", (0.0,) * 3),
                    kind,
                    _history(t),
                    arm=_arm(t, kind, "moment"),
                )
            )
        else:
            axes = t.get("axes", str, "global", choices=("global", "section"))
            if axes == "section" and kind == "quasitangential":
                t.fail("axes", "a quasitangential moment's arm is global: give axes = 'global'")
            distributed.append(
                DistributedLoad(
                    t.get("beam", str, None),
                    t.get("force_per_length", "vec3", (0.0,) * 3),
                    t.get("moment_per_length", "vec3", (0.0,) * 3),
                    kind,
                    _history(t),
                    arm=_arm(t, kind, "moment_per_length"),
                    axes=axes,
                    profile=_profile(t, lengths),
                )
            )
        t.done(
            " (a point load has 'at'; a distributed one 'beam' or neither for all beams; or 'gravity')"
        )
    return point_loads, distributed, gravity


def read_springs(top):
    """``[[springs]]``: springs to ground."""
    springs = []
    for t in top.tables("springs"):
        sp = Spring(
            t.get("at", str),
            t.get("stiffness", "vec3", (0.0,) * 3),
            t.get("rotational", "vec3", (0.0,) * 3),
        )
        for key in ("stiffness", "rotational"):
            if min(getattr(sp, key)) < 0:
                t.fail(key, f"= {list(getattr(sp, key))}: each must be >= 0")
        if not any((*sp.stiffness, *sp.rotational)):
            t.fail("stiffness", "give non-negative 'stiffness' and/or 'rotational', not all zero")
        springs.append(sp)
        t.done()
    return springs


def read_masses(top):
    """``[[masses]]``: rigid bodies attached at points."""
    masses = []
    for t in top.tables("masses"):
        masses.append(_point_mass(t))
        t.done()
    return masses


__all__ = ["FIX_WORDS", "read_fix", "read_loads", "read_masses", "read_springs", "read_supports"]
