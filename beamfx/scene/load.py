"""Read a TOML scene into a :class:`~beamfx.spec.Model` plus analysis settings.

The keys are the words of the reference files (``E``, ``nu``, ``rho``, ``EA``, ``GA_y``,
``EI_y``, ``angle_deg``, ``start_tangent``, ...). See docs/scenes.md for every key.
"""

import os
from dataclasses import dataclass, field, replace
from functools import partial
from pathlib import Path

import numpy as np

from ..analyses.checks import takes_free_body
from ..analyses.trimming import PLANE_CHOICES
from ..physics.kinematics import PLANES, Kinematics
from ..solvers.options import option_problems
from ..spec import Beam, Model
from .curve import overlap, read_curve
from .files import read_toml
from .frames import RELEASE_ANALYSES, read_frames
from .limits import read_limits, unknowns
from .loads import read_loads, read_masses, read_springs, read_supports
from .section import read_material, read_section
from .sections import read_twist
from .table import SceneError, Table


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


def parse_scene(data: dict, file: str = "<scene>", base: Path = Path(".")) -> Scene:
    """Scene from already-parsed TOML data (``file`` is used in error messages)."""
    top = Table(data, "", file)
    limits = read_limits(top)
    mat = read_material(top.table("material", None))
    beams = _beams(top, mat, base, limits)
    supports = read_supports(top)
    point_loads, distributed, gravity = read_loads(top, {b.name: b.curve.length for b in beams})
    frames = read_frames(top, base, limits, partial(read_section, mat=mat, length=1.0), beams)
    beams, supports = beams + frames.beams, supports + frames.supports
    point_loads += frames.point_loads
    springs = read_springs(top)
    masses = read_masses(top)
    plane, condense, kin, formulation = _model_table(top.table("model", {}))
    at = top.table("analysis", {})
    model = Model(  # the settings are checked against it too (modes, loads)
        tuple(beams),
        tuple(supports),
        tuple(point_loads),
        tuple(distributed),
        tuple(springs),
        gravity,
        kin,
        point_masses=tuple(masses),
        releases=tuple(frames.releases),
    )
    analysis, settings = _analysis(at, model, limits)
    if frames.releases and analysis.name not in RELEASE_ANALYSES:
        top.fail(
            "frames",
            f"pinned or released joints ([[frames.joints]]) work in the analyses "
            f"{list(RELEASE_ANALYSES)}, not yet in {analysis.name!r}",
        )
    if analysis.linear:
        kin = Kinematics(False, kin.shear, kin.stretch, kin.plane)
        model = replace(model, kinematics=kin)

    probes = _probes(top)
    for name in set(probes) & set(frames.probes):
        top.fail("probes", f"probe {name!r} is given twice ([[probes]] and [[frames.probes]])")
    probes.update(frames.probes)
    output = _output(top.table("output", {}), limits)
    solver = top.get("solver", dict, {})
    for key, message in option_problems(solver):  # an allow-list: no viewers, logs, files
        top.fail(f"solver.{key}", message)
    accuracy_table = top.table("accuracy", None)
    top.done()
    _check_points(model, probes, file, data.get("loads", []))
    points = (*probes.values(), *getattr(settings, "points", tuple)())
    for key, message in getattr(settings, "problems_on_mesh", lambda m, p: ())(model, points):
        at.fail(key, message)  # e.g. more modes than the mesh has dofs
    _check_histories(model, settings, file, data.get("loads", []))
    if not model.supports and not takes_free_body(settings, model):
        raise SceneError(
            f"{file}: supports: none given; the structure is free (rigid-body motion), which "
            "only a modal analysis without pre-stress or a transient from rest can take"
        )
    try:
        model, trimming, condense = choose_model(
            model, analysis, settings, plane, condense, formulation
        )
    except ValueError as e:  # a formulation the analysis does not take
        top.fail("model.formulation", str(e))
    accuracy = _accuracy(accuracy_table, probes, analysis.name, limits)
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


def _model_table(mt):
    """``[model]``: (plane choice, condense choice, :class:`Kinematics`, formulation choice)."""
    from ..analyses.mixed import FORMULATIONS

    plane = mt.get("plane", str, "auto", choices=PLANE_CHOICES)
    condense = mt.get("condense", str, "auto", choices=("auto", "none"))
    formulation = mt.get("formulation", str, "auto", choices=FORMULATIONS)
    kin = Kinematics(
        finite=mt.get("kinematics", str, "finite", choices=("finite", "linear")) == "finite",
        shear=mt.get("shear", bool, True),
        stretch=mt.get("stretch", bool, True),
        plane=plane if plane in PLANES else None,
    )
    mt.done()
    return plane, condense, kin, formulation


