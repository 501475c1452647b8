"""``beamfx solid scene.toml``: the 3D solid of a one-beam scene, solved and compared with the
beam at the probes on the end faces (results.json, results.md, solid.pvd)."""

import resource
import time
from pathlib import Path

import numpy as np

from ..scene import SceneError
from .geometry import SolidMesh, SweepError
from .model import MATERIALS
from .solve import Solid, SolidSpec

CLAMP = {"ux", "uy", "uz", "rx", "ry", "rz"}


def spec_from_scene(scene, material=None, mesh=None, solver="auto"):
    """The :class:`SolidSpec` of a parsed scene. Raises SceneError naming file and key for
    what the solid cannot represent."""
    file, model = scene.file, scene.model
    if len(model.beams) != 1:
        raise SceneError(
            f"{file}: beams: the solid takes one beam, the scene has {len(model.beams)}"
        )
    beam = model.beams[0]
    if beam.section.varies or not beam.section.shape or callable(beam.twist_deg):
        raise SceneError(
            f"{file}: beams[0].section: the solid needs a prismatic rectangle, circle or tube "
            "(and a constant twist_deg)"
        )
    for what, items in (
        ("distributed loads", model.distributed_loads),
        ("springs", model.springs),
        ("masses", model.point_masses),
    ):
        if items:
            raise SceneError(f"{file}: {what}: not represented in the solid")
    if any(model.gravity):
        raise SceneError(f"{file}: loads.gravity: not represented in the solid")
    face = {f"{beam.name}:start": "start", f"{beam.name}:end": "end"}
    clamped = []
    for i, s in enumerate(model.supports):
        if s.at not in face or set(s.fix) != CLAMP or any(s.displacement) or any(s.rotation):
            raise SceneError(
                f"{file}: supports[{i}]: the solid clamps an end face only "
                f"(at = {list(face)}, fix = 'all', no prescribed motion)"
            )
        clamped.append(face[s.at])
    loads = {}
    for p in model.point_loads:
        if p.at not in face or p.kind != "dead" or p.history is not None:
            raise SceneError(
                f"{file}: loads.at ({p.at}): the solid takes dead loads on an end face only "
                f"(at = {list(face)}, kind = 'dead')"
            )
        f0, m0 = loads.get(face[p.at], ((0, 0, 0), (0, 0, 0)))
        loads[face[p.at]] = (tuple(np.add(f0, p.force)), tuple(np.add(m0, p.moment)))
    E, nu, rho = _material(file)
    if material is None:
        material = "neo-hookean" if model.kinematics.finite else "linear"
    if material not in MATERIALS:
        raise SceneError(f"--material {material!r} not allowed; allowed: {list(MATERIALS)}")
    mesh = mesh or SolidMesh()
    return SolidSpec(beam, E, nu, rho, tuple(clamped), loads, material, mesh, 2, solver)


def _material(file):
    """E, nu, rho of the scene's [material] table (the section holds only products)."""
    from ..scene.files import read_toml

    data = read_toml(file)  # the guarded reader (size, UTF-8, nesting); numbers checked by load
    mat = data.get("material")
    if not isinstance(mat, dict) or "E" not in mat:
        raise SceneError(f"{file}: material.E: the solid needs [material] with E and nu")
    return float(mat["E"]), float(mat.get("nu", 0.3)), float(mat.get("rho", 0.0))


def build(spec, file="<scene>", comm=None):
    """The :class:`Solid`, with sweep errors named by scene key."""
    keys = {
        "curve": "beams[0].curve",
        "section": "beams[0].section",
        "orientation": "beams[0].orientation",
    }
    try:
        return Solid(spec, comm)
    except SweepError as e:
        raise SceneError(
            f"{file}: {keys.get(e.key, '--' + e.key.replace('_', '-'))}: {e}"
        ) from None
    except ValueError as e:
        raise SceneError(f"{file}: beams[0]: {e}") from None


def beam_values(scene, probes, vtu=None):
    """The beam's probe values and cost (the scene's own model and mesh); with ``vtu``, its
    deformed centre line is written there for ParaView and the picture."""
    from ..analyses.model import BeamModel
    from ..analyses.static import solve_static
    from ..io import nodal_fields, write_vtu
    from ..io.probes import evaluate_points

    t0 = time.perf_counter()
    model = BeamModel(scene.model, extra_points=list(probes.values()))
    result = solve_static(model, steps=scene.steps, prefix="beamfx_solid_beam_")
    values = evaluate_points(model, list(probes.values()))
    if vtu is not None:
        write_vtu(vtu, nodal_fields(model))
    return {n: values[at] for n, at in probes.items()}, {
        "unknowns": model.unknowns(),
        "wall_s": time.perf_counter() - t0,
        "solve_s": result.seconds["total"] - result.seconds["compile"],
    }


