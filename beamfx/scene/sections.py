"""Scene keys of matrix (6×6) sections and of section offsets (docs/scenes.md, "Matrix sections").

``section = { type = "matrix", stiffness = [[...] × 6], mass = [[...] × 6] }``, optionally
``stations = [s/L, ...]`` with one matrix per station, and ``convention = "beamfx"`` (default)
or ``"beamdyn"``; and the offset keys ``elastic_centre``, ``shear_centre`` and ``mass_centre``
(``[y, z]`` in section axes) of a prismatic geometric or general section, which turn it into a
matrix section (:mod:`beamfx.physics.matrix_sections`); ``type = "shape"`` (a built-in shape
of sectionproperties) and ``type = "polygon"`` (``points``, ``holes``), analysed by
:mod:`beamfx.physics.shape_sections` into a matrix section.
"""

from numbers import Real
from pathlib import Path

import numpy as np

from ..physics import matrix_sections as ms
from ..physics import shape_sections as ss

OFFSET_KEYS = ("elastic_centre", "shear_centre", "mass_centre")
CONVENTIONS = ("beamfx", "beamdyn")


def _is_matrix(x):
    return (
        isinstance(x, list)
        and len(x) == 6
        and all(
            isinstance(r, list)
            and len(r) == 6
            and all(isinstance(v, Real) and not isinstance(v, bool) for v in r)
            for r in x
        )
    )


def _matrices(t, key, n, convention, required=True):
    """``n`` 6×6 matrices of ``key`` (one, or a list of one per station), beamfx order."""
    if not t.has(key) and not required:
        t.get(key, list, None)
        return np.zeros((n, 6, 6))
    raw = t.get(key, list)
    if _is_matrix(raw):
        raw = [raw]
    if not all(_is_matrix(x) for x in raw):
        t.fail(key, "expected a 6×6 list of numbers (rows of 6), or a list of them per station")
    if len(raw) != n:
        t.fail(key, f"{len(raw)} matrices for {n} station(s): give one per station")
    A = np.array(raw, float)
    if convention == "beamdyn":
        A = np.array([ms.from_beamdyn(x) for x in A])
    return A


def _stations(t):
    """The stations s/L (increasing from 0 to 1), or (0,) if the key is absent."""
    if not t.has("stations"):
        t.get("stations", list, None)
        return (0.0,)
    st = t.get("stations", list)
    if not all(isinstance(v, Real) and not isinstance(v, bool) for v in st):
        t.fail("stations", f"expected a list of numbers (s/L), got {st!r}")
    x = np.asarray(st, float)
    if len(x) < 2:
        t.fail("stations", f"a table needs at least two stations, got {len(x)}")
    if np.any(np.diff(x) <= 0):
        i = int(np.argmax(np.diff(x) <= 0))
        t.fail("stations", f"must increase: station {i + 2} ({x[i + 1]:g}) follows {x[i]:g}")
    if x[0] != 0.0 or x[-1] != 1.0:
        t.fail("stations", f"must run from 0 to 1 (s/L), got {x[0]:g} to {x[-1]:g}")
    return tuple(float(v) for v in x)


def _checked(t, key, matrices, stations, check, what=""):
    for k, A in enumerate(matrices):
        try:
            check(A)
        except ValueError as e:
            where = (
                f"station {k + 1} (s/L = {stations[k]:g})" if len(stations) > 1 else "the matrix"
            )
            t.fail(key, f"{what}{where} {e}")
        matrices[k] = 0.5 * (A + A.T)
    return matrices


def matrix_section(t, length):
    """The :class:`~beamfx.physics.matrix_sections.MatrixSection` of a ``type = "matrix"``
    section table ``t`` (a :class:`~beamfx.scene.table.Table`) on a beam of ``length``."""
    convention = t.get("convention", str, "beamfx", choices=CONVENTIONS)
    stations = _stations(t)
    n = len(stations)
    C = _checked(
        t, "stiffness", _matrices(t, "stiffness", n, convention), stations, ms.check_stiffness
    )
    M = _checked(t, "mass", _matrices(t, "mass", n, convention, False), stations, ms.check_mass)
    vertices = t.get("vertices_at_stations", bool, False)
    t.done()
    return ms.MatrixSection(C, M, stations, length, vertices)


