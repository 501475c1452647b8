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


@pytest.mark.parametrize("follower", [False, True])
def test_bend45_probes_match_serial(follower):
    from dataclasses import replace

    spec = load_scene(default_scene_path()).model
    kind = "follower" if follower else "dead"
    spec = replace(spec, point_loads=tuple(replace(p, kind=kind) for p in spec.point_loads))
    out = {}
    for comm in (MPI.COMM_SELF, MPI.COMM_WORLD):
        model = BeamModel(spec, comm, extra_points=["bend:end", "bend:0.5"])
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
