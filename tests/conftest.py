import os
import textwrap
from pathlib import Path

os.environ.setdefault("SETUPTOOLS_USE_DISTUTILS", "stdlib")

import numpy as np
import pytest

from beamfx.io.vtkfiles import OutputUnavailable, import_vtk

try:  # VTK's wheel before DOLFINx in one process (the frame writers use it)
    import_vtk()
except OutputUnavailable:
    pass


def nodal(model, sub):
    """Coordinates and values (n, comps) of the displacement (0) or rotation (1) nodes."""
    V, dofs = model.W.sub(sub).collapse()
    X = V.tabulate_dof_coordinates()
    return X, model.w.x.array[dofs].reshape(len(X), -1), dofs


def value_at(model, sub, xyz):
    """Nodal value nearest to ``xyz`` (local to this rank)."""
    X, vals, _ = nodal(model, sub)
    i = np.argmin(np.linalg.norm(X - np.asarray(xyz), axis=1))
    return X[i], vals[i]


@pytest.fixture
def shared_folder(tmp_path):
    """One folder for all ranks of the communicator (pytest's tmp_path differs between them):
    rank 0's, removed after the test (with all ranks done)."""
    from mpi4py import MPI

    comm = MPI.COMM_WORLD
    name = comm.bcast(str(tmp_path / "shared") if comm.rank == 0 else None)
    if comm.rank == 0:
        os.makedirs(name, exist_ok=True)
    comm.barrier()
    yield Path(name)
    comm.barrier()


@pytest.fixture
def tmp_out(tmp_path):
    return tmp_path / "out"


@pytest.fixture
def scene_file(tmp_path):
    """Write a scene text into the test's folder: ``scene_file(text, name="scene.toml") -> Path``."""

    def write(text, name="scene.toml"):
        path = tmp_path / name
        path.write_text(textwrap.dedent(text))
        return path

    return write
