"""Linear space frames: beamfx beside OpenSeesPy and the exact solution.

Run by ``make bench-peers``::

    python -m beamfx.bench.frame_peers export DIR    # DIR/frame_problems.json
    .venv-peers/bin/python peers/opensees_frame.py DIR  # DIR/opensees_frame.json
    python -m beamfx.bench.frame_peers DIR [REPORT]  # compare; DIR/frame_compare.json
                                                     # and REPORT/peers_frames.md

The problems are the demo frames (demos/scenes/tower.toml, dome.toml, lattice.toml) with linear kinematics,
P3 elements and their joint loads only (no gravity: a load along a member is not a joint
load, which the exact frame solution :mod:`~beamfx.bench.frame_stiffness` and OpenSees'
nodal loads would need as equivalent nodal loads). Errors are max |difference| / max |value|
over all nodes, separately for translations, rotations and reactions.

Times: beamfx's whole run is the scene file of that linear frame (:func:`linear_scene_text`,
``type = "linear_static"``) through :func:`~beamfx.runner.run_scene` as ``beamfx run`` runs it
(model, solve, reactions, the output the scene asks for), first and second in one process,
and ``beamfx run`` in a process of its own; the solve alone is :func:`beamfx_frame`'s.
"""

import json
import re
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from . import frame_stiffness

DEMOS = Path(__file__).resolve().parents[2] / "demos" / "scenes"
FRAMES = ("tower", "dome", "lattice")


def linear_frame(spec, degree=3):
    """The model ``spec`` with linear kinematics, P``degree`` members and no gravity."""
    from ..physics.kinematics import Kinematics

    beams = tuple(replace(b, degree=degree) for b in spec.beams)
    kin = Kinematics(False, spec.kinematics.shear, spec.kinematics.stretch)
    return replace(spec, beams=beams, gravity=(0.0, 0.0, 0.0), kinematics=kin)


def linear_scene_text(name, degree=3):
    """The demo scene ``name`` as the linear frame of :func:`linear_frame`: a scene file with
    P``degree`` members, no gravity and ``[analysis] type = "linear_static"``."""
    text = (DEMOS / f"{name}.toml").read_text()
    text = re.sub(r"(?m)^degree = \d+$", f"degree = {degree}", text)
    text = re.sub(r"(?m)^\[\[loads\]\]\ngravity = .*\n", "", text)
    text, n = re.subn(r"(?ms)^\[analysis\]\n.*", '[analysis]\ntype = "linear_static"\n', text)
    if n != 1 or "gravity" in text:
        raise ValueError(f"{name}.toml: not the demo frame this bench expects")
    return text


def write_linear_scene(name, folder):
    """:func:`linear_scene_text` and the frame's mesh written to ``folder``; the file's path."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    shutil.copy(DEMOS / f"{name}.msh", folder)
    path = folder / f"{name}.toml"
    path.write_text(linear_scene_text(name))
    return path


def whole_runs(name):
    """The whole runs of beamfx on the linear frame ``name`` as a user waits for them: ``first_s``
    and ``whole_s`` = the first and second :func:`~beamfx.runner.run_scene` of its scene file
    in this process, ``process_s`` = ``beamfx run`` in a process of its own (interpreter,
    imports, JIT cache load, model, solve, output)."""
    from ..runner import run_scene

    times = {}
    with tempfile.TemporaryDirectory(prefix="beamfx-frame-") as tmp:
        path = write_linear_scene(name, Path(tmp) / "scene")
        for key in ("first_s", "whole_s"):
            t0 = time.perf_counter()
            run = run_scene(path, Path(tmp) / key, log=lambda *a, **k: None)
            times[key] = time.perf_counter() - t0
        times["split_s"] = {k: float(v) for k, v in run.wall_time_s.items()}
        cmd = [sys.executable, "-m", "beamfx.cli", "run", str(path), "--out", f"{tmp}/process"]
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, capture_output=True)
        times["process_s"] = time.perf_counter() - t0
    return times


def problem_json(problem):
    """A :class:`~beamfx.bench.frame_stiffness.FrameProblem` as plain JSON data."""
    return {
        "nodes": problem.nodes.tolist(),
        "members": problem.members.tolist(),
        "stiffness": problem.stiffness.tolist(),
        "axes": problem.axes.tolist(),
        "fixed": {str(k): sorted(v) for k, v in problem.fixed.items()},
        "loads": {str(k): np.asarray(v).tolist() for k, v in problem.loads.items()},
    }


def beamfx_frame(spec, comm=None):
    """The linear beamfx solution of ``spec`` at the frame's nodes (numbering of
    :func:`~beamfx.bench.frame_stiffness.problem_from_model`): displacements and rotations
    (n, 6), reactions {node: (6,)} and the solve's wall time. Collective."""
    from mpi4py import MPI

    from ..analyses.model import BeamModel
    from ..analyses.reactions import entries
    from ..analyses.static import solve_static
    from ..io import evaluate_points
    from ..spec import resolve_point

    problem = frame_stiffness.problem_from_model(spec)
    ends = [f"{b.name}:{w}" for b in spec.beams for w in ("start", "end")]
    model = BeamModel(spec, comm or MPI.COMM_WORLD, extra_points=ends)
    t0 = time.perf_counter()
    solve_static(model)
    wall = time.perf_counter() - t0
    values = evaluate_points(model, ends)
    index = {_key(x): i for i, x in enumerate(problem.nodes)}
    u = np.zeros((len(problem.nodes), 6))
    for at in ends:
        u[index[_key(resolve_point(spec, at)[2])]] = np.r_[
            values[at]["displacement"], values[at]["rotation_vector"]
        ]
    found = entries(model)["reactions"]
    reactions = {
        index[_key(resolve_point(spec, at)[2])]: np.r_[r["force"], r["moment"]]
        for at, r in found.items()
    }
    return u, reactions, wall


