"""The XDMF series of a restarted transient on 2 ranks keeps the frames before the checkpoint
(tests/scenes/test_xdmf_restart.py on one rank): a run to 0.05 s restarted to 0.1 s, and
then, with the checkpoint of 0.05 s put back (a run killed past its last checkpoint), again:
deformed.xdmf holds the frame times of a run never interrupted, the second time reading the
frames before the checkpoint from deformed.part1.h5 (rank 0 edits the file, every rank
appends to it)."""

import re
import shutil

import pytest
from mpi4py import MPI
from scenekit import spun_beam

from beamfx.runner import run_scene

pytestmark = pytest.mark.mpi


def scene(t_end):
    return spun_beam("4 * t**2", t_end, checkpoint_every=3) + (
        '\n[output]\nformats = ["vtu", "xdmf"]\nevery = 2\n'
    )


def times(folder):
    return re.findall(r'<Time Value="([^"]+)"', (folder / "deformed.xdmf").read_text())


def test_a_restarted_xdmf_series_on_two_ranks_keeps_the_earlier_frames(shared_folder):
    comm, root = MPI.COMM_WORLD, shared_folder
    if comm.rank == 0:
        (root / "a.toml").write_text(scene(0.1))
        (root / "b.toml").write_text(scene(0.05))
    comm.barrier()
    quiet, notes = {"log": lambda m: None}, []
    run_scene(root / "a.toml", root / "whole", **quiet)
    out = root / "out"
    run_scene(root / "b.toml", out, **quiet)
    if comm.rank == 0:
        for r in range(2):
            shutil.copy(out / f"checkpoint_2ranks_{r}.npz", root / f"at_0.05_{r}.npz")
    comm.barrier()
    run_scene(root / "a.toml", out, restart=True, **quiet)
    if comm.rank == 0:
        assert times(out) == times(root / "whole")
        for r in range(2):
            shutil.copy(root / f"at_0.05_{r}.npz", out / f"checkpoint_2ranks_{r}.npz")
    comm.barrier()
    run_scene(root / "a.toml", out, restart=True, log=notes.append)
    if comm.rank == 0:
        assert times(out) == times(root / "whole")
        assert any("deformed.part1.h5" in n for n in notes), notes
        assert (out / "deformed.part1.h5").exists() and (out / "deformed.h5").exists()
