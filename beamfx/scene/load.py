"""Read a TOML scene into a :class:`~beamfx.spec.Model` plus analysis settings.

The keys are the words of the reference files (``E``, ``nu``, ``rho``, ``EA``, ``GA_y``,
``EI_y``, ``angle_deg``, ``start_tangent``, ...). See docs/scenes.md for every key.
"""

import os
import tomllib
from dataclasses import dataclass, field
from functools import partial
from numbers import Real
from pathlib import Path

import numpy as np

from ..analyses.trimming import PLANE_CHOICES
from ..geometry import curves
from ..physics import sections
from ..physics.kinematics import PLANES, Kinematics
from ..solvers.options import option_problems
from ..spec import (
    AXES,
    DOF_NAMES,
    LOAD_KINDS,
    Beam,
    DistributedLoad,
    Model,
    PointLoad,
    PointMass,
    Spring,
    Support,
)
from .expr import compile_expression, table_function
from .table import SceneError, Table

CURVE_SHAPES = ("line", "arc", "helix", "polyline", "spline", "gmsh")
SECTION_TYPES = ("rectangle", "circle", "tube", "general")
FIX_WORDS = {"all": DOF_NAMES, "clamped": DOF_NAMES, "pinned": DOF_NAMES[:3]}


@dataclass(frozen=True)
class Scene:
    """A parsed scene: the model and how to analyse and report it."""

    file: str
    model: Model
    analysis: str = "static"
    probes: dict = field(default_factory=dict)  # name -> point ("beam:end")
    output: object = None  # beamfx.io.output.OutputSettings of [output]
    solver_options: dict = field(default_factory=dict)
    settings: object = None  # the analysis's Settings (beamfx/analyses/<name>_run.py)
    trimming: object = None  # analyses.trimming.Trim: the model the builder chose, and why
    condense: bool = False  # the statically condensed model (analyses/condensed.py) is used
    accuracy: dict | None = None  # [accuracy]: tolerance on a probe quantity (adaptive.py)

    def __post_init__(self):
        if self.output is None:
            from ..io.output import OutputSettings

            object.__setattr__(self, "output", OutputSettings())
        if self.settings is None:  # a scene made in code: the analysis's defaults
            from ..analyses.registry import analysis

            object.__setattr__(self, "settings", analysis(self.analysis).settings())

    @property
    def output_dir(self) -> str:
        """The output folder of ``[output] dir``."""
        return self.output.dir

    @property
    def steps(self) -> int:
        """Load steps of the analysis's static solves (10 where it has none)."""
        return getattr(self.settings, "steps", 10)


def _curve(t, base):
    shape = t.get("shape", str, choices=CURVE_SHAPES)
    if shape == "line":
        start = t.get("start", "vec3")
        if t.has("end"):
            end = t.get("end", "vec3")
        else:
            d, L = t.get("direction", "vec3"), t.get("length", float, positive=True)
            n = sum(x * x for x in d) ** 0.5 or t.fail("direction", "must not be zero")
            end = tuple(s + L * x / n for s, x in zip(start, d))
        c = curves.Line(start, end)
    elif shape == "arc":
        c = curves.Arc(
            t.get("start", "vec3"),
            t.get("start_tangent", "vec3"),
            t.get("centre", "vec3"),
            t.get("angle_deg", float, positive=True),
        )
        if c.radius == 0:
            t.fail("centre", "must differ from start (zero radius)")
    elif shape == "helix":
        c = curves.Helix(
            t.get("centre", "vec3"),
            t.get("axis", "vec3"),
            t.get("radius", float, positive=True),
            t.get("pitch", float),
            t.get("turns", float, positive=True),
            t.get("start_direction", "vec3", (1.0, 0.0, 0.0)),
        )
    elif shape in ("polyline", "spline"):
        pts = t.get("points", list)
        if len(pts) < 2 or not all(isinstance(p, list) and len(p) == 3 for p in pts):
            t.fail("points", "expected a list of at least two [x, y, z] points")
        pts = tuple(tuple(float(x) for x in p) for p in pts)
        c = curves.Polyline(pts) if shape == "polyline" else curves.SampledCurve(pts)
    else:
        f = base / t.get("file", str)
        if not f.exists():
            t.fail("file", f"no such file: {f}")
        c = curves.curve_from_gmsh(f, t.get("curve_tag", int, None))
    t.done()
    if not c.length > 0:
        raise SceneError(f"{t.where('')[:-1]}: zero-length curve")
    return c