def _pair(t, key):
    value = t.get(key, list, None)
    if value is None:
        return None
    ok = len(value) == 2 and all(isinstance(v, Real) and not isinstance(v, bool) for v in value)
    if not ok or not np.all(np.isfinite(np.asarray(value, float))):
        t.fail(key, f"expected [y, z] (two finite numbers, section axes), got {value!r}")
    return tuple(float(v) for v in value)


def offsets(t):
    """The offset keys of a section table: {key: (y, z)} of those given (none: {})."""
    found = {k: _pair(t, k) for k in OFFSET_KEYS}
    return {k: v for k, v in found.items() if v is not None}


def with_offsets(t, section, given, length):
    """``section`` (a prismatic ``Section``) with the offsets ``given`` (:func:`offsets`) as a
    matrix section: stiffness by :func:`~beamfx.physics.matrix_sections.offset_stiffness`,
    mass by :func:`~beamfx.physics.matrix_sections.offset_mass` (the section's ρI taken about
    the mass centre)."""
    if section.varies:
        t.fail(next(iter(given)), "offsets need a prismatic section; give a varying one as a "
               "type = 'matrix' table with stations")  # fmt: skip
    s = section
    C = ms.offset_stiffness(
        s.EA, s.GA_y, s.GA_z, s.GJ, s.EI_y, s.EI_z,
        given.get("elastic_centre", (0.0, 0.0)), given.get("shear_centre", (0.0, 0.0)),
    )  # fmt: skip
    M = ms.offset_mass(s.rho_A, s.rho_I, given.get("mass_centre", (0.0, 0.0)))
    return ms.MatrixSection(C, M, (0.0,), length)


def beamdyn_section(t, length, base):
    """The matrix section of a ``type = "beamdyn"`` table: ``file``, a BeamDyn blade (or
    primary) file, relative to the scene's folder (:mod:`beamfx.scene.beamdyn`)."""
    from .beamdyn import read_blade

    path = Path(base) / t.get("file", str)
    vertices = t.get("vertices_at_stations", bool, False)
    t.done()
    try:
        eta, K, M = read_blade(path)
    except ValueError as e:
        t.fail("file", str(e))
    what = f"{path}: "
    if len(eta) < 2 or np.any(np.diff(eta) <= 0) or eta[0] != 0.0 or eta[-1] != 1.0:
        t.fail("file", f"{what}the stations must increase from 0 to 1, got {list(eta)}")
    stations = tuple(float(x) for x in eta)
    C = np.array([ms.from_beamdyn(k) for k in K])
    Mb = np.array([ms.from_beamdyn(m) for m in M])
    C = _checked(t, "file", C, stations, ms.check_stiffness, what + "stiffness at ")
    Mb = _checked(t, "file", Mb, stations, ms.check_mass, what + "mass at ")
    return ms.MatrixSection(C, Mb, stations, length, vertices)


def span_function(t, key, length, default=0.0):
    """A value along a beam of ``length`` from key ``key`` of table ``t``: a number, an
    expression of the arc length ``s`` (and ``L``) or a table ``{ s = [...], values = [...] }``
    (piecewise linear in s), finite along the beam (negative values allowed). A number is
    returned as a float, the others as a vectorised function of s."""
    from .expr import compile_expression, table_function
    from .table import MAX_MAGNITUDE, Table

    raw = t.data.get(key, default)
    if not isinstance(raw, (str, dict)):
        value = t.get(key, float, default)
        if not abs(value) <= MAX_MAGNITUDE:
            t.fail(key, f"= {value:g}: must be a finite number")
        return value
    t.used.add(key)
    try:
        if isinstance(raw, str):
            f = compile_expression(raw, "s", {"L": length})
        else:
            sub = Table(raw, t.path + "." + key, t.file)
            f = table_function(sub.get("s", list), sub.get("values", list))
            sub.done()
        samples = f(np.linspace(0.0, length, 201))
    except (ValueError, TypeError, ZeroDivisionError, FloatingPointError, OverflowError) as e:
        t.fail(
            key,
            f"{e} (write a number, an expression of s and L, or {{ s = [...], values = [...] }})",
        )
    if not np.all(np.abs(samples) <= MAX_MAGNITUDE):
        t.fail(key, "must be finite along the whole beam")
    return f


