"""``curve = { shape = ... }`` of a ``[[beams]]`` table: the centre line, checked key by key.

A degenerate curve is blamed on the key that makes it so (a tangent parallel to the radius, a
helix axis along its start direction, two equal spline points), not on the first point that
later falls on it; a curve that runs over itself (an arc beyond 360°, a helix of pitch 0 beyond
one turn) is refused here, before the mesh would merge its vertices into a broken topology.
"""

import numpy as np

from ..geometry import curves
from .files import named_file
from .table import is_number

SHAPES = ("line", "arc", "helix", "polyline", "spline", "gmsh")
GMSH_SUFFIXES = (".geo", ".msh")


def _normal_part(t, key, v, axis, axis_key):
    """``v`` minus its component along the unit ``axis``; fails if nothing is left."""
    n = np.asarray(v) - (np.asarray(v) @ axis) * axis
    if not np.linalg.norm(n) > 1e-12 * np.linalg.norm(v):
        t.fail(key, f"{list(v)} is parallel to {axis_key} (or zero); give a vector normal to it")
    return n


def _line(t):
    start = t.get("start", "vec3")
    if t.has("end"):
        end = t.get("end", "vec3")
        if end == start:
            t.fail("end", "equals start: a line of zero length")
        return curves.Line(start, end)
    d, L = t.get("direction", "vec3"), t.get("length", float, positive=True)
    n = float(np.linalg.norm(d))
    if not n > 0:
        t.fail("direction", "must not be zero")
    end = tuple(s + L * x / n for s, x in zip(start, d))
    return curves.Line(start, end)


def _arc(t):
    start, tangent = t.get("start", "vec3"), t.get("start_tangent", "vec3")
    centre, angle = t.get("centre", "vec3"), t.get("angle_deg", float, positive=True)
    radius = np.subtract(start, centre)
    if not np.linalg.norm(radius) > 0:
        t.fail("centre", "must differ from start (zero radius)")
    _normal_part(t, "start_tangent", tangent, radius / np.linalg.norm(radius), "centre - start")
    if angle > 360:
        t.fail("angle_deg", f"= {angle:g}: allowed: (0, 360]; a longer arc runs over itself")
    return curves.Arc(start, tangent, centre, angle)


def _helix(t):
    axis = np.asarray(t.get("axis", "vec3"))
    if not np.linalg.norm(axis) > 0:
        t.fail("axis", "must not be zero")
    radius, pitch = t.get("radius", float, positive=True), t.get("pitch", float)
    turns = t.get("turns", float, positive=True)
    start_direction = t.get("start_direction", "vec3", (1.0, 0.0, 0.0))
    _normal_part(t, "start_direction", start_direction, axis / np.linalg.norm(axis), "axis")
    if pitch == 0 and turns > 1:
        t.fail("turns", f"= {turns:g}: a helix of pitch 0 runs over itself beyond one turn")
    centre = t.get("centre", "vec3")
    return curves.Helix(centre, tuple(axis), radius, pitch, turns, start_direction)


def _through(t, shape):
    pts = t.get("points", list)
    ok = all(isinstance(p, list) and len(p) == 3 for p in pts)
    if len(pts) < 2 or not ok:
        t.fail("points", "expected a list of at least two [x, y, z] points")
    pts = tuple(_points(t, pts))
    steps = np.linalg.norm(np.diff(np.asarray(pts), axis=0), axis=1)
    if shape == "spline" and not np.all(steps > 0):
        i = int(np.argmin(steps))
        t.fail("points", f"points {i} and {i + 1} are equal; a spline needs distinct neighbours")
    if shape == "polyline":
        return curves.Polyline(pts)
    try:
        return curves.SampledCurve(pts)
    except ValueError as e:
        t.fail("points", f"no spline through these points: {e}")


def _points(t, pts):
    """The points of ``points`` as float triples, each number finite."""
    for i, p in enumerate(pts):
        if not all(map(is_number, p)):
            t.fail(f"points[{i}]", f"expected 3 finite numbers, got {p!r}"[:120])
    return [tuple(float(x) for x in p) for p in pts]


_GMSH_CACHE = {}  # (path, mtime, size, curve_tag) -> curve: a sweep reads its file once
_GMSH_CACHE_SIZE = 32


def _gmsh(t, base, limits):
    name = t.get("file", str)
    path = named_file(
        base, name, limits, lambda message: t.fail("file", message), suffixes=GMSH_SUFFIXES
    )
    tag = t.get("curve_tag", int, None)
    info = path.stat()
    key = (str(path), info.st_mtime_ns, info.st_size, tag)
    if key not in _GMSH_CACHE:
        try:
            curve = curves.curve_from_gmsh(path, tag)
        except (ValueError, UnicodeDecodeError) as e:
            t.fail("file", str(e))
        if len(_GMSH_CACHE) >= _GMSH_CACHE_SIZE:
            _GMSH_CACHE.pop(next(iter(_GMSH_CACHE)))
        _GMSH_CACHE[key] = curve
    return _GMSH_CACHE[key]


def read_curve(t, base, limits):
    """The curve of the ``curve`` table ``t`` (:class:`~.table.Table`)."""
    shape = t.get("shape", str, choices=SHAPES)
    if shape == "line":
        c = _line(t)
    elif shape == "arc":
        c = _arc(t)
    elif shape == "helix":
        c = _helix(t)
    elif shape in ("polyline", "spline"):
        c = _through(t, shape)
    else:
        c = _gmsh(t, base, limits)
    t.done()
    length = c.length
    if not np.isfinite(length):
        t.fail("shape", f"a {shape} of length {length}: its size must be finite")
    if not length > 0:
        t.fail("shape", f"a {shape} of zero length")
    return c


def overlap(beams):
    """Why the beams' element vertices fall on each other (a curve over itself), or None.

    A closed curve (end on start) and beams meeting at a point are joints; two elements on the
    same two vertices, or an element whose ends coincide, would break the mesh (an arc of 720°
    aborted the process in DOLFINx's mesh creation).
    """
    from ..geometry.mesh import BeamSpec, overlapping_cells

    return overlapping_cells([BeamSpec(b.name, b.curve, b.elements) for b in beams])


__all__ = ["SHAPES", "overlap", "read_curve"]