def _check_size(top, beams, limits):
    """The model's unknowns within ``[limits] max_unknowns``, its mesh not over itself."""
    n = unknowns(beams)
    if n > limits.max_unknowns:
        cells = [max(b.elements, len(b.curve.kinks) + 1) for b in beams]
        i = max(range(len(beams)), key=cells.__getitem__)
        kinks = cells[i] > beams[i].elements
        top.fail(
            f"beams[{i}].{'curve.points' if kinks else 'elements'}",
            f"= {f'{cells[i] - 1} kinks' if kinks else beams[i].elements}: the model would "
            f"have about {n:.3g} unknowns (7 per node; elements, at least one per kink, times "
            f"the degree); allowed: at most {limits.max_unknowns} ([limits] max_unknowns "
            "raises it)",
        )
    problem = overlap(beams)
    if problem:
        top.fail(f"beams[{problem[0]}].curve", problem[1])


def _beams(top, mat, base, limits):
    """``[[beams]]``: the beams, their names unique."""
    beams, tables = [], top.tables("beams")
    if len(tables) > limits.max_beams:
        top.fail(
            "beams",
            f"{len(tables)} [[beams]] tables; allowed: at most {limits.max_beams} "
            "([limits] max_beams raises it)",
        )
    names = set()
    for t in tables:
        name = t.get("name", str)
        if ":" in name or name in names:
            t.fail("name", f"{name!r} must be unique and contain no ':'")
        names.add(name)
        curve = read_curve(t.table("curve"), base, limits)
        section = read_section(t.table("section"), mat, curve.length, base)
        beams.append(
            Beam(
                name,
                curve,
                section,
                t.get("elements", int, 8, positive=True),
                t.get("degree", int, 2, choices=(1, 2, 3, 4)),
                t.get("orientation", "vec3", None),
                read_twist(t, curve.length),
            )
        )
        t.done()
    if not beams and not top.has("frames"):
        top.fail("beams", "a scene needs at least one [[beams]] table")
    if not beams:
        return beams
    _check_size(top, beams, limits)
    for i, b in enumerate(beams):
        _check_orientation(b, top.where(f"beams[{i}].orientation"))
    return beams


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


def _output(t, limits):
    """``[output]``: where the results go and which frames, by the fields of
    :class:`~beamfx.io.output.OutputSettings`."""
    from ..io.output import OutputSettings
    from .schema import read_settings

    return read_settings(OutputSettings, t, max_count=limits.max_count)


def _analysis(t, model, limits):
    """The :class:`~beamfx.analyses.registry.Analysis` of ``[analysis] type`` and its settings,
    read from the rest of the table by the settings class's fields."""
    from ..analyses.registry import analyses
    from .schema import read_settings

    entry = analyses()[t.get("type", str, "static", choices=tuple(analyses()))]
    defaults = getattr(entry.settings, "defaults", lambda model: {})(model)
    settings = read_settings(entry.settings, t, defaults, done=False, max_count=limits.max_count)
    t.done(_other_analyses(t, analyses()))
    for key, message in getattr(settings, "problems_in", lambda model: ())(model):
        t.fail(key, message)
    t_end, dt = getattr(settings, "t_end", None), getattr(settings, "dt", None)
    if t_end is not None and dt is not None and t_end / dt > limits.max_count:
        t.fail(
            "dt",
            f"= {dt:g}: t_end / dt = {t_end / dt:.3g} time steps; allowed: at most "
            f"{limits.max_count} ([limits] max_count raises it)",
        )
    return entry, settings


def _other_analyses(t, entries):
    """What the first unknown key of ``[analysis]`` belongs to, if another analysis type takes
    it (``modes`` without ``type = "modal"``): a note for :meth:`Table.done`."""
    from dataclasses import fields

    unknown = sorted(k for k in t.data if k not in t.used)
    if not unknown:
        return ""
    takes = [
        name for name, a in entries.items() if unknown[0] in {f.name for f in fields(a.settings)}
    ]
    return f"; {unknown[0]!r} is a key of type = {takes}" if takes else ""


