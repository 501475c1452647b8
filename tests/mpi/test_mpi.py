"""Run under ``mpirun -n 2``: the same probes from all ranks as from one process."""

import numpy as np
import pytest
from mpi4py import MPI

from beamfx.analyses.model import BeamModel
from beamfx.analyses.static import solve_static
from beamfx.io import evaluate_points
from beamfx.runner import default_scene_path
from beamfx.scene import load_scene

pytestmark = pytest.mark.mpi


@pytest.mark.parametrize("condensed", [False, True])
@pytest.mark.parametrize("follower", [False, True])
def test_bend45_probes_match_serial(follower, condensed):
    from dataclasses import replace

    from beamfx.analyses.planar_condensed import build_model

    spec = load_scene(default_scene_path()).model
    kind = "follower" if follower else "dead"
    spec = replace(spec, point_loads=tuple(replace(p, kind=kind) for p in spec.point_loads))
    out = {}
    for comm in (MPI.COMM_SELF, MPI.COMM_WORLD):
        model = build_model(spec, comm, ["bend:end", "bend:0.5"], condensed)
        solve_static(model, steps=10)
        out[comm.size] = evaluate_points(model, ["bend:end", "bend:0.5"])
    parallel, serial = out[MPI.COMM_WORLD.size], out[1]
    for name in ("bend:end", "bend:0.5"):
        for key in ("position", "rotation_vector", "section_moment"):
            a, b = np.asarray(parallel[name][key]), np.asarray(serial[name][key])
            assert np.allclose(a, b, rtol=1e-9, atol=1e-9 * max(1.0, np.abs(b).max())), (
                name,
                key,
                a,
                b,
            )


def _serial_and_parallel(run):
    """``run(comm)`` on one process and on all ranks."""
    return run(MPI.COMM_SELF), run(MPI.COMM_WORLD)


def test_modal_and_buckling_match_serial():
    """Frequencies of the pre-stressed 45-degree bend and its buckling factors: eigenvalues
    do not depend on the partition (MUMPS solves the same shifted problem)."""
    from beamfx.analyses.buckling import solve_buckling
    from beamfx.analyses.modal import solve_modes

    spec = load_scene(default_scene_path()).model

    def run(comm):
        model = BeamModel(spec, comm)
        buckling = solve_buckling(model, n_modes=2).load_factors
        solve_static(model, steps=4)
        return np.concatenate([solve_modes(model, n_modes=4).hz, buckling])

    serial, parallel = _serial_and_parallel(run)
    assert np.allclose(parallel, serial, rtol=1e-8), (parallel, serial)


def test_transient_matches_serial():
    """A short transient of a 3D cantilever (quaternions, generalized-α, a load pulse): the
    tip after 40 steps is the same from 1 and 2 ranks (Newton converges to ~1e-10)."""
    from scenekit import cantilever

    from beamfx.analyses.transient import TransientSettings, solve_transient

    spec = cantilever(elements=4)
    settings = TransientSettings(t_end=0.04, dt=0.001, rho_inf=0.8, checkpoint_every=0)

    def run(comm):
        model = BeamModel(spec, comm, extra_points=["b:end"])
        result = solve_transient(model, settings)
        tip = evaluate_points(model, ["b:end"])["b:end"]
        energy = result.steps[-1].energy
        return np.concatenate([tip["position"], tip["rotation_vector"], [energy["kinetic"]]])

    serial, parallel = _serial_and_parallel(run)
    assert np.allclose(parallel, serial, rtol=1e-8, atol=1e-10), (parallel, serial)


@pytest.mark.parametrize(
    "values", [[[0, 0, 150], [0, 0, 300], [0, 0, 600]], [[0, 0, 600]]], ids=["3-members", "1"]
)
def test_sweep_ensemble_matches_serial(values, shared_folder):
    """A sweep on split communicators (3 members: groups of one rank; 1 member: one group of
    all ranks) gives the probes each member's scene gives on one process."""
    import json

    from beamfx.runner import run_scene
    from beamfx.scene import parse_sweep
    from beamfx.sweep import run_sweep

    data = {**load_scene_data(), "sweep": [{"key": "loads[0].force", "values": values}]}
    data["model"] = {"condense": "none"}  # the quaternion model (the condensed one: above)
    sweep = parse_sweep(json.loads(json.dumps(data)), "sweep.toml")
    folder = shared_folder
    table = run_sweep(sweep, folder / "ensemble", run_scene)
    assert table["groups"] == min(len(values), MPI.COMM_WORLD.size)
    for row, member in zip(table["members"], sweep.members):
        assert row["status"] == "converged"
        assert row["ranks"] == MPI.COMM_WORLD.size // table["groups"]
        alone = run_scene(
            "alone.toml",
            folder / f"alone_{member.index}_rank{MPI.COMM_WORLD.rank}",  # each rank alone
            comm=MPI.COMM_SELF,
            scene=member.scene,
        )
        for what in ("displacement", "rotation_vector"):
            a, b = np.asarray(row["probes"]["tip"][what]), np.asarray(alone["probes"]["tip"][what])
            assert np.allclose(a, b, rtol=1e-9, atol=1e-9 * np.abs(b).max()), (what, a, b)


