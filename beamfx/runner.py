"""Run a scene: build the model, run its analysis, write results as it goes. One call behind
``beamfx run``; the analysis is looked up by name (:mod:`beamfx.analyses.registry`)."""

import os
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import cached_property, partial
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # mpi4py and the scene reader are imported where used (start-up time)
    from mpi4py import MPI

    from .analyses.result import Result
    from .scene import Scene, Sweep

DEFAULT_SCENE = "bend45.toml"


def default_scene_path() -> Path:
    """The built-in default scene (the 45-degree bend)."""
    return Path(str(resources.files("beamfx") / "scenes" / DEFAULT_SCENE))


@dataclass(frozen=True)
class RunResult:
    """What ``beamfx run`` produced: the analysis's :class:`~beamfx.analyses.result.Result`
    and the run around it. ``to_json()`` is ``results.json``; ``run["key"]`` reads it."""

    scene: str
    result: "Result"  # the analysis's Result
    model: dict  # beams, degree, unknowns, kinematics, trimming, condensed
    probes: dict  # {probe name: values at the final state}
    wall_time_s: dict  # the analysis's split, "model" (its build, the frame writer's set-up),
    # "output_probes"/"_reactions"/"_frames" (per step, outside the analysis's own split), and
    # "run": the whole run in-process
    paraview: dict  # the files written for ParaView
    accuracy: dict | None = None  # the [accuracy] refinement, if asked
    pictures: dict | None = None  # the pictures rendered, if asked
    reactions: dict | None = None  # reactions and their balance (static and arc length)
    linear_solver: tuple = ()  # the linear solvers of the run's Newton solves

    @property
    def converged(self) -> bool:
        """Whether the analysis converged (its result's status)."""
        return self.result.status == "converged"

    def to_json(self) -> dict:
        """The content of results.json: scene, result, model, probes, wall time and outputs."""
        out = {"scene": self.scene, **self.result.to_json(), "model": self.model}
        if self.linear_solver:
            out["linear_solver"] = list(self.linear_solver)
        if self.accuracy is not None:
            out["accuracy"] = self.accuracy
        if self.reactions is not None:
            out.update(self.reactions)
        out.update(wall_time_s=self.wall_time_s, probes=self.probes, paraview=self.paraview)
        if self.pictures is not None:
            out["pictures"] = self.pictures
        return out

    @cached_property
    def json(self) -> dict:
        """The results.json content, computed once."""
        return self.to_json()

    def __getitem__(self, key: str) -> object:
        return self.json[key]

    def get(self, key: str, default: object = None) -> object:
        """Value of results.json key ``key``, or ``default``."""
        return self.json.get(key, default)

    def __contains__(self, key: object) -> bool:
        return key in self.json


