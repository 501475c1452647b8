"""Run under ``mpirun -n 2``: the reactions series and ``reactions.csv`` of a static run are
written by rank 0 alone (one ``.vtu`` per frame, no pieces) and hold the reduced reactions of
results.json, the same on every rank."""

import csv
import json
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI
from test_reactions_mpi import FRAME

from beamfx.runner import run_scene

pytestmark = pytest.mark.mpi
comm = MPI.COMM_WORLD


def test_reaction_frames_are_written_by_rank_0(tmp_path):
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

    folder = Path(comm.bcast(str(tmp_path), root=0))
    if comm.rank == 0:
        text = FRAME.replace("KIN", "finite") + '[analysis]\ntype = "static"\nsteps = 2\n'
        (folder / "scene.toml").write_text(text)
    comm.barrier()
    out = folder / "out"
    run = run_scene(folder / "scene.toml", out, log=lambda message: None)
    everywhere = comm.allgather(json.dumps(run["reactions"], sort_keys=True))
    assert len(set(everywhere)) == 1
    comm.barrier()
    if comm.rank != 0:
        return
    assert sorted(p.name for p in out.glob("reactions_*")) == [
        "reactions_0001.vtu",
        "reactions_0002.vtu",
    ]
    with (out / "reactions.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 2
    names = list(run["reactions"])
    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(out / "reactions_0002.vtu"))
    reader.Update()
    grid = reader.GetOutput()
    force = vtk_to_numpy(grid.GetPointData().GetArray("force"))
    points = vtk_to_numpy(grid.GetPoints().GetData())
    for i, at in enumerate(names):  # the frame's doubles are results.json's
        r = run["reactions"][at]
        assert np.array_equal(force[i], r["force"]) and np.array_equal(points[i], r["position"])
        scale = np.abs(r["force"]).max()
        csv_force = [float(rows[-1][f"{at}_f{c}"]) for c in "xyz"]
        assert np.allclose(csv_force, r["force"], rtol=0, atol=1e-11 * scale)
