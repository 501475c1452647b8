"""Reactions in the streamed and ParaView output (issue 19): ``reactions.csv`` of static and
arc-length runs (the transient's columns without the inertia), and the ``reactions.pvd``
series (one vertex per support, point arrays ``force`` and ``moment``) at the frames of the
deformed series, for static, arc-length and transient runs.

Tolerances: the CSV holds 12 significant digits ("{:.12g}"), so a cell equals its value in
results.json to 1e-12 relative to the largest of its kind (atol = 1e-11·max |value| covers the
rounding with margin); the VTU frames hold the doubles themselves (binary), so they equal
results.json exactly.
"""

import csv
import json

import numpy as np
import pytest
from test_reactions import CANTILEVER, _quiet
from test_transient_reactions import CANTILEVER as SHAKEN_CANTILEVER

from beamfx.runner import run_scene


def csv_rows(folder):
    """reactions.csv as a list of {column: float}."""
    with (folder / "reactions.csv").open() as f:
        return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]


def pvd_frames(path):
    """[(time, file)] of a ``.pvd`` index."""
    import xml.etree.ElementTree as ET

    root = ET.parse(path).getroot()
    return [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")]


def read_vtu(path):
    """(points, {array: values}) of a ``.vtu`` read by VTK's XML reader."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    grid = reader.GetOutput()
    pd = grid.GetPointData()
    arrays = {
        pd.GetArrayName(i): vtk_to_numpy(pd.GetArray(i)) for i in range(pd.GetNumberOfArrays())
    }
    return vtk_to_numpy(grid.GetPoints().GetData()), arrays


def row_reactions(row, points):
    """{point: (force, moment, position)} of a CSV row."""
    return {
        at: tuple(np.array([row[f"{at}_{k}{c}"] for c in "xyz"]) for k in ("f", "m", ""))
        for at in points
    }


def assert_row_equals(row, reactions):
    """A CSV row's reactions equal results.json's (12 significant digits)."""
    for at, (f, m, x) in row_reactions(row, list(reactions)).items():
        r = reactions[at]
        scale = max(np.abs(r["force"]).max(), np.abs(r["moment"]).max(), 1.0)
        for got, want in ((f, r["force"]), (m, r["moment"]), (x, r["position"])):
            assert np.allclose(got, want, rtol=0, atol=1e-11 * scale)


def assert_frame_equals(folder, file, reactions):
    """A reactions frame holds a vertex per point at its position with its force and moment,
    exactly (binary doubles)."""
    points, arrays = read_vtu(folder / file)
    assert set(arrays) == {"force", "moment"}
    names = list(reactions)
    assert np.array_equal(points, [reactions[at]["position"] for at in names])
    assert np.array_equal(arrays["force"], [reactions[at]["force"] for at in names])
    assert np.array_equal(arrays["moment"], [reactions[at]["moment"] for at in names])


@pytest.mark.parametrize("kin", ["linear", "finite"])
def test_static_cantilever_streams_its_reactions(scene_file, tmp_path, kin):
    """A row of reactions.csv per load step equal to the path's reactions in results.json,
    and a reactions frame at every deformed frame (same times) holding them."""
    text = CANTILEVER.replace("KIN", kin).replace("CONDENSE", "none")
    out = tmp_path / "out"
    run = run_scene(scene_file(text), out, log=_quiet)
    saved = json.loads((out / "results.json").read_text())
    rows, path = csv_rows(out), saved["path"]
    assert len(rows) == len(path) == (1 if kin == "linear" else 2)
    for i, (row, point) in enumerate(zip(rows, path)):
        assert row["step"] == i + 1 and row["load_factor"] == point["load_factor"]
        assert_row_equals(row, point["reactions"])
    assert_row_equals(rows[-1], saved["reactions"])
    bal = saved["reaction_balance"]
    assert rows[-1]["balance_force"] == pytest.approx(bal["force"], rel=1e-11)
    assert np.allclose([rows[-1][f"applied_f_{c}"] for c in "xyz"], bal["applied_force"])
    assert "inertia_f_x" not in rows[0] and "free_residual" not in rows[0]
    frames = pvd_frames(out / "reactions.pvd")
    assert [t for t, _ in frames] == [t for t, _ in pvd_frames(out / "deformed.pvd")]
    for (t, file), point in zip(frames, path):
        assert t == point["load_factor"]
        assert_frame_equals(out, file, point["reactions"])
    assert run["paraview"]["reactions"] == "reactions.pvd"


def test_arclength_rows_and_frames_follow_the_path(tmp_path):
    """The shallow arch (built-in scene, 4 steps): a row and a frame per accepted point, equal
    to the path's reactions; the unloaded start has none."""
    from dataclasses import replace
    from importlib import resources

    from beamfx.scene import load_scene

    path = resources.files("beamfx") / "scenes" / "shallow_arch_snap.toml"
    scene = load_scene(path)
    scene = replace(scene, settings=replace(scene.settings, max_steps=4))
    out = tmp_path / "out"
    run_scene(path, out, log=_quiet, scene=scene)
    saved = json.loads((out / "results.json").read_text())
    points = [p for p in saved["path"] if "reactions" in p]
    rows = csv_rows(out)
    assert len(rows) == len(points) == 4
    for row, point in zip(rows, points):
        assert row["load_factor"] == pytest.approx(point["load_factor"], rel=1e-11)
        assert_row_equals(row, point["reactions"])
    frames = pvd_frames(out / "reactions.pvd")
    assert [t for t, _ in frames] == [t for t, _ in pvd_frames(out / "deformed.pvd")]
    assert len(frames) == len(points)
    for (_, file), point in zip(frames, points):
        assert_frame_equals(out, file, point["reactions"])


def test_transient_frames_hold_the_rows_of_their_steps(scene_file, tmp_path):
    """A transient's reactions frames are at its output steps (not at t = 0: no step has
    been taken), each equal to the row of reactions.csv at its time; a re-run without the
    format removes the earlier run's reactions series."""
    text = SHAKEN_CANTILEVER.replace("t_end = 0.1", "t_end = 0.02").replace(
        "output_every = 1", "output_every = 2"
    )
    out = tmp_path / "out"
    run_scene(scene_file(text), out, log=_quiet)
    rows = csv_rows(out)
    frames = pvd_frames(out / "reactions.pvd")
    deformed = [t for t, _ in pvd_frames(out / "deformed.pvd")]
    assert deformed[0] == 0.0 and [t for t, _ in frames] == deformed[1:]
    assert len(rows) == len(frames) == 4
    for row, (t, file) in zip(rows, frames):
        assert row["time"] == pytest.approx(t, rel=1e-11)
        points, arrays = read_vtu(out / file)
        names = ["b:start", "b:0.5"]
        for i, (f, m, x) in enumerate(row_reactions(row, names).values()):
            scale = max(np.abs(arrays["force"]).max(), np.abs(arrays["moment"]).max())
            assert np.allclose(arrays["force"][i], f, rtol=0, atol=1e-11 * scale)
            assert np.allclose(arrays["moment"][i], m, rtol=0, atol=1e-11 * scale)
            assert np.allclose(points[i], x, rtol=0, atol=1e-12)
    again = text + '[output]\nformats = ["vtu"]\n'
    run_scene(scene_file(again), out, log=_quiet)
    assert not list(out.glob("reactions*.vtu")) and not (out / "reactions.pvd").exists()
    assert (out / "reactions.csv").exists()  # the rows do not depend on the formats


def test_no_supports_no_reactions_series(tmp_path):
    """A format asked for where it has nothing to show (no supports, no springs) writes no
    series and names none in results.json."""
    from beamfx.io.output import FrameWriter, OutputSettings

    class Spec:
        supports, springs = (), ()

    class Model:
        spec, degree, comm = Spec(), 1, None

    from mpi4py import MPI

    writer = FrameWriter(
        tmp_path, Model(), OutputSettings(formats=("reactions",)), [], MPI.COMM_SELF
    )
    assert writer.reactions is None and "reactions" not in writer.files()
    writer.close()


def test_reaction_series_files_are_run_files(tmp_path):
    """reactions.pvd and its frames are a run's files: a fresh run removes the index, keeps
    the frames to write over in place, and a link of such a name is removed, never followed."""
    from beamfx.io.folder import FRAME_FILES, RUN_FILES, clear_earlier_run

    assert RUN_FILES.fullmatch("reactions.pvd") and RUN_FILES.fullmatch("reactions_0012.vtu")
    assert FRAME_FILES.fullmatch("reactions_0012.vtu") and not FRAME_FILES.fullmatch(
        "reactions.pvd"
    )
    assert not RUN_FILES.fullmatch("reactions_0012.pvtu")  # rank 0 alone writes them
    outside = tmp_path / "outside.txt"
    outside.write_text("keep me")
    out = tmp_path / "out"
    out.mkdir()
    (out / "reactions.pvd").write_text("old")
    (out / "reactions_0001.vtu").write_text("old")
    (out / "reactions_0002.vtu").symlink_to(outside)
    removed, frames = clear_earlier_run(out, restart=False)
    assert sorted(removed) == ["reactions.pvd", "reactions_0002.vtu"]
    assert list(frames) == ["reactions_0001.vtu"] and outside.read_text() == "keep me"


def test_restart_cuts_and_continues_the_reaction_series(tmp_path):
    """The spin-up stopped at t = 0.25 s and restarted to 0.5 s: reactions.pvd lists the
    frames of one run to 0.5 s (those after the checkpoint dropped first), each holding what
    the whole run's frame holds (the restart repeats the same steps: to 1e-9)."""
    from scenekit import run_whole_and_restarted
    from test_transient_reactions import SPIN

    short = SPIN.replace("t_end = 1.5", "t_end = 0.25").replace(
        "\noutput_every", "\ncheckpoint_every = 4\noutput_every"
    )
    run_whole_and_restarted(tmp_path, short.replace("t_end = 0.25", "t_end = 0.5"), short)
    whole, parts = (pvd_frames(tmp_path / n / "reactions.pvd") for n in ("whole", "parts"))
    assert len(whole) == 20 and [f for _, f in parts] == [f for _, f in whole]
    assert np.allclose([t for t, _ in parts], [t for t, _ in whole], rtol=1e-12)
    for _, file in whole:
        a, b = (read_vtu(tmp_path / n / file) for n in ("whole", "parts"))
        assert np.allclose(a[0], b[0], rtol=0, atol=1e-9)
        scale = np.abs(a[1]["moment"]).max()
        for key in ("force", "moment"):
            assert np.allclose(a[1][key], b[1][key], rtol=1e-9, atol=1e-9 * scale)
    assert sorted(p.name for p in (tmp_path / "parts").glob("reactions_*")) == [f for _, f in whole]


def test_condensed_cantilever_rows_have_the_balance(scene_file, tmp_path):
    """The statically condensed model reports the clamp's reaction from the section
    resultants and its balance with the loads: its rows hold both (no NaN), and its frames
    the reactions of results.json."""
    text = CANTILEVER.replace("KIN", "finite").replace("CONDENSE", "auto")
    out = tmp_path / "out"
    run = run_scene(scene_file(text), out, log=_quiet)
    assert run["model"]["condensed"]
    saved = json.loads((out / "results.json").read_text())
    rows = csv_rows(out)
    assert len(rows) == len(saved["path"]) == 2
    for row, point in zip(rows, saved["path"]):
        assert_row_equals(row, point["reactions"])
        assert not any(np.isnan(v) for v in row.values())
        applied = [row[f"applied_f_{c}"] for c in "xyz"]  # λ F, dead: load factor 0.5, 1
        assert np.allclose(applied, np.multiply(point["load_factor"], [1e3, -2e3, 5e3]))
    bal = saved["reaction_balance"]
    last = rows[-1]
    assert np.allclose([last[f"applied_m_{c}"] for c in "xyz"], bal["applied_moment"])
    assert last["balance_moment"] == pytest.approx(bal["moment"], rel=1e-11)
    assert last["balance_force"] == pytest.approx(bal["force"], rel=1e-11, abs=1e-15)
    frames = pvd_frames(out / "reactions.pvd")
    assert len(frames) == 2
    assert_frame_equals(out, frames[-1][1], saved["reactions"])