def run_scene(
    path: str | os.PathLike | None = None,
    out_dir: str | os.PathLike | None = None,
    log: Callable[[str], None] | None = None,
    restart: bool = False,
    png: bool = False,
    animate: bool = False,
    comm: "MPI.Comm | None" = None,
    scene: "Scene | None" = None,
) -> "RunResult | dict":
    """Solve the scene at ``path`` (built-in default if None) on ``comm`` (default: all
    ranks) and return its :class:`RunResult`; a ``[[sweep]]`` file returns the sweep's table
    (:func:`beamfx.sweep.run_sweep`). ``scene``: already parsed (``path`` then only names it).
    Frames are written as the analysis goes, ``results.json`` at the end; ``png``/``animate``:
    pictures after the solve."""
    from mpi4py import MPI

    from .analyses.registry import analysis
    from .io import log as default_log
    from .io.folder import claim
    from .solvers.forms import remember_loaded_modules
    from .solvers.options import linear_solvers

    remember_loaded_modules()  # before the elements' lookup too: a later run here finds them
    comm, t_start = comm or MPI.COMM_WORLD, time.perf_counter()
    log = log or partial(default_log, comm=comm)
    path = Path(path) if path else default_scene_path()
    if scene is None:
        from .scene import Sweep, load_scene_or_sweep

        scene = load_scene_or_sweep(path)
        if isinstance(scene, Sweep):
            from .sweep import run_sweep

            check_members(scene)  # every member's input before any solve
            return run_sweep(scene, out_dir, run_scene, log=log, png=png, comm=comm)
    out = _prepare(Path(out_dir or scene.output_dir), scene, comm, out_dir is None)
    log(f"beamfx: {path} -> {out}/")
    if restart and not analysis(scene.analysis).restart:
        log(f"note: a {scene.analysis} analysis has no checkpoint to go on from: a fresh run")
        restart = False
    if restart:  # checkpoints of another number of ranks only: refused, nothing touched
        from .analyses.restart import refuse_other_ranks

        refuse_other_ranks(out, comm)
    with claim(out, comm, path, restart, log):  # locked, an earlier run's files removed
        linear_solvers(reset=True)  # those of this run only
        scene, refinement = _refine(scene, comm, log)
        t_model = time.perf_counter()
        ctx = _context(scene, out, comm, log, restart, png or animate)
        t_model = time.perf_counter() - t_model
        _note_small(ctx.model.unknowns(), comm, log)
        result = _analyse(analysis(scene.analysis), scene, ctx, log)
        linear = tuple(linear_solvers(reset=True))
        if linear:
            log(f"linear solver: {', '.join(linear)}")
        ctx.frames.close()
        ctx.close()
        output = {f"output_{k}": v for k, v in ctx.seconds.items()}
        seconds = {**result.seconds, "model": t_model, **output}
        run = RunResult(
            str(path),
            result,
            _model_entry(scene, ctx),
            _final_probes(scene, ctx),
            {**seconds, "run": time.perf_counter() - t_start},
            ctx.frames.files(),
            refinement.entry(scene.accuracy) if refinement else None,
            reactions=_reactions(ctx),
            linear_solver=linear,
        )
        return _finish(run, out, scene, refinement, log, comm, png, animate)


#: unknowns per rank below which one rank is faster (the ranks' messages cost more than
#: their share of the work saves; the 27-unknown spin-up took 15 s on 2 ranks, 1.2 s on one)
SMALL_PER_RANK = 2000


def _note_small(unknowns, comm, log):
    """Say so when a model is too small for the ranks it runs on."""
    if comm.size > 1 and unknowns < SMALL_PER_RANK * comm.size:
        log(
            f"note: {unknowns} unknowns on {comm.size} ranks: a model this small runs faster "
            "on one (MPI pays off from some thousands of unknowns per rank)"
        )


def _analyse(kind, scene, ctx, log):
    """The analysis's Result; a numerical failure (SolveFailed) becomes a failed Result, so
    that results.json is written and says why (``beamfx run`` then exits 3)."""
    from .analyses.result import failed
    from .solvers import SolveFailed

    t0 = time.perf_counter()
    try:
        return kind.run(ctx.model, scene.settings, ctx)
    except SolveFailed as e:
        log(f"failed: {e}")
        return failed(ctx.analysis, e, {"total": time.perf_counter() - t0})


def _prepare(out, scene, comm, named_by_scene):
    """The output folder, allowed (:func:`beamfx.io.folder.check_output_dir`) and checked
    writable; the frame writers' library imported (VTK before DOLFINx) or its absence
    reported, before any model is built. ``named_by_scene``: the folder is the scene's
    ``[output] dir`` (named in the error)."""
    from .io import check_writable
    from .io.folder import check_output_dir
    from .io.output import prepare_output

    check_output_dir(out, scene.file if named_by_scene else None)
    try:
        check_writable(out, comm)
    except OSError as e:
        raise OSError(f"{scene.file}: output.dir: {e}" if named_by_scene else str(e)) from None
    prepare_output(scene.output)
    return out


