"""Run under ``mpirun -n 2``: the frames of 2 ranks are pieces that, merged and put in the
order of the input cell index, equal the frame of 1 rank; each rank wrote its own piece.

The half-circle roll-up (tests/unit/test_io.py) with a rectangular section is solved on one rank
(COMM_SELF) and on all; the two solutions agree to the solver's tolerance, so the files are
compared with the tolerance of tests/mpi/test_mpi.py (1e-9 relative).
"""

import os
from dataclasses import replace

import numpy as np
import pytest
from mpi4py import MPI
from scenekit import SECTION, rollup_model

from beamfx.analyses.static import solve_static
from beamfx.io import FrameWriter, OutputSettings

pytestmark = pytest.mark.mpi
comm = MPI.COMM_WORLD
RTOL = 1e-9


def _write(folder, comm_):
    """Solve the half circle on ``comm_`` and write its frame 1 into ``folder``; returns the
    input indices of the cells this rank owns."""
    model, _ = rollup_model(0.5, comm_)
    solve_static(model, steps=4)
    section = replace(SECTION, shape=("rectangle", 0.2, 0.1))
    beams = tuple(replace(b, section=section) for b in model.spec.beams)
    writer = FrameWriter(folder, model, OutputSettings(), beams, comm_)
    writer.write(1, 1.0)
    writer.close()
    m = model.mesh.mesh
    owned = m.topology.index_map(1).size_local
    return np.sort(np.asarray(m.topology.original_cell_index[:owned]))


def _by_cell(path):
    """{input cell index: (points of its cells in order, point arrays there)} of one file."""
    import pyvista as pv

    grid = pv.read(path)
    offsets, conn = np.asarray(grid.cell_offsets), np.asarray(grid.cell_connectivity)
    out = {}
    for c, index in enumerate(np.asarray(grid.cell_data["cell"])):
        ids = conn[offsets[c] : offsets[c + 1]]
        pts, data = out.setdefault(int(index), ([], {k: [] for k in grid.point_data}))
        pts.append(np.asarray(grid.points)[ids])
        for k in data:
            data[k].append(np.asarray(grid.point_data[k])[ids])
    return out


def _assert_same(parallel, serial):
    """Equal to round-off and the solver's tolerance, relative to each quantity's size in the
    whole frame (N and M together: N vanishes in the roll-up, its size is that of M)."""
    assert sorted(parallel) == sorted(serial)

    def size(k):
        keys = ("N", "M") if k in ("N", "M") else (k,)
        return max(
            1.0, *(np.abs(np.concatenate(d[j])).max() for _, d in serial.values() for j in keys)
        )

    x_size = max(np.abs(np.concatenate(p)).max() for p, _ in serial.values())
    for index, (pts, data) in serial.items():
        p_pts, p_data = parallel[index]
        assert np.allclose(np.concatenate(p_pts), np.concatenate(pts), rtol=0, atol=RTOL * x_size)
        for k, v in data.items():
            v, w = np.concatenate(v), np.concatenate(p_data[k])
            assert np.allclose(w, v, rtol=0, atol=RTOL * size(k)), (k, index)


@pytest.mark.skipif(comm.size == 1, reason="needs mpirun -n 2 or more")
def test_pieces_merged_equal_the_one_rank_frame(tmp_path):
    root = comm.bcast(str(tmp_path), root=0)
    serial = os.path.join(root, f"serial_{comm.rank}")  # every rank solves alone
    parallel = os.path.join(root, "parallel")
    os.makedirs(serial)
    if comm.rank == 0:
        os.makedirs(parallel)
    _write(serial, MPI.COMM_SELF)
    comm.barrier()
    owned = _write(parallel, comm)

    # each rank wrote its own piece, of the cells it owns: nothing went through rank 0
    for stem in ("deformed", "surface"):
        mine = _by_cell(os.path.join(parallel, f"{stem}_0001_{comm.rank}.vtu"))
        assert np.array_equal(sorted(mine), owned), stem
    assert 0 < len(owned) < comm.allreduce(len(owned))
    comm.barrier()
    if comm.rank != 0:
        return
    for stem in ("deformed", "surface"):
        assert not os.path.exists(os.path.join(parallel, f"{stem}_0001.vtu"))
        merged = _by_cell(os.path.join(parallel, f"{stem}_0001.pvtu"))
        _assert_same(merged, _by_cell(os.path.join(serial, f"{stem}_0001.vtu")))
