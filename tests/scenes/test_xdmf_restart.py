"""The XDMF series of a restarted transient holds the earlier run's frames up to the
checkpoint, as the .pvd series does (it started at the checkpoint's time: 428 grids from
t = 4.92 against 715 from t = 0 uninterrupted).

A spin-up run to 0.05 s and restarted to 0.1 s is compared with one run to 0.1 s: the same
frame times, and the same values of every array at each (read back through VTK's XDMF reader,
which follows the data items into the .h5 files) to 1e-12 of their size: the restarted march
repeats the same floating-point operations. A killed run (its frames went on past the last
checkpoint) is made by putting an earlier checkpoint back after a restart to the end: the
restarted frames of those times cannot be written into the .h5 that holds them (HDF5 refuses
a data set that exists), so that file becomes deformed.part1.h5, read by the same
deformed.xdmf, which is again equal to the whole run's; a fresh run removes it.
"""

import re
import shutil

import numpy as np
import pytest
from scenekit import spun_beam

from beamfx.runner import run_scene

OUTPUT = '\n[output]\nformats = ["vtu", "xdmf"]\nevery = 2\n'


def scene(t_end):
    return spun_beam("4 * t**2", t_end, checkpoint_every=3) + OUTPUT


def frames(folder):
    """{time: {array: values}} of ``folder``/deformed.xdmf, read by VTK."""
    import vtk
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline as sddp

    reader = vtk.vtkXdmfReader()
    reader.SetFileName(str(folder / "deformed.xdmf"))
    reader.UpdateInformation()
    out = {}
    for t in reader.GetOutputInformation(0).Get(sddp.TIME_STEPS()):
        reader.UpdateTimeStep(t)
        blocks = reader.GetOutputDataObject(0)
        out[t] = {}
        for i in range(blocks.GetNumberOfBlocks()):
            name = blocks.GetMetaData(i).Get(blocks.NAME())
            data = blocks.GetBlock(i).GetPointData().GetArray(name)
            if data is not None:  # (the mesh block has none)
                out[t][name] = vtk_to_numpy(data).copy()
    return out


def grids(folder):
    """The frame times of deformed.xdmf as written (one per array and frame)."""
    return re.findall(r'<Time Value="([^"]+)"', (folder / "deformed.xdmf").read_text())


def assert_same(a, b):
    assert list(a) == pytest.approx(list(b), rel=1e-12)
    for ta, tb in zip(a, b):
        assert a[ta].keys() == b[tb].keys() and "u" in a[ta]
        for name, x in a[ta].items():
            scale = max(1.0, float(np.max(np.abs(x))))
            np.testing.assert_allclose(b[tb][name], x, rtol=0, atol=1e-12 * scale, err_msg=name)


@pytest.fixture(scope="module")
def whole(tmp_path_factory):
    root = tmp_path_factory.mktemp("whole")
    (root / "a.toml").write_text(scene(0.1))
    run_scene(root / "a.toml", root / "out", log=lambda m: None)
    return root / "out"


def test_a_restarted_xdmf_series_equals_the_whole_runs(whole, tmp_path):
    (tmp_path / "a.toml").write_text(scene(0.1))
    (tmp_path / "b.toml").write_text(scene(0.05))
    quiet = {"log": lambda m: None}
    run_scene(tmp_path / "b.toml", tmp_path / "out", **quiet)
    run_scene(tmp_path / "a.toml", tmp_path / "out", restart=True, **quiet)
    assert grids(tmp_path / "out") == grids(whole)
    assert_same(frames(whole), frames(tmp_path / "out"))
    assert sorted(p.name for p in (tmp_path / "out").glob("deformed*.h5")) == ["deformed.h5"]


def test_frames_past_the_checkpoint_of_a_killed_run_are_replaced(whole, tmp_path):
    (tmp_path / "a.toml").write_text(scene(0.1))
    (tmp_path / "b.toml").write_text(scene(0.05))
    out, notes = tmp_path / "out", []
    run_scene(tmp_path / "b.toml", out, log=lambda m: None)
    shutil.copy(out / "checkpoint_1ranks_0.npz", tmp_path / "at_0.05.npz")
    run_scene(tmp_path / "a.toml", out, restart=True, log=lambda m: None)
    shutil.copy(tmp_path / "at_0.05.npz", out / "checkpoint_1ranks_0.npz")  # killed past it
    run_scene(tmp_path / "a.toml", out, restart=True, log=notes.append)
    assert any("XDMF:" in n and "deformed.part1.h5" in n for n in notes), notes
    assert sorted(p.name for p in out.glob("deformed*.h5")) == ["deformed.h5", "deformed.part1.h5"]
    assert grids(out) == grids(whole)
    assert_same(frames(whole), frames(out))
    run_scene(tmp_path / "a.toml", out, log=lambda m: None)  # a fresh run: one .h5 again
    assert sorted(p.name for p in out.glob("deformed*.h5")) == ["deformed.h5"]


def test_an_unreadable_earlier_xdmf_file_is_set_aside_not_lost(tmp_path):
    """A deformed.xdmf cut short (a run killed while DOLFINx rewrote it) cannot be continued:
    it and its .h5 are kept as deformed.before_restart.*, the series starts afresh ("w"),
    and the note says so; without an earlier file the series simply starts ("w", no note)."""
    from beamfx.io.xdmf import _resume_file

    path = tmp_path / "deformed.xdmf"
    assert _resume_file(str(path), 1.0, True) == ("w", None)
    path.write_text('<?xml version="1.0"?>\n<Xdmf Version="3.0">\n  <Domain>\n    <Grid Na')
    (tmp_path / "deformed.h5").write_bytes(b"frames")
    mode, note = _resume_file(str(path), 1.0, True)
    assert mode == "w" and "cannot be continued" in note
    assert "deformed.before_restart.xdmf and deformed.before_restart.h5" in note
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "deformed.before_restart.h5",
        "deformed.before_restart.xdmf",
    ]
    assert (tmp_path / "deformed.before_restart.h5").read_bytes() == b"frames"
