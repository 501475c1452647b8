"""Lattice frames from 10³ to 10⁶ unknowns on 1 and 2 ranks: time per Newton iteration split
by phase, Krylov iterations, memory per rank, and a projection to more ranks.

The frame is the block of demos/scenes/lattice.toml (body-centred cubic cells of 10 mm,
struts of 1 mm diameter, bottom pinned, 1 N down on every top node) at n³ cells
(:mod:`beamfx.geometry.lattice`), read through ``[[frames]]`` like a user's scene; one
element of degree 2 per member. Each size is solved with linear kinematics (6 unknowns per
node, one load step) and finite kinematics (7 per node: the quaternion; one load step of
Newton), with ``[solver] linear = "direct"`` (MUMPS) and ``"iterative"`` (CG + BoomerAMG on
node blocks).

``python -m beamfx.bench.frame_scaling run DIR [CELLS ...] [--linear direct|iterative]
[--kinematics linear|finite]`` solves on the ranks it is started on and writes ``DIR/frame_scaling_np<N>.json``;
``... report DIR`` writes ``DIR/frame_scaling.md`` and ``.json`` from the 1- and 2-rank
files (``make bench-frame-scaling``). Each solve's peak memory is its own (the process's
high-water mark is reset before it).
"""

import json
import time
from pathlib import Path

from .frame_scaling_report import report

#: cells along an edge -> about 10³, 10⁴, 10⁵ and 10⁶ unknowns (7 per node)
CELLS = (2, 5, 10, 22)
#: PETSc events of a Newton iteration (the slowest rank's time): residual and tangent
#: assembly, preconditioner set-up (MUMPS: the factorisation; BoomerAMG: the node-ordered
#: copy and the hierarchy) and the linear solve (MUMPS: the triangular solves; CG: the
#: iterations)
EVENTS = {
    "assembly": ("SNESFunctionEval", "SNESJacobianEval"),
    "pc_setup": ("PCSetUp",),
    "solve": ("KSPSolve",),
}
SCENE = """
[material]
E = 2e9
nu = 0.35
rho = 1200
[[frames]]
name = "cell"
mesh = "lattice_{cells}.msh"
elements = 1
degree = 2
[[frames.members]]
group = "edges"
section = {{ type = "circle", d = 0.001 }}
[[frames.members]]
group = "struts"
section = {{ type = "circle", d = 0.001 }}
[[frames.supports]]
group = "bottom"
fix = "pinned"
[[frames.loads]]
group = "top"
force = [0, 0, -1.0]
[[frames.probes]]
group = "corner"
[model]
kinematics = "{kinematics}"
plane = "none"
[analysis]
type = "static"
steps = 1
[limits]
max_beams = 1000000
max_unknowns = 10000000
[solver]
linear = "{linear}"
"""


def lattice_scene(folder, cells, kinematics, linear, comm):
    """The scene of the ``cells``³ lattice (its mesh written to ``folder`` by rank 0)."""
    import tomllib

    from ..geometry.lattice import write_bcc_lattice
    from ..scene.load import parse_scene

    folder = Path(folder)
    mesh = folder / f"lattice_{cells}.msh"
    if comm.rank == 0 and not mesh.exists():
        folder.mkdir(parents=True, exist_ok=True)
        write_bcc_lattice(mesh, cells)
    comm.barrier()
    text = SCENE.format(cells=cells, kinematics=kinematics, linear=linear)
    return parse_scene(tomllib.loads(text), f"lattice_{cells}", folder)


def _event_seconds():
    """This rank's seconds so far in each of :data:`EVENTS`."""
    from petsc4py import PETSc

    return {
        k: sum(PETSc.Log.Event(n).getPerfInfo()["time"] for n in names)
        for k, names in EVENTS.items()
    }


def _release():
    """Freed memory back to the system: Python's cycles collected, and the heap that C's
    allocator keeps after a free (PETSc's and hypre's blocks, a third of a solve's peak at
    10³ cells) returned to it, so that it is not counted again under the next phase."""
    import ctypes
    import gc

    gc.collect()
    ctypes.CDLL("libc.so.6").malloc_trim(0)