def _along(t, key, length, default=..., positive=True):
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
            values = f(np.linspace(0.0, length, 201))
        except (ValueError, TypeError, ZeroDivisionError, FloatingPointError) as e:
            t.fail(
                key,
                f"{e} (write a number, an expression of s and L, or {{ s = [...], values = [...] }})",
            )
        if positive and not np.all(values > 0):
            t.fail(
                key,
                f"must be positive along the whole beam; its smallest value is {values.min():g}",
            )
        return f
    return t.get(key, float, default, positive=positive)


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
            value = float(raw)
            f = partial(np.full_like, fill_value=value, dtype=float)
            f.text = str(value)
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
    except (ValueError, TypeError, ZeroDivisionError, FloatingPointError) as e:
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
            return (
                isinstance(row, list)
                and len(row) == 3
                and all(isinstance(x, Real) and not isinstance(x, bool) for x in row)
            )

        if numbers(raw):
            J = np.diag(np.array(raw, float))
        elif len(raw) == 3 and all(numbers(row) for row in raw):
            J = np.array(raw, float)
        else:
            t.fail("inertia", f"expected [Jxx, Jyy, Jzz] or a 3x3 list of numbers, got {raw!r}")
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


def _section(t, mat, length):
    """A Section, or a SectionAlong if a value varies along the beam."""
    kind = t.get("type", str, choices=SECTION_TYPES)
    k = t.get("shear_factor", float, None, positive=True)
    along = partial(_along, t, length=length)
    if kind == "general":
        params = {key: along(key) for key in ("EA", "GA_y", "GA_z", "GJ", "EI_y", "EI_z")}
        params["rho_A"] = along("rho_A", default=0.0, positive=False)
        rho_I = t.get("rho_I", "vec3", (0.0, 0.0, 0.0))

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
                or (not isinstance(torsion, str) and torsion <= 0)
                or (isinstance(torsion, str) and torsion not in ("saint-venant", "thin-strip"))
            ):
                t.fail(
                    "torsion",
                    f"{torsion!r} is not allowed; allowed: 'saint-venant', 'thin-strip' or a number J",
                )
            params = {"h": along("h"), "w": along("w")}
            make = partial(sections.rectangle, E, G, rho, torsion=torsion, shear_factor=k, nu=nu)
        elif kind == "circle":
            params = {"d": along("d")}
            make = partial(sections.tube, E, G, rho, d_inner=0.0, shear_factor=k, nu=nu)
        else:
            params = {"d": along("d"), "d_inner": along("d_inner", positive=False)}
            make = partial(sections.tube, E, G, rho, shear_factor=k, nu=nu)
            s = np.linspace(0.0, length, 201)
            d, di = (p(s) if callable(p) else np.full_like(s, p) for p in params.values())
            if not np.all((0 <= di) & (di < d)):
                t.fail("d_inner", "must satisfy 0 <= d_inner < d along the whole beam")
    t.done()
    if any(callable(v) for v in params.values()):
        return sections.SectionAlong(make, params)
    return make(**params)


def _material(t):
    if t is None:
        return None
    E = t.get("E", float, positive=True)
    nu = t.get("nu", float, 0.3)
    if not -1 < nu < 0.5:
        t.fail("nu", f"must lie in (-1, 0.5), got {nu}")
    G = t.get("G", float, E / (2 * (1 + nu)), positive=True)
    rho = t.get("rho", float, 0.0)
    t.done()
    return E, G, rho, nu


