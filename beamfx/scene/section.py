"""The section and material of a ``[[beams]]`` table: numbers, expressions of the arc length
or tables along the beam, every value checked finite and in range along the whole beam."""

from functools import partial
from pathlib import Path

import numpy as np

from ..physics import sections
from .expr import compile_expression, table_function
from .sections import beamdyn_section, matrix_section, offsets, shape_section, with_offsets
from .table import MAX_MAGNITUDE, Table, is_number

SECTION_TYPES = ("rectangle", "circle", "tube", "general", "matrix", "beamdyn", "shape", "polygon")
_SAMPLES = 201  # points along the beam where a varying value is checked
_EXPRESSION_ERRORS = (ValueError, TypeError, ZeroDivisionError, FloatingPointError, OverflowError)


def along(t, key, length, default=..., positive=True):
    """A section value: a number, an expression of the arc length ``s`` (and the beam length
    ``L``), or a table ``{ s = [...], values = [...] }``; checked positive along the beam."""
    if not t.has(key) and default is not ...:
        t.get(key, float, default)
        return default
    raw = t.data.get(key)
    if isinstance(raw, (str, dict)):
        t.used.add(key)
        try:
            if isinstance(raw, str):
                f = compile_expression(raw, "s", {"L": length})
            else:
                sub = Table(raw, t.path + "." + key, t.file)
                f = table_function(sub.get("s", list), sub.get("values", list))
                sub.done()
            values = f(np.linspace(0.0, length, _SAMPLES))
        except _EXPRESSION_ERRORS as e:
            t.fail(
                key,
                f"{e} (write a number, an expression of s and L, or {{ s = [...], values = [...] }})",
            )
        if not np.all(np.isfinite(values) & (np.abs(values) <= MAX_MAGNITUDE)):
            bad = float(values[~(np.abs(values) <= MAX_MAGNITUDE)][0])
            t.fail(
                key,
                f"must be a finite number of magnitude at most {MAX_MAGNITUDE:.0e} along the "
                f"whole beam; it is {bad:g} somewhere",
            )
        if not positive and not np.all(values >= 0):
            t.fail(
                key, f"must be >= 0 along the whole beam; its smallest value is {values.min():g}"
            )
        if positive and not np.all(values > 0):
            t.fail(
                key,
                f"must be positive along the whole beam; its smallest value is {values.min():g}",
            )
        return f
    value = t.get(key, float, default, positive=positive)
    if not value >= 0:
        t.fail(key, f"= {value:g}: must be a finite number >= 0")
    return value


def read_section(t, mat, length, base=Path(".")):
    """A Section, or a SectionAlong if a value varies along the beam (``mat``: the
    material's (E, G, rho, nu) or None; ``length``: the beam's); a MatrixSection for the
    types "matrix", "beamdyn" (files relative to ``base``), "shape", "polygon" or with offset keys
    (:mod:`beamfx.scene.sections`)."""
    kind = t.get("type", str, choices=SECTION_TYPES)
    if kind == "matrix":
        return matrix_section(t, length)
    if kind == "beamdyn":
        return beamdyn_section(t, length, base)
    if kind in ("shape", "polygon"):
        return shape_section(t, mat, length)
    given = offsets(t)
    k = t.get("shear_factor", float, None, positive=True)
    value = partial(along, t, length=length)
    if kind == "general":
        params = {key: value(key) for key in ("EA", "GA_y", "GA_z", "GJ", "EI_y", "EI_z")}
        params["rho_A"] = value("rho_A", default=0.0, positive=False)
        rho_I = t.get("rho_I", "vec3", (0.0, 0.0, 0.0))
        if min(rho_I) < 0:
            t.fail("rho_I", f"= {list(rho_I)}: each must be >= 0")

        def make(rho_I=rho_I, **values):
            return sections.Section(**values, rho_I=rho_I)

    else:
        if mat is None:
            t.fail("type", "a geometric section needs the [material] table (E, nu, rho)")
        E, G, rho, nu = mat
        if kind == "rectangle":
            torsion = t.get("torsion", (str, float, int), "saint-venant")
            if (
                isinstance(torsion, bool)
                or (not isinstance(torsion, str) and not (is_number(torsion) and torsion > 0))
                or (isinstance(torsion, str) and torsion not in ("saint-venant", "thin-strip"))
            ):
                t.fail(
                    "torsion",
                    f"{torsion!r} is not allowed; allowed: 'saint-venant', 'thin-strip' or a "
                    "number J > 0 (the torsion constant, m^4)",
                )
            params = {"h": value("h"), "w": value("w")}
            make = partial(sections.rectangle, E, G, rho, torsion=torsion, shear_factor=k, nu=nu)
        elif kind == "circle":
            params = {"d": value("d")}
            make = partial(sections.tube, E, G, rho, d_inner=0.0, shear_factor=k, nu=nu)
        else:
            params = {"d": value("d"), "d_inner": value("d_inner", positive=False)}
            make = partial(sections.tube, E, G, rho, shear_factor=k, nu=nu)
            s = np.linspace(0.0, length, _SAMPLES)
            d, di = (p(s) if callable(p) else np.full_like(s, p) for p in params.values())
            if not np.all((0 <= di) & (di < d)):
                t.fail("d_inner", "must satisfy 0 <= d_inner < d along the whole beam")
    t.done()
    if any(callable(v) for v in params.values()):
        section = sections.SectionAlong(make, params)
    else:
        section = make(**params)
    return with_offsets(t, section, given, length) if given else section


def read_material(t):
    """(E, G, rho, nu) of the ``[material]`` table, or None without one."""
    if t is None:
        return None
    E = t.get("E", float, positive=True)
    nu = t.get("nu", float, 0.3)
    if not -1 < nu < 0.5:
        t.fail("nu", f"must lie in (-1, 0.5), got {nu}")
    G = t.get("G", float, E / (2 * (1 + nu)), positive=True)
    rho = t.get("rho", float, 0.0)
    if rho < 0:
        t.fail("rho", f"= {rho:g}: must be a finite number >= 0")
    t.done()
    return E, G, rho, nu


__all__ = ["SECTION_TYPES", "along", "read_material", "read_section"]
