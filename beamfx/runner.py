"""Run a scene: build the model, solve, write results as it goes. One call behind ``beamfx run``."""

import os
import time
from dataclasses import replace
from functools import partial
from importlib import resources
from pathlib import Path

DEFAULT_SCENE = "bend45.toml"


def default_scene_path():
    """The built-in default scene (the 45-degree bend)."""
    return Path(str(resources.files("beamfx") / "scenes" / DEFAULT_SCENE))


def run_scene(
    path=None,
    out_dir=None,
    log=None,
    restart=False,
    png=False,
    animate=False,
    comm=None,
    scene=None,
):
    """Solve the scene at ``path`` (built-in default if None); return the results dict.

    A file with ``[[sweep]]`` tables is a family of scenes: it runs as an ensemble
    (:func:`beamfx.sweep.run_sweep`) and the sweep's summary is returned instead.
    ``comm`` (default: all ranks) is the communicator the scene is solved on; ``scene`` an
    already-parsed scene (then ``path`` only names it in the results).

    With ``png`` (or ``animate``: a GIF of a transient's frames too) pictures of the results
    are rendered into the output folder after the solve (:mod:`beamfx.io.pictures`).

    Writes ``results.json`` only after success (a stale one is removed first), and the
    ParaView series (``deformed.pvd`` / ``deformed.xdmf``) after every accepted load step.
    """
    from mpi4py import MPI

    from .analyses.checks import check_supported
    from .analyses.condensed import RotationRangeError, build_model
    from .analyses.static import solve_static
    from .io import (
        PvdSeries,
        XdmfSeries,
        check_writable,
        evaluate_points,
        nodal_fields,
        track_rotations,
        write_json_atomic,
        write_vtu,
    )
    from .io import log as default_log
    from .io.surface import SurfaceSeries, model_outlines, write_paraview_script
    from .solvers import SolveFailed

    comm = comm or MPI.COMM_WORLD
    log = log or partial(default_log, comm=comm)
    t_start = time.perf_counter()
    path = Path(path) if path else default_scene_path()
    if scene is None:
        from .scene import Sweep, load_scene_or_sweep

        scene = load_scene_or_sweep(path)
        if isinstance(scene, Sweep):
            from .sweep import run_sweep

            return run_sweep(scene, out_dir, log=log, png=png, comm=comm)
    out = Path(out_dir or scene.output_dir)
    check_writable(out, comm)
    results_file = out / "results.json"
    if comm.rank == 0 and results_file.exists():
        os.remove(results_file)
    check_supported(scene.model)

    log(f"beamfx: {path} -> {out}/")
    refinement = None
    if scene.accuracy:  # choose elements and degree first (analyses/adaptive.py)
        from .analyses.adaptive import refine_to_tolerance

        refinement = refine_to_tolerance(scene, comm, log)
        scene = refinement.scene
    extra_points = [
        *scene.probes.values(),
        *filter(None, [scene.settings.get("control_point")]),
    ]
    model = build_model(scene.model, comm, extra_points, scene.condense)
    if model.raised_degree:
        log(
            f"note: beams {model.raised_degree} raised to degree {model.degree} (one degree per mesh)"
        )
    log(
        f"model: {len(scene.model.beams)} beam(s), {model.mesh.mesh.topology.index_map(1).size_global} elements, degree "
        f"{model.degree}, {model.unknowns()} unknowns, {'finite' if model.kin.finite else 'linear'} kinematics"
    )
    from .analyses.trimming import Trim, trimming_summary

    trim = scene.trimming or Trim(model.kin.plane, False, "given as a model")
    trim_line, trim_entry = trimming_summary(trim, model.kin, model.unknowns())
    log(f"model: {trim_line}")
    if scene.condense:
        per_node = 3 + model.full.kin.rotation_size
        log(
            "model: statically condensed (a cantilever under point loads): the rotations are "
            f"the only unknowns, 3 per node instead of {per_node}, {model.unknowns()} instead of "
            f"{model.unknowns() // 3 * per_node}; shear and stretch kept"
        )
    pvd, xdmf = PvdSeries(out / "deformed.pvd", comm), XdmfSeries(out / "deformed.xdmf", comm)
    names = [b.name for b in scene.model.beams]
    outlines = model_outlines(scene.model.beams)
    surface = SurfaceSeries(out / "surface.pvd", model.degree, names, outlines, comm=comm)
    write_paraview_script(out, comm)
    if png or animate:
        from .io.pictures import write_undeformed

        write_undeformed(out, model, names, outlines)  # before the solve: w = 0
    latest = {}  # probe values of the last accepted step, rotations tracked along the path

    def write(step, time):
        """ParaView files of the current state as step ``step`` at ``time``."""
        fields = nodal_fields(model)
        vtu = out / f"deformed_{step:04d}.vtu"
        write_vtu(vtu, fields, comm)
        pvd.add(time, vtu)
        xdmf.add(time, fields)
        surface.add(step, time, fields)

    def resume(t):
        """Keep the ParaView frames of a restarted run up to time ``t``."""
        for series in (pvd, xdmf, surface.pvd):
            series.resume(t)

    write.resume = resume

    def on_step(step):
        write(step.step, step.load_factor)
        values = evaluate_points(model, list(scene.probes.values()))
        latest["probes"] = track_rotations(latest.get("probes"), values)

    extra = {}
    if scene.analysis == "arclength":
        result, extra = _trace(model, scene, out, on_step, log)
    elif scene.analysis in ("modal", "buckling"):
        from .analyses.eigen_run import run_eigen

        result, extra = run_eigen(model, scene, write, log)
        if "probes" not in latest:
            latest["probes"] = track_rotations(
                None, evaluate_points(model, list(scene.probes.values()))
            )
    elif scene.analysis == "transient":
        from .analyses.transient_run import run_transient

        result, extra, latest["probes"] = run_transient(model, scene, out, write, log, restart)
    elif scene.analysis == "rotating":
        from .analyses.rotating_run import run_rotating

        result, extra = run_rotating(model, scene, write, log, out)
        latest["probes"] = track_rotations(
            None, evaluate_points(model, list(scene.probes.values()))
        )
    else:

        def static(model):
            return solve_static(
                model, steps=scene.steps, options=scene.solver_options, on_step=on_step, log=log
            )

        try:
            result = static(model)
        except (RotationRangeError, SolveFailed) as e:
            if not scene.condense:
                raise
            log(f"model: the statically condensed model failed ({e}); solving the full model")
            scene = replace(scene, condense=False)
            model = build_model(scene.model, comm, extra_points, False)
            latest.clear()
            write.resume(0.0)  # drop the failed attempt's frames
            result = static(model)
    final = latest["probes"]
    results = {
        "scene": str(path),
        "analysis": scene.analysis,
        "converged": True,
        "model": {
            "beams": [b.name for b in scene.model.beams],
            "degree": model.degree,
            "unknowns": model.unknowns(),
            "kinematics": "finite" if model.kin.finite else "linear",
            "plane": model.kin.plane,
            "shear": model.kin.shear,
            "stretch": model.kin.stretch,
            "trimming": trim_entry,
            "condensed": scene.condense,
        },
        "load_steps": [
            {
                "step": s.step,
                "load_factor": s.load_factor,
                "newton_iterations": s.iterations,
                "residuals": list(s.residuals),
                "cutbacks": s.cutbacks,
            }
            for s in result.steps
            if hasattr(s, "load_factor")
        ],
        "newton_iterations": int(sum(s.iterations for s in result.steps)),
        **extra,
        **({"accuracy": refinement.entry(scene.accuracy)} if refinement else {}),
        "wall_time_s": {**result.seconds, "run": time.perf_counter() - t_start},
        "probes": {name: final[at] for name, at in scene.probes.items()},
        "paraview": {
            "pvd": "deformed.pvd",
            "xdmf": "deformed.xdmf",
            **({"surface": "surface.pvd"} if any(outlines.values()) else {}),
            "script": "open_in_paraview.py",
        },
    }
    if png or animate:
        from .io.pictures import write_pictures

        results["pictures"] = write_pictures(out, results, log, animate, comm=comm)
    write_json_atomic(results_file, results, comm)
    log(f"done in {results['wall_time_s']['run']:.2f} s; results in {results_file}")
    if refinement:
        estimate = f"{refinement.estimate:.3g}" if refinement.estimate is not None else "none"
        log(
            f"  accuracy: {scene.accuracy['quantity']} estimated error {estimate} "
            f"({'within' if refinement.reached else 'NOT within'} tolerance "
            f"{scene.accuracy['tolerance']:g})"
        )
    for name, v in results["probes"].items():
        log(
            f"  probe {name}: position {[round(x, 6) for x in v['position']]}, "
            f"displacement {[round(x, 6) for x in v['displacement']]}"
        )
    return results