def _fix(t):
    fix = t.get("fix", (str, list))
    if isinstance(fix, str):
        if fix not in FIX_WORDS:
            t.fail(
                "fix",
                f"{fix!r} is not allowed; allowed: {list(FIX_WORDS)} or a list of {list(DOF_NAMES)}",
            )
        return tuple(FIX_WORDS[fix])
    bad = [d for d in fix if d not in DOF_NAMES]
    if bad or not fix:
        t.fail("fix", f"{bad or fix} not allowed; allowed: a list of {list(DOF_NAMES)}")
    return tuple(fix)


def parse_scene(data: dict, file: str = "<scene>", base: Path = Path(".")) -> Scene:
    """Scene from already-parsed TOML data (``file`` is used in error messages)."""
    top = Table(data, "", file)
    mat = _material(top.table("material", None))
    beams = _beams(top, mat, base, file)
    supports = _supports(top)
    point_loads, distributed, gravity = _loads(top)
    springs = _springs(top)
    masses = _masses(top)

    mt = top.table("model", {})
    plane = mt.get("plane", str, "auto", choices=PLANE_CHOICES)
    condense = mt.get("condense", str, "auto", choices=("auto", "none"))
    kin = Kinematics(
        finite=mt.get("kinematics", str, "finite", choices=("finite", "linear")) == "finite",
        shear=mt.get("shear", bool, True),
        stretch=mt.get("stretch", bool, True),
        plane=plane if plane in PLANES else None,
    )
    mt.done()
    at = top.table("analysis", {})
    analysis, settings = _analysis(at, Model(tuple(beams), tuple(supports)))
    if analysis.linear:
        kin = Kinematics(False, kin.shear, kin.stretch, kin.plane)

    probes = _probes(top)
    output = _output(top.table("output", {}))
    solver = top.get("solver", dict, {})
    for key, message in option_problems(solver):  # an allow-list: no viewers, logs, files
        top.fail(f"solver.{key}", message)
    accuracy_table = top.table("accuracy", None)
    top.done()

    model = Model(
        tuple(beams),
        tuple(supports),
        tuple(point_loads),
        tuple(distributed),
        tuple(springs),
        gravity,
        kin,
        point_masses=tuple(masses),
    )
    _check_points(model, probes, file)
    if not model.supports and not getattr(settings, "free_body", lambda m: False)(model):
        raise SceneError(
            f"{file}: supports: none given; the structure is free (rigid-body motion), which "
            "only a modal analysis without pre-stress or a transient from rest can take"
        )
    model, trimming = _trim(model, plane, analysis, settings)
    if condense == "auto":
        from ..analyses.trimming import condensed_fit

        condense = condensed_fit(model, analysis.name) is None
    else:
        condense = False
    accuracy = _accuracy(accuracy_table, probes, analysis.name)
    _check_model(model, file)
    return Scene(
        file,
        model,
        analysis.name,
        probes,
        output,
        dict(solver),
        settings,
        trimming,
        condense,
        accuracy,
    )


def _beams(top, mat, base, file):
    """``[[beams]]``: the beams, their names unique."""
    beams = []
    for t in top.tables("beams"):
        name = t.get("name", str)
        if ":" in name or name in [b.name for b in beams]:
            t.fail("name", f"{name!r} must be unique and contain no ':'")
        curve = _curve(t.table("curve"), base)
        section = _section(t.table("section"), mat, curve.length)
        beams.append(
            Beam(
                name,
                curve,
                section,
                t.get("elements", int, 8, positive=True),
                t.get("degree", int, 2, choices=(1, 2, 3, 4)),
                t.get("orientation", "vec3", None),
                t.get("twist_deg", float, 0.0),
            )
        )
        t.done()
    if not beams:
        top.fail("beams", "a scene needs at least one [[beams]] table")
    for i, b in enumerate(beams):
        _check_orientation(b, f"{file}: beams[{i}].orientation")
    return beams


