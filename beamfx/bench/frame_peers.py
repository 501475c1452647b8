"""Linear space frames: beamfx beside OpenSeesPy and the exact solution.

Run by ``make bench-peers``::

    python -m beamfx.bench.frame_peers export DIR    # DIR/frame_problems.json
    .venv-peers/bin/python peers/opensees_frame.py DIR  # DIR/opensees_frame.json
    python -m beamfx.bench.frame_peers DIR           # compare; DIR/frame_compare.json

The problems are the demo frames (demos/scenes/tower.toml, dome.toml, lattice.toml) with linear kinematics,
P3 elements and their joint loads only (no gravity: a load along a member is not a joint
load, which the exact frame solution :mod:`~beamfx.bench.frame_stiffness` and OpenSees'
nodal loads would need as equivalent nodal loads). Errors are max |difference| / max |value|
over all nodes, separately for translations, rotations and reactions.
"""

import json
import sys
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


def compare(out_dir):
    """beamfx, OpenSees (if DIR/opensees_frame.json exists) and the exact solution; prints a
    table and writes DIR/frame_compare.json."""
    out_dir = Path(out_dir)
    peer_file = out_dir / "opensees_frame.json"
    peers = {}
    if peer_file.exists():
        peers = {r["problem"]: r for r in json.loads(peer_file.read_text())["records"]}
    rows = []
    for name, spec in _specs().items():
        u, reactions, wall = beamfx_frame(spec)
        exact, exact_r = frame_stiffness.solve(frame_stiffness.problem_from_model(spec))
        row = {"problem": name, "members": len(spec.beams), "beamfx_solve_s": wall}
        row["beamfx_vs_exact"] = differences(u, reactions, exact, exact_r)
        if name in peers:
            v = peers[name]["values"]
            r_os = {int(k): np.asarray(x) for k, x in v["reactions"].items()}
            row["opensees_vs_exact"] = differences(
                np.asarray(v["displacements"]), r_os, exact, exact_r
            )
            row["beamfx_vs_opensees"] = differences(
                u, reactions, np.asarray(v["displacements"]), r_os
            )
            row["opensees_solve_s"] = peers[name]["wall_s"]
        rows.append(row)
        print(json.dumps(row))
    (out_dir / "frame_compare.json").write_text(json.dumps(rows, indent=1))
    return rows


if __name__ == "__main__":
    if sys.argv[1] == "export":
        export(sys.argv[2])
    else:
        compare(sys.argv[1])