def load_scene_data():
    import tomllib

    return tomllib.loads(default_scene_path().read_text())


@pytest.mark.parametrize("solver", ["direct", "iterative"])
def test_solid_matches_serial(solver):
    """The 3D solid of SM 2.1 (2 x 4 x 25 Q2 hexahedra) from 1 and 2 ranks: MUMPS, and CG +
    GAMG (whose preconditioner depends on the partition, converged to rtol 1e-10)."""
    from beamfx.bench import schwab_meijaard_2009 as sm
    from beamfx.bench._builders import straight
    from beamfx.solid.geometry import SolidMesh
    from beamfx.solid.solve import Solid, SolidSpec
    from beamfx.spec import Beam

    beam = Beam("b", straight(1.0), sm.S21, 1)
    loads = {"end": ((0, 0, sm.F), (sm.MX, sm.MY, 0))}
    spec = SolidSpec(beam, sm.E, sm.NU, loads=loads, mesh=SolidMesh(2), solver=solver)

    def run(comm):
        solid = Solid(spec, comm)
        solid.solve_static()
        tip = solid.face_values("end")
        return np.concatenate([tip["displacement"], tip["rotation_vector"]])

    serial, parallel = _serial_and_parallel(run)
    # Round-off, not the method, separates the two: MUMPS with another ordering differs by a
    # few 1e-9 here (the thin solid's stiffness is ill-conditioned), CG stops at 1e-10 of the
    # residual with a partition-dependent preconditioner; a lost ghost update would be O(1).
    assert np.allclose(parallel, serial, rtol=1e-7, atol=1e-7 * np.abs(serial).max())


def _docs_scene(analysis):
    """The first complete scene of docs/scenes.md with ``[analysis] type = analysis``."""
    import re
    from pathlib import Path

    text = (Path(__file__).resolve().parents[2] / "docs" / "scenes.md").read_text()
    for body in re.findall(r"^```toml\n(.*?)^```$", text, re.MULTILINE | re.DOTALL):
        if re.search(rf'^type = "{analysis}"', body, re.MULTILINE) and "[[sweep]]" not in body:
            return body
    raise AssertionError(f"docs/scenes.md has no {analysis} scene")


@pytest.mark.parametrize("analysis", ["arclength", "rotating", "buckling", "linear_static"])
def test_documented_scene_runs_the_same_on_all_ranks(analysis, shared_folder):
    """``beamfx run`` of the documented scene of each analysis from one process and from all
    ranks: the same probes and, where the analysis has them, the same eigenvalues and path."""
    import tomllib

    from beamfx.runner import run_scene
    from beamfx.scene import parse_scene

    scene = parse_scene(tomllib.loads(_docs_scene(analysis)), f"{analysis}.toml")
    folder = shared_folder
    rank = MPI.COMM_WORLD.rank
    serial = run_scene("s.toml", folder / f"serial{rank}", comm=MPI.COMM_SELF, scene=scene)
    parallel = run_scene("s.toml", folder / "parallel", scene=scene)
    for key in ("frequencies_hz", "load_factors"):
        if key in serial:
            assert np.allclose(parallel[key], serial[key], rtol=1e-8), key
    if "path" in serial:  # load factors (or a rotating run's speeds) and the probes along it
        key = "speed_rad_s" if serial["analysis"] == "rotating" else "load_factor"
        a = np.array([p[key] for p in parallel["path"]])
        b = np.array([p[key] for p in serial["path"]])
        assert a.shape == b.shape and np.allclose(a, b, rtol=1e-8, atol=1e-10)
    for name, probe in serial["probes"].items():
        for what in ("position", "rotation_vector"):
            a, b = np.asarray(parallel["probes"][name][what]), np.asarray(probe[what])
            assert np.allclose(a, b, rtol=1e-8, atol=1e-8 * max(1.0, np.abs(b).max())), (name, a, b)