def _peak_mib(comm, reset=False):
    """Peak resident memory (VmHWM) of every rank in MiB; ``reset`` starts a new peak."""
    if reset:  # freed heap back to the system first, else the last solve's stays counted
        _release()
        Path("/proc/self/clear_refs").write_text("5")
    status = Path("/proc/self/status").read_text().splitlines()
    kib = next(int(x.split()[1]) for x in status if x.startswith("VmHWM"))
    return comm.allgather(kib / 1024)


def _solve(scene, comm):
    """Model, Newton solver and the static solve of ``scene``: (model, solver, solved,
    seconds of each phase, seconds in each of :data:`EVENTS`, peak MiB of the solve alone)."""
    from ..analyses.planar_condensed import build_model
    from ..analyses.static import solve_static
    from ..solvers import NewtonSolver

    t = time.perf_counter()
    model = build_model(scene.model, comm, list(scene.probes.values()), False)
    seconds = {"model": time.perf_counter() - t}
    solver = NewtonSolver(
        model.F, model.J, model.w, model.bcs, "beamfx_static_", scene.solver_options
    )
    seconds["forms"] = time.perf_counter() - t - seconds["model"]
    events = _event_seconds()
    _peak_mib(comm, reset=True)
    cpu = time.process_time()
    solved = solve_static(model, steps=1, options=scene.solver_options, solver=solver)
    seconds["cpu_solve"] = time.process_time() - cpu
    peak_solve = _peak_mib(comm)
    after = _event_seconds()
    seconds["solve"] = solved.seconds["total"]
    split = {k: comm.allreduce(after[k] - events[k], op=_max()) for k in EVENTS}
    return model, solver, solved, seconds, split, peak_solve


def _max():
    from mpi4py import MPI

    return MPI.MAX


def measure(folder, cells, kinematics, linear, comm):
    """One solve of the ``cells``³ lattice: sizes, iterations, times and memory (a dict)."""
    from petsc4py import PETSc

    from ..analyses.reactions import entries
    from ..io import evaluate_points

    PETSc.Log.begin()
    _peak_mib(comm, reset=True)
    t0 = time.perf_counter()
    scene = lattice_scene(folder, cells, kinematics, linear, comm)
    read = time.perf_counter() - t0
    model, solver, solved, seconds, split, peak_solve = _solve(scene, comm)
    cpu = comm.allgather(seconds.pop("cpu_solve"))
    newton = max(solved.newton_iterations, 1)
    split["other"] = max(0.0, seconds["solve"] - sum(split.values()))
    at = scene.probes["corner"]
    probe = evaluate_points(model, [at], full=False)[at]
    reactions = entries(model)
    krylov = solver.snes.getLinearSolveIterations()
    # the tangent, its node-ordered copy and the hierarchy go before the frame is written (as
    # at the end of a run), so that the frame's arrays do not come on top of them
    solver.destroy()
    _release()
    seconds["output"] = _write_frame(folder / f"out_{comm.size}", scene, model, comm)
    out = {
        "cells": cells,
        "kinematics": kinematics,
        "linear": linear,
        "ranks": comm.size,
        "unknowns": model.unknowns(),
        "members": len(scene.model.beams),
        "converged": bool(solved.steps) and solved.steps[-1].load_factor == 1.0,
        "newton_iterations": solved.newton_iterations,
        "krylov_iterations": krylov,
        "seconds": {"scene": read, **seconds},
        "seconds_in_solve": split,
        "per_newton_iteration": {k: v / newton for k, v in split.items()},
        "cpu_seconds_solve": cpu,  # per rank
        "peak_MiB": _peak_mib(comm),  # the whole case: model, solve, frame
        "peak_MiB_solve": peak_solve,  # the Newton iterations only
        "probe_displacement": [float(v) for v in probe["displacement"]],
        "reaction_force": _total_force(reactions["reactions"]),
        "reactions": {k: v["force"] for k, v in list(reactions["reactions"].items())[:4]},
    }
    return out