def read_twist(t, length):
    """``twist_deg`` of a beam table ``t``, in degrees (:func:`span_function`)."""
    return span_function(t, "twist_deg", length)


SHAPE_TYPES = ("shape", "polygon")
REFERENCES = ("centroid", "shear_centre")


def _points(t, key, value, what="points"):
    ok = isinstance(value, list) and len(value) >= 3
    ok = ok and all(
        isinstance(p, list) and len(p) == 2 and all(map(_finite_number, p)) for p in value
    )
    if not ok:
        t.fail(key, f"{what}: expected a list of at least 3 points [y, z] (finite numbers)")
    return tuple((float(y), float(z)) for y, z in value)


def _finite_number(v):
    return isinstance(v, Real) and not isinstance(v, bool) and bool(np.isfinite(v))


def _shape_params(t, name):
    """The keyword arguments of the built-in shape ``name``, each checked (kind, sign)."""
    params = {}
    for key, (kind, required) in ss.shape_parameters(name).items():
        if kind == "int":
            value = t.get(key, int, ss.POINT_DEFAULTS.get(key, ...))
            if value < 1:
                t.fail(key, f"= {value}: must be a positive integer")
        else:
            value = t.get(key, float, ... if required else None, positive=kind == "length")
            if value is None:
                continue
            if kind == "radius" and value < 0:
                t.fail(key, f"= {value:g}: must be >= 0 (a radius)")
        params[key] = value
    for key, rule, holds in _SHAPE_RULES.get(name, ()):
        if not holds(dict(params, **{k: 0.0 for k in ("r", "r_r") if k not in params})):
            given = ", ".join(f"{k} = {params[k]:g}" for k in _names_in(rule, params))
            t.fail(key, f"= {params[key]:g}: the {name} needs {rule} (given {given})")
    return tuple(sorted(params.items()))


def _names_in(rule, params):
    """The parameters named in ``rule`` (words of it that are keys of ``params``)."""
    words = rule.replace("(", " ").replace(")", " ").replace("·", " ").split()
    return [w for w in dict.fromkeys(words) if w in params]


#: the walls of a built-in shape must fit in its outline (sectionproperties builds a section
#: with a web wider than its flanges without complaint): (key blamed, rule, test) per shape
_I_RULES = (
    ("t_w", "t_w + 2·r < b", lambda p: p["t_w"] + 2 * p["r"] < p["b"]),
    ("t_f", "2·t_f + 2·r < d", lambda p: 2 * p["t_f"] + 2 * p["r"] < p["d"]),
)
_SHAPE_RULES = {
    "i_section": _I_RULES,
    "tapered_flange_i_section": (
        ("t_w", "t_w + 2·r_r < b", lambda p: p["t_w"] + 2 * p["r_r"] < p["b"]),
        ("t_f", "2·t_f < d", lambda p: 2 * p["t_f"] < p["d"]),
    ),
    "mono_i_section": (
        ("t_w", "t_w + 2·r < b_t", lambda p: p["t_w"] + 2 * p["r"] < p["b_t"]),
        ("t_w", "t_w + 2·r < b_b", lambda p: p["t_w"] + 2 * p["r"] < p["b_b"]),
        ("t_ft", "t_ft + t_fb + 2·r < d", lambda p: p["t_ft"] + p["t_fb"] + 2 * p["r"] < p["d"]),
    ),
    "channel_section": (
        ("t_w", "t_w + r < b", lambda p: p["t_w"] + p["r"] < p["b"]),
        ("t_f", "2·t_f + 2·r < d", lambda p: 2 * p["t_f"] + 2 * p["r"] < p["d"]),
    ),
    "tee_section": (
        ("t_w", "t_w + 2·r < b", lambda p: p["t_w"] + 2 * p["r"] < p["b"]),
        ("t_f", "t_f + r < d", lambda p: p["t_f"] + p["r"] < p["d"]),
    ),
    "angle_section": (
        ("t", "t < b", lambda p: p["t"] < p["b"]),
        ("t", "t < d", lambda p: p["t"] < p["d"]),
    ),
    "rectangular_hollow_section": (
        ("t", "2·t < b", lambda p: 2 * p["t"] < p["b"]),
        ("t", "2·t < d", lambda p: 2 * p["t"] < p["d"]),
    ),
    "circular_hollow_section": (("t", "2·t < d", lambda p: 2 * p["t"] < p["d"]),),
    "elliptical_hollow_section": (
        ("t", "2·t < d_x", lambda p: 2 * p["t"] < p["d_x"]),
        ("t", "2·t < d_y", lambda p: 2 * p["t"] < p["d_y"]),
    ),
}


