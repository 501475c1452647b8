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


XDMF = """<?xml version="1.0"?>
<Xdmf Version="3.0" xmlns:xi="http://www.w3.org/2001/XInclude">
  <Domain>
    <Grid Name="mesh" GridType="Uniform">
      <Geometry GeometryType="XYZ">
        <DataItem Dimensions="3 3" Format="HDF">deformed.h5:/Mesh/mesh/geometry</DataItem>
      </Geometry>
    </Grid>
    <Grid Name="u" GridType="Collection" CollectionType="Temporal">{grids}
    </Grid>
  </Domain>
</Xdmf>
"""
GRID = """
      <Grid Name="u" GridType="Uniform">
        <xi:include xpointer="xpointer(/Xdmf/Domain/Grid[@GridType='Uniform'][1]/*)" />
        <Time Value="{t!r}" />
        <Attribute Name="u" AttributeType="Vector" Center="Node">
          <DataItem Dimensions="3 3" Format="HDF">deformed.h5:/Function/u/{t!r}</DataItem>
        </Attribute>
      </Grid>"""


@pytest.mark.parametrize("t_max, inclusive, kept, part", [
    (0.2, True, [0.0, 0.1, 0.2], True),  # frames past the checkpoint: a killed run
    (0.3, False, [0.0, 0.1, 0.2], False),  # the frame where it stopped, off the grid: dropped
    (0.3, True, [0.0, 0.1, 0.2, 0.3], False),
])  # fmt: skip
def test_the_xml_is_cut_back_to_the_checkpoint(tmp_path, t_max, inclusive, kept, part):
    """The grids up to the checkpoint stay; with grids past it, the .h5 becomes part1 and
    every data item (the mesh's too) reads it; the XInclude prefix stays declared."""
    import xml.etree.ElementTree as ET

    from beamfx.io.xdmf import _resume_file

    path = tmp_path / "deformed.xdmf"
    path.write_text(XDMF.format(grids="".join(GRID.format(t=t) for t in (0.0, 0.1, 0.2, 0.3))))
    (tmp_path / "deformed.h5").write_bytes(b"frames")
    mode, note = _resume_file(str(path), t_max, inclusive)
    assert mode == "a" and (note is not None) == part
    text = path.read_text()
    assert [float(t) for t in re.findall(r'<Time Value="([^"]+)"', text)] == kept
    root = ET.fromstring(text)  # well-formed, xi declared
    assert root.find("Domain") is not None and 'xmlns:xi="http' in text
    items = [d.text for d in root.iter("DataItem")]
    h5 = "deformed.part1.h5" if part else "deformed.h5"
    assert len(items) == 1 + len(kept) and all(d.startswith(f"{h5}:/") for d in items)
    assert (tmp_path / h5).read_bytes() == b"frames"
    assert (tmp_path / "deformed.h5").exists() == (not part)


def test_nothing_to_keep_starts_the_file_afresh(tmp_path):
    """No frame up to t_max (the condensed model's frames when the full one takes over,
    resume(0)): mode "w", the file replaced at the first frame, no part file."""
    from beamfx.io.xdmf import _resume_file

    path = tmp_path / "deformed.xdmf"
    path.write_text(XDMF.format(grids="".join(GRID.format(t=t) for t in (0.1, 0.2))))
    (tmp_path / "deformed.h5").write_bytes(b"frames")
    assert _resume_file(str(path), 0.0, True) == ("w", None)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["deformed.h5", "deformed.xdmf"]