def _write_frame(out, scene, model, comm):
    """Seconds (slowest rank) to write the state as a ParaView frame, as ``beamfx run`` does:
    each rank its own piece, nothing gathered."""
    from dataclasses import replace

    from ..io.output import FrameWriter

    if comm.rank == 0:
        out.mkdir(parents=True, exist_ok=True)
    comm.barrier()
    t = time.perf_counter()
    frames = FrameWriter(out, model, replace(scene.output, dir=str(out)), scene.model.beams, comm)
    frames.write(1, 1.0)
    frames.close()
    return comm.allreduce(time.perf_counter() - t, op=_max())


def _total_force(reactions):
    """The sum of the reaction forces (it balances the 1 N per top node)."""
    return [float(sum(r["force"][i] for r in reactions.values())) for i in range(3)]


def run(
    cells=CELLS,
    linear=("direct", "iterative"),
    comm=None,
    save=None,
    kinematics=("linear", "finite"),
):
    """Every size, kinematics and linear solver on ``comm``'s ranks (a list of dicts); the
    meshes go to a temporary folder. ``save(runs)`` is called on rank 0 after each solve."""
    import shutil
    import tempfile

    from mpi4py import MPI

    from ..io.vtkfiles import import_vtk

    import_vtk()  # before DOLFINx (docs: the VTK wheel and DOLFINx's RTLD_GLOBAL)
    comm = comm or MPI.COMM_WORLD
    folder = Path(comm.bcast(tempfile.mkdtemp() if comm.rank == 0 else None))
    out = []
    try:
        for n in cells:
            for kin in kinematics:
                for solver in linear:
                    out.append(measure(folder, n, kin, solver, comm))
                    if comm.rank == 0:
                        print(json.dumps(_brief(out[-1])), flush=True)
                        if save:
                            save(out)
    finally:
        comm.barrier()
        if comm.rank == 0:
            shutil.rmtree(folder, ignore_errors=True)
    return out


def _brief(r):
    """One line of progress."""
    keys = ("cells", "kinematics", "linear", "ranks", "unknowns", "newton_iterations")
    return {
        **{k: r[k] for k in keys},
        "krylov": r["krylov_iterations"],
        "per_it": {k: round(v, 4) for k, v in r["per_newton_iteration"].items()},
        "MiB": [round(m) for m in r["peak_MiB"]],
    }


def main(argv=None):
    """Command line: ``run DIR [CELLS ...] [--linear direct|iterative] [--kinematics
    linear|finite]`` measures (adding to what ``DIR/frame_scaling_np<N>.json`` holds of other
    rows), ``report DIR`` writes the report. One row per process (``--linear`` and
    ``--kinematics`` once each) keeps a large row's peak memory its own: a process does not
    give all the memory of a finished row back to the system."""
    import argparse

    from mpi4py import MPI

    cli = argparse.ArgumentParser(prog="python -m beamfx.bench.frame_scaling")
    cli.add_argument("what", choices=("run", "report"))
    cli.add_argument("folder", type=Path)
    cli.add_argument("cells", type=int, nargs="*", default=CELLS)
    cli.add_argument("--linear", choices=("direct", "iterative"), action="append")
    cli.add_argument("--kinematics", choices=("linear", "finite"), action="append")
    args = cli.parse_args(argv)
    if args.what == "report":
        report(args.folder)
        return
    comm = MPI.COMM_WORLD
    out = args.folder / f"frame_scaling_np{comm.size}.json"
    before = json.loads(out.read_text()) if comm.rank == 0 and out.exists() else {}
    old = before.get("runs", [])

    def save(runs):  # after every solve: a long run stopped keeps what it measured
        new = {(r["cells"], r["kinematics"], r["linear"]) for r in runs}
        keep = [r for r in old if (r["cells"], r["kinematics"], r["linear"]) not in new]
        args.folder.mkdir(parents=True, exist_ok=True)
        data = {"runs": keep + runs, "conditions": before.get("conditions", "")}
        out.write_text(json.dumps(data, indent=1, default=float))

    linear = tuple(args.linear or ("direct", "iterative"))
    run(tuple(args.cells), linear, comm, save, tuple(args.kinematics or ("linear", "finite")))


if __name__ == "__main__":
    main()