def _key(x, tol=1e-9):
    return tuple(np.round(np.asarray(x) / tol).astype(np.int64))


def differences(u, reactions, u_ref, reactions_ref):
    """Max relative differences: translations, rotations, reactions."""
    out = [
        float(np.abs(u[:, s] - u_ref[:, s]).max() / np.abs(u_ref[:, s]).max())
        for s in (slice(0, 3), slice(3, 6))
    ]
    r = np.array([reactions[k] for k in reactions_ref])
    r_ref = np.array([reactions_ref[k] for k in reactions_ref])
    out.append(float(np.abs(r - r_ref).max() / np.abs(r_ref).max()))
    return out


def _specs():
    from ..scene import load_scene

    return {name: linear_frame(load_scene(DEMOS / f"{name}.toml").model) for name in FRAMES}


def export(out_dir):
    """Write DIR/frame_problems.json."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    data = {n: problem_json(frame_stiffness.problem_from_model(s)) for n, s in _specs().items()}
    (out_dir / "frame_problems.json").write_text(json.dumps(data))


def _opensees_row(record, import_s, exact, exact_r, u, reactions):
    """The OpenSees columns of a row: differences and times (process = import + first run)."""
    v = record["values"]
    r_os = {int(k): np.asarray(x) for k, x in v["reactions"].items()}
    u_os = np.asarray(v["displacements"])
    first = record.get("first_s")
    return {
        "opensees_vs_exact": differences(u_os, r_os, exact, exact_r),
        "beamfx_vs_opensees": differences(u, reactions, u_os, r_os),
        "opensees_solve_s": record["wall_s"],
        "opensees_whole_s": record.get("whole_s"),
        "opensees_first_s": first,
        "opensees_process_s": None if first is None else import_s + first,
    }


def compare(out_dir, report_dir=None):
    """beamfx, OpenSees (if DIR/opensees_frame.json exists) and the exact solution; prints
    each row, writes DIR/frame_compare.json and, with ``report_dir``, its peers_frames.md."""
    out_dir = Path(out_dir)
    peer_file = out_dir / "opensees_frame.json"
    peers, meta = {}, {}
    if peer_file.exists():
        data = json.loads(peer_file.read_text())
        peers, meta = {r["problem"]: r for r in data["records"]}, data.get("meta", {})
    rows = []
    for name, spec in _specs().items():
        u, reactions, wall = beamfx_frame(spec)
        exact, exact_r = frame_stiffness.solve(frame_stiffness.problem_from_model(spec))
        row = {"problem": name, "members": len(spec.beams), "beamfx_solve_s": wall}
        row |= {f"beamfx_{k}": v for k, v in whole_runs(name).items()}
        row["beamfx_vs_exact"] = differences(u, reactions, exact, exact_r)
        if name in peers:
            import_s = meta.get("import_s", 0.0)
            row |= _opensees_row(peers[name], import_s, exact, exact_r, u, reactions)
        rows.append(row)
        print(json.dumps(row))
    (out_dir / "frame_compare.json").write_text(json.dumps({"meta": meta, "rows": rows}, indent=1))
    if report_dir is not None:
        Path(report_dir).mkdir(parents=True, exist_ok=True)
        (Path(report_dir) / "peers_frames.md").write_text(markdown(rows, meta))
    return rows


def _s(x):
    return "—" if x is None else f"{x:.3g}"


def markdown(rows, meta):
    """The report section: agreement, then whole-run and solve times beside OpenSees."""
    lines = [
        "# Linear space frames: beamfx beside OpenSeesPy",
        "",
        (
            "Generated by `make bench-peers` (`python -m beamfx.bench.frame_peers`). The demo frames "
            "(demos/scenes/tower.toml, dome.toml, lattice.toml) with linear kinematics, P3 members and "
            "their joint loads (no gravity), in beamfx, in OpenSeesPy "
            f"{meta.get('openseespy', '?')} (one `ElasticTimoshenkoBeam` per member, beamfx's "
            "stiffnesses, `geomTransf Linear` with beamfx's section axes) and by the exact frame "
            "stiffness method (beamfx/bench/frame_stiffness.py). Differences are max |a - b| / max |b| "
            "over all nodes: translations / rotations / reactions."
        ),
        "",
        "| frame | members | beamfx vs exact | OpenSees vs exact | beamfx vs OpenSees |",
        "|---|---|---|---|---|",
    ]
    for r in rows:
        cells = [r.get(k) for k in ("beamfx_vs_exact", "opensees_vs_exact", "beamfx_vs_opensees")]
        text = ["—" if c is None else " / ".join(f"{x:.1e}" for x in c) for c in cells]
        lines.append(f"| {r['problem']} | {r['members']} | " + " | ".join(text) + " |")
    lines += [
        "",
        (
            "Times in seconds (noisy: a shared 2-core machine). *whole* = a user's run in a warm "
            "process: for beamfx the second `run_scene` of the scene file (model, solve, reactions, "
            "output as the scene asks), for OpenSees the second model build and solve (no files "
            "written); *first* = the first such run in the process; *process* = beamfx: `beamfx run` "
            "timed from outside; OpenSees: a fresh interpreter importing openseespy "
            f"({_s(meta.get('import_s'))} s) + its first run; *solve* = the linear solve alone; "
            "*of it analysis* = the part of beamfx's whole run spent in the analysis (forms, "
            "assembly, solve), the rest being the model (mesh file, spaces), reactions and output. "
            "The verdict compares whole runs."
        ),
        "",
        (
            "| frame | beamfx whole | of it analysis | OpenSees whole | beamfx first | OpenSees first | "
            "beamfx process | OpenSees process | beamfx solve | OpenSees solve | beamfx ahead |"
        ),
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        fx, os_ = r.get("beamfx_whole_s"), r.get("opensees_whole_s")
        ahead = "—" if os_ is None else ("yes" if fx < os_ else f"**no** ({fx / os_:.2g} x)")
        keys = ("whole_s", "first_s", "process_s", "solve_s")
        cells = [_s(r.get(f"{c}_{k}")) for k in keys for c in ("beamfx", "opensees")]
        cells.insert(1, _s(r.get("beamfx_split_s", {}).get("total")))
        lines.append(f"| {r['problem']} | " + " | ".join(cells) + f" | {ahead} |")
    return "\n".join(lines + ["", NOTE]) + "\n"


NOTE = (
    "Both codes solve the same linear system to round-off; the differences to the exact frame "
    "are its conditioning (the lattice's pinned supports leave rotations of nearly free struts). "
    "On time OpenSees is ahead on these small linear frames: a member is one closed-form "
    "12 x 12 stiffness matrix, assembled in C++; beamfx builds a finite element model of "
    "P3 members through DOLFINx (mesh, function spaces, forms, PETSc assembly, MUMPS), a fixed "
    "cost per run that a linear frame of a few hundred unknowns does not amortise."
)


def cli(argv, export, compare, module):
    """A peer comparison's command line: ``export DIR`` or ``DIR [REPORT_DIR]``."""
    if len(argv) == 2 and argv[0] == "export":
        export(argv[1])
    elif len(argv) in (1, 2) and argv[0] != "export":
        compare(*argv)
    else:
        raise SystemExit(f"usage: python -m {module} export DIR | DIR [REPORT_DIR]")


def main(argv):
    """``export DIR`` or ``DIR [REPORT_DIR]``."""
    cli(argv, export, compare, "beamfx.bench.frame_peers")


if __name__ == "__main__":
    main(sys.argv[1:])