def _trace(model, scene, out, on_step, log):
    """Arc-length continuation of a scene; the path is written to ``path.csv`` as it goes."""
    from types import SimpleNamespace

    from .analyses.continuation import limit_points, trace_path
    from .solvers.arclength import ArcLengthSettings

    settings = dict(scene.settings)
    method = settings.pop("method")
    csv = out / "path.csv"
    root = model.comm.rank == 0
    if root:
        csv.write_text("step,load_factor,ux,uy,uz,arc_length,iterations\n")

    def record(point):
        step = SimpleNamespace(step=len(record.points), load_factor=point.load_factor)
        record.points.append(point)
        if root:
            with csv.open("a") as f:
                u = ",".join(f"{x:.12g}" for x in point.displacement)
                f.write(
                    f"{step.step},{point.load_factor:.12g},{u},{point.arc_length:.12g},"
                    f"{point.iterations}\n"
                )
        on_step(step)

    record.points = []
    result = trace_path(
        model,
        **settings,
        settings=ArcLengthSettings(method=method),
        options=scene.solver_options,
        on_step=record,
        log=log,
    )
    control = result.control_point
    extra = {
        "control_point": control,
        "path": [
            {
                "load_factor": p.load_factor,
                "displacement": p.displacement.tolist(),
                "arc_length": p.arc_length,
            }
            for p in result.path
        ],
        "limit_points": [
            {"kind": p.kind, "load_factor": p.load_factor, "displacement": p.displacement.tolist()}
            for p in limit_points(result.path)
        ],
        "stopped_by": result.reason,
    }
    for p in extra["limit_points"]:
        log(f"  limit point ({p['kind']}): load factor {p['load_factor']:.6g} at {control}")
    return result, extra


def check_scene(path):
    """Validate a scene without solving: keys, types, points, supports; for a sweep file every
    member. Returns the scene, or the :class:`~beamfx.scene.Sweep`."""
    from .analyses.checks import check_supported
    from .scene import Sweep, load_scene_or_sweep

    loaded = load_scene_or_sweep(path)
    for scene in [m.scene for m in loaded.members] if isinstance(loaded, Sweep) else [loaded]:
        check_supported(scene.model)
    return loaded