def _shape_material(t, mat):
    """(E, G, rho, nu) from the section table's own keys, else from ``mat`` ([material])."""
    E0, G0, rho0, nu0 = mat if mat is not None else (None, None, 0.0, 0.3)
    E = t.get("E", float, E0 if E0 is not None else ..., positive=True)
    nu = t.get("nu", float, nu0)
    if not -1 < nu < 0.5:
        t.fail("nu", f"must lie in (-1, 0.5), got {nu}")
    own = t.has("E") or t.has("nu")
    G = t.get("G", float, E / (2 * (1 + nu)) if own or G0 is None else G0, positive=True)
    rho = t.get("rho", float, rho0)
    if not rho >= 0:
        t.fail("rho", f"= {rho:g}: must be a finite number >= 0")
    return E, G, rho, nu


def _properties(t, kind):
    """ShapeProperties of a shape or polygon table (computed once per distinct section; the
    time of a new FE section solve is reported on stderr by rank 0)."""
    mesh_size = t.get("mesh_size", float, None, positive=True)
    key = "shape" if kind == "shape" else "points"
    if kind == "shape":
        name = t.get("shape", str, choices=ss.SHAPES)
        args = (name, _shape_params(t, name))
        solve = ss.shape_properties
    else:
        holes = t.get("holes", list, [])
        holes = [_points(t, "holes", h, f"hole {i + 1}") for i, h in enumerate(holes)]
        args = (_points(t, "points", t.get("points", list)), tuple(holes))
        solve = ss.polygon_properties
    return key, solve, args, mesh_size


def shape_section(t, mat, length):
    """The matrix section of a ``type = "shape"`` (a built-in shape of sectionproperties) or
    ``type = "polygon"`` table (:mod:`beamfx.physics.shape_sections`), about its
    ``reference`` point ("centroid", "shear_centre" or [y, z] of the shape's coordinates)."""
    kind = t.get("type", str, choices=SHAPE_TYPES)
    try:
        import sectionproperties  # noqa: F401
    except ImportError:
        t.fail("type", f"{kind!r} needs the Python package sectionproperties (scripts/install.sh)")
    key, solve, args, mesh_size = _properties(t, kind)
    E, G, rho, nu = _shape_material(t, mat)
    raw = t.data.get("reference", "centroid")
    reference = raw if isinstance(raw, str) else _pair(t, "reference")
    if isinstance(raw, str):
        t.get("reference", str, "centroid", choices=REFERENCES)
    t.done()
    misses = solve.cache_info().misses
    try:
        props = solve(*args, nu, mesh_size)
    except ValueError as e:
        t.fail(key, str(e))
    if solve.cache_info().misses > misses:
        _report(t, props)
    point = {"centroid": props.centroid, "shear_centre": props.shear_centre}.get(reference)
    C, M = ss.shape_matrices(props, E, G, rho, reference if point is None else point)
    return ms.MatrixSection(C[None], M[None], (0.0,), length)


def _report(t, props):
    import sys

    from mpi4py import MPI

    if MPI.COMM_WORLD.rank == 0:
        print(
            f"beamfx: {t.where('type')}: FE section analysis of {props.elements} triangles "
            f"in {props.seconds:.2f} s",
            file=sys.stderr,
            flush=True,
        )
