"""Run under ``mpirun -n 2``: the transient reactions series (reactions.csv) of a 3D spin-up
(quaternions) from all ranks equals the one from a single process, row by row."""

import csv
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI
from scenekit import SPIN_HISTORY, spun_beam

from beamfx.runner import run_scene

pytestmark = pytest.mark.mpi


def _series(folder):
    with (folder / "reactions.csv").open() as f:
        rows = list(csv.DictReader(f))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def test_reaction_series_of_all_ranks_is_that_of_one(tmp_path_factory):
    scene = spun_beam(SPIN_HISTORY, 0.3, dt=0.01).replace(
        "dt = 0.01", "dt = 0.01\noutput_every = 3"
    )
    comm = MPI.COMM_WORLD
    base = Path(comm.bcast(str(tmp_path_factory.mktemp("spin")) if comm.rank == 0 else None))
    if comm.rank == 0:
        (base / "spin.toml").write_text(scene)
    comm.barrier()
    quiet = {"log": lambda m: None}
    parallel = run_scene(base / "spin.toml", base / "all", comm=comm, **quiet)
    serial = run_scene(base / "spin.toml", base / f"one{comm.rank}", comm=MPI.COMM_SELF, **quiet)
    a, b = _series(base / "all"), _series(base / f"one{comm.rank}")
    assert list(a) == list(b) and len(a["step"]) == 10
    scale = np.abs(b["inertia_f_x"]).max() + np.abs(b["inertia_f_y"]).max()
    for key in a:
        if key in ("balance_force", "balance_moment", "free_residual"):
            continue  # Newton's stopping point: round-off, not the same digits
        tol = 1e-9 * scale * (10 if key.endswith(("_mx", "_my", "_mz")) else 1)
        assert np.allclose(a[key], b[key], rtol=1e-9, atol=tol), (key, a[key], b[key])
    for run, series in ((parallel, a), (serial, b)):  # the bound of test_transient_reactions
        gap = [series[f"beam:start_f{c}"] - series[f"inertia_f_{c}"] for c in "xyz"]
        bound = np.sqrt(run["model"]["unknowns"]) * series["free_residual"] + 1e-13 * scale
        assert np.all(np.linalg.norm(gap, axis=0) <= bound)
        assert run["reaction_history"]["rows"] == 10
    assert parallel["reactions"].keys() == serial["reactions"].keys() == {"beam:start"}