def compare(beam, solid):
    """Rows (probe, quantity, beam, solid, difference relative to the largest beam value)."""
    rows = []
    for name in solid:
        for key in ("displacement", "rotation_vector"):
            b, s = np.asarray(beam[name][key]), np.asarray(solid[name][key])
            scale = max(np.max(np.abs(b)), 1e-300)
            for i, c in enumerate("xyz"):
                rows.append(
                    [name, f"{key[0]}_{c}", float(b[i]), float(s[i]), float((s[i] - b[i]) / scale)]
                )
    return rows


def markdown(rows):
    """Markdown table of the beam-against-solid rows of each probe's quantity."""
    lines = [
        "| probe | quantity | beam | solid | (solid − beam)/max|beam| |",
        "|---|---|---|---|---|",
    ]
    lines += [f"| {p} | {q} | {b:.6g} | {s:.6g} | {d:+.2e} |" for p, q, b, s, d in rows]
    return "\n".join(lines)


def run_solid(path, out=None, material=None, mesh=None, solver="auto", log=print, png=False):
    """Solve the solid of the scene at ``path`` and compare it with the beam; return results.

    Writes ``solid.pvd`` (the solid's displacement), ``beam.vtu`` (the beam's deformed centre
    line), ``results.json`` and ``results.md``; with ``png`` also ``solid_vs_beam.png``."""
    from mpi4py import MPI

    from ..io import write_json_atomic
    from ..scene import load_scene

    comm = MPI.COMM_WORLD
    say = log if comm.rank == 0 else (lambda *a: None)
    scene = load_scene(path)
    if scene.analysis not in ("static", "linear_static"):
        raise SceneError(f"{path}: analysis.type: the solid runs static or linear_static only")
    spec = spec_from_scene(scene, material, mesh, solver)
    beam = spec.beam
    probes = {n: at for n, at in scene.probes.items() if at.split(":")[-1] in ("start", "end")}
    if not probes:
        probes = {"tip": f"{beam.name}:end"}
    out = Path(out or Path(scene.output_dir) / "solid")
    if comm.rank == 0:
        out.mkdir(parents=True, exist_ok=True)
    comm.barrier()
    t0 = time.perf_counter()
    solid = build(spec, str(path), comm)
    say(
        f"solid: {solid.mesh.topology.index_map(3).size_global} {spec.mesh.cell} cells (P2), "
        f"{solid.unknowns()} unknowns, {spec.material}, {comm.size} rank(s)"
    )
    report = solid.solve_static(steps=scene.steps, log=say)
    wall = time.perf_counter() - t0
    values = {n: solid.face_values(at.split(":")[-1]) for n, at in probes.items()}
    rss = comm.allreduce(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, op=MPI.SUM)
    beam_vals, beam_cost = beam_values(scene, probes, out / "beam.vtu")
    rows = compare(beam_vals, values)
    results = {
        "scene": str(path),
        "material": spec.material,
        "E": spec.E,
        "nu": spec.nu,
        "mesh": {**solid.mesh_info, "unknowns": solid.unknowns(), "ranks": comm.size},
        "solve": report,
        "seconds": {**solid.seconds, "total": wall},
        "max_rss_MiB_all_ranks": rss / 1024,
        "beam": beam_cost,
        "solid": values,
        "table": rows,
    }
    solid.write(out / "solid.pvd")
    write_json_atomic(out / "results.json", results)
    table = markdown(rows)
    if comm.rank == 0:
        (out / "results.md").write_text(f"# Solid vs beam: {path}\n\n{table}\n")
    if png:
        from .picture import write_solid_picture

        title = f"{Path(path).name}: {spec.material}, {solid.unknowns()} unknowns"
        results["pictures"] = write_solid_picture(out, title, say)
        write_json_atomic(out / "results.json", results)
    say(table)
    say(
        f"solid {wall:.2f} s ({solid.unknowns()} unknowns, {report['krylov_iterations']} "
        f"linear iterations, {report['linear_solver']}); beam {beam_cost['wall_s']:.2f} s "
        f"({beam_cost['unknowns']} unknowns) -> {out}/"
    )
    return results