def _supports(top):
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
        )
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


def _loads(top):
    """``[[loads]]``: point loads, distributed loads and gravity."""
    point_loads, distributed, gravity = [], [], (0.0, 0.0, 0.0)
    for t in top.tables("loads"):
        if t.has("gravity"):
            gravity = t.get("gravity", "vec3")
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
                )
            )
        t.done(
            " (a point load has 'at'; a distributed one 'beam' or neither for all beams; or 'gravity')"
        )
    return point_loads, distributed, gravity


def _springs(top):
    """``[[springs]]``: springs to ground."""
    springs = []
    for t in top.tables("springs"):
        sp = Spring(
            t.get("at", str),
            t.get("stiffness", "vec3", (0.0,) * 3),
            t.get("rotational", "vec3", (0.0,) * 3),
        )
        if min(*sp.stiffness, *sp.rotational) < 0 or not any((*sp.stiffness, *sp.rotational)):
            t.fail("stiffness", "give non-negative 'stiffness' and/or 'rotational', not all zero")
        springs.append(sp)
        t.done()
    return springs


def _masses(top):
    """``[[masses]]``: rigid bodies attached at points."""
    masses = []
    for t in top.tables("masses"):
        masses.append(_point_mass(t))
        t.done()
    return masses


def _probes(top):
    """``[[probes]]``: ``{name: point}``."""
    probes = {}
    for t in top.tables("probes"):
        name = t.get("name", str)
        if name in probes:
            t.fail("name", f"probe {name!r} is given twice")
        probes[name] = t.get("at", str)
        t.done()
    return probes


def _output(t):
    """``[output]``: where the results go and which frames, by the fields of
    :class:`~beamfx.io.output.OutputSettings`."""
    from ..io.output import OutputSettings
    from .schema import read_settings

    return read_settings(OutputSettings, t)


def _analysis(t, model):
    """The :class:`~beamfx.analyses.registry.Analysis` of ``[analysis] type`` and its settings,
    read from the rest of the table by the settings class's fields."""
    from ..analyses.registry import analyses
    from .schema import read_settings

    entry = analyses()[t.get("type", str, "static", choices=tuple(analyses()))]
    defaults = getattr(entry.settings, "defaults", lambda model: {})(model)
    settings = read_settings(entry.settings, t, defaults)
    for key, message in getattr(settings, "problems_in", lambda model: ())(model):
        t.fail(key, message)
    return entry, settings


def _trim(model, plane, analysis, settings):
    """The model the scene needs: with ``[model] plane = "auto"`` (the default) the planar one
    where the scene is a plane problem (:func:`~beamfx.analyses.trimming.choose_plane`) and
    the analysis allows it (``analysis.plane``)."""
    from dataclasses import asdict, replace

    from ..analyses.trimming import Trim, choose_plane

    if plane != "auto":
        return model, Trim(model.kinematics.plane, False, f"stated: [model] plane = {plane!r}")
    if not analysis.plane:
        why = f"full model: a {analysis.name} analysis has out-of-plane modes"
        return model, Trim(None, True, why)
    free_body = getattr(settings, "free_body", lambda model: False)(model)
    trim = choose_plane(model, analysis.name, asdict(settings), free_body)
    if trim.plane:
        model = replace(model, kinematics=replace(model.kinematics, plane=trim.plane))
    return model, trim


