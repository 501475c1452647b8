"""Run under ``mpirun -n 2``: the support reactions of a frame are the same from all ranks as
from one process (each rank sums its owned dofs; the sums are reduced)."""

import tomllib

import numpy as np
import pytest
from mpi4py import MPI

from beamfx.analyses.model import BeamModel
from beamfx.analyses.reactions import entries
from beamfx.analyses.static import solve_static
from beamfx.scene.load import parse_scene

pytestmark = pytest.mark.mpi

FRAME = """
[material]
E = 210e9
nu = 0.3
rho = 7850
[[beams]]
name = "left"
curve = { shape = "line", start = [0, 0, 0], end = [0, 0, 3] }
section = { type = "rectangle", h = 0.2, w = 0.1 }
elements = 6
[[beams]]
name = "top"
curve = { shape = "line", start = [0, 0, 3], end = [4, 1, 3] }
section = { type = "rectangle", h = 0.2, w = 0.1 }
orientation = [0, 0, 1]
elements = 6
[[beams]]
name = "right"
curve = { shape = "line", start = [4, 1, 3], end = [4, 1, 0] }
section = { type = "rectangle", h = 0.2, w = 0.1 }
elements = 6
[[supports]]
at = "left:start"
fix = "all"
[[supports]]
at = "right:end"
fix = "pinned"
[[springs]]
at = "top:0.5"
stiffness = [0, 1e6, 0]
[[loads]]
at = "top:0.25"
force = [2e4, 3e3, -5e4]
moment = [0, 1e3, 0]
[[loads]]
gravity = [0, 0, -9.81]
[model]
kinematics = "KIN"
plane = "none"
"""


@pytest.mark.parametrize("kin", ["linear", "finite"])
def test_frame_reactions_match_serial(kin):
    spec = parse_scene(tomllib.loads(FRAME.replace("KIN", kin))).model
    out = {}
    for comm in (MPI.COMM_SELF, MPI.COMM_WORLD):
        model = BeamModel(spec, comm)
        solve_static(model, steps=2)
        out[comm.size] = entries(model)
    parallel, serial = out[MPI.COMM_WORLD.size], out[1]
    assert set(parallel["reactions"]) == {"left:start", "right:end", "top:0.5"}
    for at, r in serial["reactions"].items():
        for key in ("force", "moment", "position"):
            a, b = np.asarray(parallel["reactions"][at][key]), np.asarray(r[key])
            assert np.allclose(a, b, rtol=1e-9, atol=1e-9 * 6e4), (at, key, a, b)
    for result in (serial, parallel):
        assert result["reaction_balance"]["force"] < 1e-9
        assert result["reaction_balance"]["moment"] < 1e-9


@pytest.mark.parametrize("name", ["tower", "dome", "lattice"])
def test_demo_frames_match_serial_and_the_exact_frame(name):
    """The demo frames, linear: point loads at joints of many elements (the joint density
    on an element that may sit on either rank) and the reactions of 4 or 12 supports."""
    from pathlib import Path

    from beamfx.bench import frame_peers, frame_stiffness
    from beamfx.scene import load_scene

    demos = Path(__file__).resolve().parents[2] / "demos" / "scenes"
    spec = frame_peers.linear_frame(load_scene(demos / f"{name}.toml").model)
    exact, exact_r = frame_stiffness.solve(frame_stiffness.problem_from_model(spec))
    for comm in (MPI.COMM_SELF, MPI.COMM_WORLD):
        u, reactions, _ = frame_peers.beamfx_frame(spec, comm)
        assert max(frame_peers.differences(u, reactions, exact, exact_r)) < 1e-8, comm.size


def test_tower_scene_runs_on_two_ranks_with_the_reactions_of_one(tmp_path_factory):
    """The whole ``beamfx run`` of the 96-member tower (probes, ParaView frames, results.json)
    on all ranks and on one process: the same reactions and probes."""
    from pathlib import Path

    from beamfx.runner import run_scene

    scene = Path(__file__).resolve().parents[2] / "demos" / "scenes" / "tower.toml"
    comm = MPI.COMM_WORLD
    base = Path(comm.bcast(str(tmp_path_factory.mktemp("tower")) if comm.rank == 0 else None))
    parallel = run_scene(scene, base / "all", log=lambda m: None, comm=comm)
    serial = run_scene(scene, base / f"one{comm.rank}", log=lambda m: None, comm=MPI.COMM_SELF)
    for at, r in serial["reactions"].items():
        for key in ("force", "moment"):
            a, b = np.asarray(parallel["reactions"][at][key]), np.asarray(r[key])
            assert np.allclose(a, b, rtol=1e-9, atol=1e-9 * 4e4), (at, key, a, b)
    for name, p in serial["probes"].items():
        a, b = parallel["probes"][name]["displacement"], p["displacement"]
        assert np.allclose(a, b, rtol=1e-8, atol=1e-12), name


@pytest.mark.parametrize("planar", [False, True])
def test_condensed_reaction_balance_matches_serial(planar):
    """The statically condensed model's reactions and balance (its load points' unknowns
    from the ranks that own them) are the same on every rank and as from one process: the
    spatial model under loads of every kind, the planar one under a tip follower force."""
    from dataclasses import replace

    from scenekit import CONDENSED_LOADS

    from beamfx.analyses.planar_condensed import build_model
    from beamfx.physics.kinematics import Kinematics
    from beamfx.spec import PointLoad

    spec = parse_scene(tomllib.loads(CONDENSED_LOADS)).model
    if planar:
        tip = PointLoad("b:end", (0.0, 0.0, 6e4), (0.0, -3e4, 0.0), "follower")
        spec = replace(spec, point_loads=(tip,), kinematics=Kinematics(plane="xz"))
    out = {}
    for comm in (MPI.COMM_SELF, MPI.COMM_WORLD):
        model = build_model(spec, comm, condense=True)
        solve_static(model, steps=4)
        out[comm.size] = entries(model)
    parallel, serial = out[MPI.COMM_WORLD.size], out[1]
    every = MPI.COMM_WORLD.allgather(parallel)
    assert all(e == parallel for e in every)  # the same entries on every rank
    bal, ser = parallel["reaction_balance"], serial["reaction_balance"]
    scale = np.linalg.norm(ser["applied_force"]) * 2.0  # force × length
    for key, s in (("applied_force", scale / 2), ("applied_moment", scale)):
        assert np.allclose(bal[key], ser[key], rtol=0, atol=1e-10 * s), key
    r, rs = parallel["reactions"]["b:start"], serial["reactions"]["b:start"]
    assert np.allclose(r["force"], rs["force"], rtol=0, atol=1e-10 * scale)
    assert np.allclose(r["moment"], rs["moment"], rtol=0, atol=1e-10 * scale)
    assert bal["force"] < 1e-14 and bal["moment"] < 1e-3
    assert bal["moment"] == pytest.approx(ser["moment"], rel=1e-4)