def _refine(scene, comm, log):
    """The scene with the elements and degree that meet its ``[accuracy]``, if it has one."""
    from .analyses.checks import check_supports_for

    if not scene.condense:  # a condensed model is a clamped cantilever (condensed_fit)
        check_supports_for(scene.model, scene.settings)
    if not scene.accuracy:
        return scene, None
    from .analyses.adaptive import refine_to_tolerance

    refinement = refine_to_tolerance(scene, comm, log)
    return refinement.scene, refinement


def _build(scene, comm, log, condense):
    """The model the scene asks for (condensed where the builder chose it), logged."""
    from .analyses.planar_condensed import build_model

    points = [*scene.probes.values(), *getattr(scene.settings, "points", lambda: ())()]
    model = build_model(scene.model, comm, points, condense)
    raised = model.discretisation.raised_degree
    if raised:
        log(f"note: beams {raised} raised to degree {model.degree} (one per mesh)")
    log(
        f"model: {len(scene.model.beams)} beam(s), "
        f"{model.mesh.mesh.topology.index_map(1).size_global} elements, degree {model.degree}, "
        f"{model.unknowns()} unknowns, {'finite' if model.kin.finite else 'linear'} kinematics"
    )
    return model


def _context(scene, out, comm, log, restart, pictures):
    """The model and the run context of the scene's analysis."""
    from .analyses.context import RunContext
    from .io.output import FrameWriter

    model = _build(scene, comm, log, scene.condense)
    log(f"model: {_trimming(scene, model, scene.condense)[0]}")
    formulation = _formulation(scene, model)
    log(f"model: {formulation['name']} formulation ({formulation['reason']})")
    if scene.condense:
        from .analyses.trimming import condensing_summary

        log(f"model: {condensing_summary(model.kin, model.unknowns())[0]}")
    output = scene.output
    if output.every is None and output.times is None:  # the analysis's default interval
        output = replace(output, every=getattr(scene.settings, "frames_every", 1))
    frames = FrameWriter(out, model, replace(output, dir=str(out)), scene.model.beams, comm)
    if pictures:
        from .io.pictures import write_undeformed

        write_undeformed(out, model, [b.name for b in scene.model.beams], frames.outlines)
    full = partial(_build, replace(scene, condense=False), comm, log, False)
    return RunContext(
        scene.analysis,
        model,
        out,
        comm,
        log,
        frames,
        scene.probes,
        scene.model,
        scene.file,
        scene.solver_options,
        restart,
        full if scene.condense else None,
    )


def _trimming(scene, model, condensed):
    """(log line, results entry) of the model the scene builder chose for ``model``."""
    from .analyses.mixed import force_unknowns
    from .analyses.trimming import Trim, trimming_summary

    trim = scene.trimming or Trim(model.kin.plane, False, "given as a model")
    nodal = model.unknowns() - force_unknowns(model)  # per node: the section force is not
    return trimming_summary(trim, model.kin, nodal, bool(condensed))


def _model_entry(scene, ctx):
    """The ``model`` entry of results.json: what was solved."""
    model, kin = ctx.model, ctx.model.kin
    condensed = bool(scene.condense and ctx.rebuild is not None)  # not after a fallback
    return {
        "beams": [b.name for b in scene.model.beams],
        "degree": model.degree,
        "unknowns": model.unknowns(),
        "kinematics": "finite" if kin.finite else "linear",
        "plane": kin.plane,
        "shear": kin.shear,
        "stretch": kin.stretch,
        "trimming": _trimming(scene, model, condensed)[1],
        "condensed": condensed,
        "formulation": _formulation(scene, model, fell_back=bool(scene.condense) and not condensed),
        **({"condensing": _condensing(ctx)} if condensed else {}),
    }


def _formulation(scene, model, fell_back=False):
    """The ``formulation`` entry of results.json: displacement or mixed
    (:mod:`beamfx.analyses.mixed`), and why (``fell_back``: the full model solved after the
    condensed one failed)."""
    name = "mixed" if getattr(model, "mixed", False) else "displacement"
    why = scene.trimming.formulation if scene.trimming else ""
    if fell_back:
        why = "the full model's, after the statically condensed model failed"
    return {"name": name, "reason": why or "given as a model"}