def _accuracy(t, probes, analysis):
    """``[accuracy]``: element count and degree chosen to meet a tolerance on a probe quantity
    (:mod:`beamfx.analyses.adaptive`)."""
    from ..analyses.adaptive import DEGREES, QUANTITIES

    if t is None:
        return None
    if analysis not in ("static", "linear_static"):
        t.fail("tolerance", f"works with static and linear_static analyses, not {analysis!r}")
    quantity = t.get("quantity", str)
    name, _, what = quantity.partition(".")
    if name not in probes or what not in QUANTITIES:
        t.fail(
            "quantity",
            f"{quantity!r}: write '<probe>.<quantity>', probe one of {sorted(probes)}, "
            f"quantity one of {list(QUANTITIES)}",
        )
    out = {
        "quantity": quantity,
        "tolerance": t.get("tolerance", float, positive=True),
        "relative": t.get("relative", bool, False),
        "start_elements": t.get("start_elements", int, 1, positive=True),
        "start_degree": t.get("start_degree", int, 2, choices=DEGREES),
        "max_degree": t.get("max_degree", int, max(DEGREES), choices=DEGREES),
        "max_unknowns": t.get("max_unknowns", int, 20000, positive=True),
    }
    if out["max_degree"] < out["start_degree"]:
        t.fail("max_degree", f"must be at least start_degree ({out['start_degree']})")
    t.done()
    return out


def _check_model(model, file):
    """Checks that need the whole model: the planar model's plane, prescribed rotations."""
    from ..analyses.checks import check_planar

    try:
        check_planar(model)
    except ValueError as e:
        raise SceneError(f"{file}: model.plane: {e}") from None
    for i, s in enumerate(model.supports):
        kin = model.kinematics
        local_rotation = s.axes == "local" and any(s.rotation)
        if local_rotation and kin.finite and not kin.plane and not {"rx", "ry", "rz"} <= set(s.fix):
            raise SceneError(
                f"{file}: supports[{i}].rotation: a prescribed rotation needs rx, ry and rz in fix"
            )


def _check_points(model, probes, file):
    from ..spec import resolve_point

    named = [(f"supports[{i}].at", s.at) for i, s in enumerate(model.supports)]
    named += [(f"loads.at ({p.at})", p.at) for p in model.point_loads]
    named += [(f"springs[{i}].at", s.at) for i, s in enumerate(model.springs)]
    named += [(f"masses[{i}].at", m.at) for i, m in enumerate(model.point_masses)]
    named += [(f"probes.{k}.at", v) for k, v in probes.items()]
    for where, at in named:
        try:
            resolve_point(model, at)
        except ValueError as e:
            raise SceneError(f"{file}: {where}: {e}") from None
    for d in model.distributed_loads:
        if d.beam is not None and d.beam not in [b.name for b in model.beams]:
            raise SceneError(
                f"{file}: loads.beam: {d.beam!r} is no beam; beams are {[b.name for b in model.beams]}"
            )


def _check_orientation(beam, where):
    """The reference vector must not be parallel to the centre line anywhere."""
    import numpy as np

    if beam.orientation is None:
        return
    s = np.linspace(0, beam.curve.length, 201)
    x = beam.curve.points(s)
    t = np.diff(x, axis=0)
    t /= np.linalg.norm(t, axis=1)[:, None]
    o = np.asarray(beam.orientation, float)
    if (
        not np.linalg.norm(o) > 0
        or np.min(np.linalg.norm(np.cross(t, o / np.linalg.norm(o)), axis=1)) < 1e-6
    ):
        raise SceneError(
            f"{where}: {list(o)} is parallel to the centre line of beam {beam.name!r} "
            "somewhere; give a vector normal to it (the section's local z)"
        )


def read_toml(path: str | os.PathLike) -> dict:
    """The TOML data of the file at ``path``; a missing or malformed file is a SceneError."""
    try:
        return tomllib.loads(Path(path).read_text())
    except FileNotFoundError:
        raise SceneError(f"{path}: no such scene file") from None
    except tomllib.TOMLDecodeError as e:
        raise SceneError(f"{path}: not valid TOML: {e}") from None


def load_scene(path: str | os.PathLike) -> Scene:
    """Read and validate a scene file; raises :class:`SceneError` naming file and key."""
    path = Path(path)
    data = read_toml(path)
    if "sweep" in data:
        raise SceneError(
            f"{path}: sweep: this file describes a family of scenes (a parameter sweep); "
            "run it with 'beamfx run', or read it with beamfx.scene.load_sweep"
        )
    return parse_scene(data, str(path), path.parent)
