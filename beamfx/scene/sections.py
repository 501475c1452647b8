"""Scene keys of matrix (6×6) sections and of section offsets (docs/scenes.md, "Matrix sections").

``section = { type = "matrix", stiffness = [[...] × 6], mass = [[...] × 6] }``, optionally
``stations = [s/L, ...]`` with one matrix per station, and ``convention = "beamfx"`` (default)
or ``"beamdyn"``; and the offset keys ``elastic_centre``, ``shear_centre`` and ``mass_centre``
(``[y, z]`` in section axes) of a prismatic geometric or general section, which turn it into a
matrix section (:mod:`beamfx.physics.matrix_sections`).
"""

from numbers import Real
from pathlib import Path

import numpy as np

from ..physics import matrix_sections as ms

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


def read_twist(t, length):
    """``twist_deg`` of a beam table ``t``: a number (degrees), an expression of the arc length
    ``s`` (and ``L``) or a table ``{ s = [...], values = [...] }`` (piecewise linear in s),
    finite along the beam (negative values allowed)."""
    from .expr import compile_expression, table_function
    from .table import MAX_MAGNITUDE, Table

    raw = t.data.get("twist_deg", 0.0)
    if not isinstance(raw, (str, dict)):
        value = t.get("twist_deg", float, 0.0)
        if not abs(value) <= MAX_MAGNITUDE:
            t.fail("twist_deg", f"= {value:g}: must be a finite number")
        return value
    t.used.add("twist_deg")
    try:
        if isinstance(raw, str):
            f = compile_expression(raw, "s", {"L": length})
        else:
            sub = Table(raw, t.path + ".twist_deg", t.file)
            f = table_function(sub.get("s", list), sub.get("values", list))
            sub.done()
        samples = f(np.linspace(0.0, length, 201))
    except (ValueError, TypeError, ZeroDivisionError, FloatingPointError, OverflowError) as e:
        t.fail(
            "twist_deg",
            f"{e} (write a number, an expression of s and L, or {{ s = [...], values = [...] }})",
        )
    if not np.all(np.abs(samples) <= MAX_MAGNITUDE):
        t.fail("twist_deg", "must be finite along the whole beam")
    return f