def _condensing(ctx):
    """The ``condensing`` entry of results.json: which condensed model solved, and why."""
    from .analyses.trimming import condensing_summary

    return condensing_summary(ctx.model.kin, ctx.model.unknowns())[1]


def _reactions(ctx):
    """The reactions of the analysis's last accepted state, logged with their balance."""
    if ctx.latest_reactions is None:
        return None
    from .analyses.reactions import balance_line

    ctx.log(balance_line(ctx.latest_reactions))
    return ctx.latest_reactions


def _final_probes(scene, ctx):
    """The probes at the final state (rotations unwrapped along the analysis's path)."""
    values = ctx.latest if ctx.latest is not None else ctx.probe_values(ctx.model, track=False)
    return {name: values[at] for name, at in scene.probes.items()}


def _finish(run, out, scene, refinement, log, comm, png, animate):
    """Pictures (if asked), results.json, and the summary in the log."""
    from .io import write_json_atomic

    if png or animate:
        from .io.pictures import write_pictures

        pictures = write_pictures(out, run.to_json(), log, animate, comm=comm)
        run = replace(run, pictures=pictures)
    write_json_atomic(out / "results.json", run.to_json(), comm)
    log(_ending(run, out))
    if refinement:
        estimate = f"{refinement.estimate:.3g}" if refinement.estimate is not None else "none"
        log(
            f"  accuracy: {scene.accuracy['quantity']} estimated error {estimate} "
            f"({'within' if refinement.reached else 'NOT within'} tolerance "
            f"{scene.accuracy['tolerance']:g})"
        )
    for name, v in run.probes.items():
        log(
            f"  probe {name}: position {[round(x, 6) for x in v['position']]}, "
            f"displacement {[round(x, 6) for x in v['displacement']]}"
        )
    return run


def _ending(run, out):
    """The last line of a run's log: "done in" for a converged run, else its status first
    ("failed after", "stopped after": a "done" before the failure read as a success; the
    reason is in results.json and ``beamfx run`` prints it)."""
    where = f"results in {out / 'results.json'}"
    seconds = run.wall_time_s["run"]
    if run.converged:
        return f"done in {seconds:.2f} s; {where}"
    return f"{run.result.status} after {seconds:.2f} s; {where}"


def check_scene(path: str | os.PathLike) -> "Scene | Sweep":
    """Validate a scene without solving: keys, types, points, supports; for a sweep file every
    member (:func:`check_members`) up to :data:`CHECK_EVERY_MEMBER` members, else each value
    once (those read). Returns the scene, or the :class:`~beamfx.scene.Sweep`."""
    from .io.folder import check_output_dir
    from .scene import Sweep, load_scene_or_sweep

    loaded = load_scene_or_sweep(path)
    if isinstance(loaded, Sweep):
        if len(loaded.members) <= CHECK_EVERY_MEMBER:
            check_members(loaded)
        else:  # those read (each value once): a check of 10⁴ members stays a second
            for scene in loaded.validated:
                _check_supports(scene)
    else:
        _check_supports(loaded)
    check_output_dir(loaded.output_dir, str(path))
    return loaded


#: ``beamfx check`` builds every member of a sweep of at most this many (2-5 ms each); a larger
#: one has each value checked once on reading, and ``beamfx run`` checks every member before
#: solving any
CHECK_EVERY_MEMBER = 2000


def check_members(sweep: "Sweep") -> None:
    """Build and check every member of ``sweep`` (keys, values, supports; a large sweep's
    reading validated only some), so that bad input in any member is refused, naming the
    member, before any is solved. About 2 ms per member of one small beam."""
    for member in sweep.members:
        _check_supports(member.scene)


def _check_supports(scene):
    """:func:`~beamfx.analyses.checks.check_supports_for` as a SceneError naming the file."""
    from .analyses.checks import check_supports_for
    from .scene import SceneError

    try:
        check_supports_for(scene.model, scene.settings)
    except ValueError as e:
        raise SceneError(f"{scene.file}: supports: {e}") from None