def choose_model(model, analysis, settings, plane="auto", condense="auto", formulation="auto"):
    """The model the scene builder solves ``model`` with, for ``analysis`` (a registry
    entry) and its ``settings``: (model with the planar kinematics and the formulation where
    chosen, :class:`~beamfx.analyses.trimming.Trim` with the reasons, whether it is statically
    condensed). ``plane``, ``condense`` and ``formulation`` are the ``[model]`` keys; with all
    "auto" a static cantilever under point loads in a plane gets the planar condensed model
    (the angle the only unknown), and a full model with a huge stiffness ratio the mixed
    formulation (:func:`~beamfx.analyses.mixed.choose_formulation`).

    Raises:
        ValueError: ``formulation`` "mixed" for an analysis that does not take it.
    """
    from dataclasses import replace

    from ..analyses.mixed import choose_formulation
    from ..analyses.trimming import condensed_fit

    model, trimming = _trim(model, plane, analysis, settings)
    condensed = (  # a stated mixed formulation is not condensed
        condense == "auto"
        and formulation != "mixed"
        and condensed_fit(model, analysis.name) is None
    )
    name, why = choose_formulation(model, analysis.name, formulation, condensed)
    model = replace(model, formulation=name)
    return model, trimming._replace(formulation=why), condensed


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
    trim = choose_plane(model, analysis.name, asdict(settings), takes_free_body(settings, model))
    if trim.plane:
        model = replace(model, kinematics=replace(model.kinematics, plane=trim.plane))
    return model, trim


def _accuracy(t, probes, analysis, limits):
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
    for key in ("max_unknowns", "start_elements"):
        if out[key] > limits.max_unknowns:
            t.fail(
                key,
                f"= {out[key]}: allowed: at most {limits.max_unknowns} "
                "([limits] max_unknowns raises it)",
            )
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


def _load_indices(loads):
    """Indices in ``[[loads]]`` of the point loads and of the distributed loads, in order."""
    at_load = [i for i, t in enumerate(loads) if "gravity" not in t and "at" in t]
    on_beam = [i for i, t in enumerate(loads) if "gravity" not in t and "at" not in t]
    return at_load, on_beam


def _check_histories(model, settings, file, loads):
    """Every load and support history finite over the whole run (``[0, t_end]`` of a
    transient; the reader checked ``[0, 1]``)."""
    t_end = getattr(settings, "t_end", None)
    if t_end is None:
        return
    at_load, on_beam = _load_indices(loads)
    timed = [(f"loads[{i}]", p) for i, p in zip(at_load, model.point_loads)]
    timed += [(f"loads[{i}]", d) for i, d in zip(on_beam, model.distributed_loads)]
    timed += [(f"supports[{i}]", s) for i, s in enumerate(model.supports)]
    t = np.linspace(0.0, t_end, 1001)
    for where, item in timed:
        given = item.histories() if hasattr(item, "histories") else (("history", item.history),)
        for key, f in given:
            if f is None:
                continue
            with np.errstate(all="ignore"):
                values = np.asarray(f(t), float)
            if not np.all(np.isfinite(values)):
                bad = float(t[~np.isfinite(values)][0])
                raise SceneError(
                    f"{file}: {where}.{key}: not finite at t = {bad:g} (within [0, t_end]); "
                    "allowed: a function finite over the whole run"
                )


def _check_points(model, probes, file, loads):
    """Every named point on a beam, every load's beam a beam (``loads``: the scene's
    ``[[loads]]`` tables, for the index of each load in the messages)."""
    from ..spec import resolve_point
    from ..spec.model import beam_index

    at_load, on_beam = _load_indices(loads)
    named = [(f"supports[{i}].at", s.at) for i, s in enumerate(model.supports)]
    named += [(f"loads[{i}].at", p.at) for i, p in zip(at_load, model.point_loads)]
    named += [(f"springs[{i}].at", s.at) for i, s in enumerate(model.springs)]
    named += [(f"masses[{i}].at", m.at) for i, m in enumerate(model.point_masses)]
    named += [(f"probes[{i}].at", v) for i, v in enumerate(probes.values())]
    index = beam_index(model)
    for where, at in named:
        try:
            resolve_point(model, at, index)
        except ValueError as e:
            raise SceneError(f"{file}: {where}: {e}") from None
    beams = [b.name for b in model.beams]
    for i, d in zip(on_beam, model.distributed_loads):
        if d.beam is not None and d.beam not in beams:
            raise SceneError(f"{file}: loads[{i}].beam: {d.beam!r} is no beam; beams are {beams}")


def _check_orientation(beam, where):
    """The reference vector must not be parallel to the centre line anywhere."""
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
