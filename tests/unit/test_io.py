"""Output: probes and nodal fields against the exact roll-up, files parsed back, JSON, logging.

The roll-up: a straight cantilever of length L under an end moment M about -y bends into a
circular arc of curvature κ = M/EI; with φ = κL the tip is at
x = L sin φ / φ, z = L (1 - cos φ) / φ, turned by φ about -y, and everywhere N = 0 and
M_y = -M (section axes = global axes here, since Λ0 = I). With k = M L / (2π EI) = 1/2 the
beam is a half circle: tip at (0, 0, 2L/π) turned by π.

MPI: probes are the same on every rank; gathered nodal fields live on rank 0, where the
frames (each rank writes its own piece) are read back and checked (the folder is rank 0's
tmp_path). tests/mpi/test_output_mpi.py compares the pieces of 2 ranks with 1 rank's file.
"""

import io
import itertools
import json
import os
import sys
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from scenekit import DEGREE, EI, ELEMENTS, SECTION, TOL_MOMENT, TOL_POSITION, L, comm, rollup_model

from beamfx.analyses.model import BeamModel
from beamfx.analyses.static import solve_static
from beamfx.geometry import Line
from beamfx.io import (
    FrameWriter,
    OutputSettings,
    Progress,
    check_writable,
    evaluate_points,
    log,
    nodal_fields,
    track_rotations,
    write_json_atomic,
)
from beamfx.io._sections import rotation_matrices
from beamfx.io.output import FramePolicy, default_every
from beamfx.physics.kinematics import Kinematics
from beamfx.physics.rotations import np_quaternion, np_rotation
from beamfx.spec import Beam, Model, PointLoad, Support


def exact_tip(phi):
    return np.array([L * np.sin(phi) / phi, 0.0, L * (1 - np.cos(phi)) / phi])


def shared_tmp(tmp_path):
    """Rank 0's tmp_path on every rank (writers write on rank 0 only)."""
    return comm.bcast(str(tmp_path), root=0)


@pytest.fixture(scope="module")
def half_circle():
    model, M = rollup_model(0.5)
    solve_static(model, steps=4)
    return model, M


def test_probes_match_exact_half_circle(half_circle):
    model, M = half_circle
    pts = evaluate_points(model)
    tip, root = pts["b:end"], pts["b:start"]

    assert np.linalg.norm(np.array(tip["position"]) - exact_tip(np.pi)) < TOL_POSITION * L
    assert np.allclose(tip["displacement"], exact_tip(np.pi) - [L, 0, 0], atol=TOL_POSITION * L)
    assert tip["angle"] == pytest.approx(np.pi, abs=TOL_POSITION)
    assert np.allclose(tip["axis"], [0, -1, 0], atol=1e-8)
    assert np.linalg.norm(tip["rotation_vector"]) <= np.pi + 1e-12
    # half a turn about -y: the section's x axis points back along -x
    axes = np.array(tip["section_axes"])
    assert np.allclose(axes, np.diag([-1.0, 1.0, -1.0]), atol=TOL_POSITION)
    assert np.allclose(axes.T @ axes, np.eye(3), atol=1e-12)

    assert np.allclose(root["position"], 0.0, atol=1e-12)
    assert root["angle"] == pytest.approx(0.0, abs=1e-12)
    for p in (tip, root):
        assert p["section_moment"][1] == pytest.approx(-M, rel=TOL_MOMENT)
        assert np.allclose(np.array(p["section_moment"])[[0, 2]], 0.0, atol=1e-8 * M)
        assert np.allclose(p["section_force"], 0.0, atol=1e-8 * M / L)
    assert (
        comm.allgather(json.dumps(pts, sort_keys=True))
        == [json.dumps(pts, sort_keys=True)] * comm.size
    )


def test_nodal_fields_moment_constant_and_recovery(half_circle):
    model, M = half_circle
    f = nodal_fields(model)
    raw = nodal_fields(model, recover=False)
    if comm.rank != 0:
        assert f is None and raw is None
        return
    n = ELEMENTS * (DEGREE + 1)
    assert f["X"].shape == f["u"].shape == f["e1"].shape == f["N"].shape == (n, 3)
    assert f["cells"].shape == (ELEMENTS * DEGREE, 2)
    assert np.all(np.diff(f["X"][:, 0]) >= 0)  # cells in order along the beam
    assert np.allclose(f["M"][:, 1], -M, rtol=TOL_MOMENT)
    assert np.allclose(f["N"], 0.0, atol=1e-8 * M / L)
    # pointwise values at the cell ends are off by far more: the reason for the recovery
    assert np.abs(raw["N"]).max() > 1e-3 * M / L
    # the frame is orthonormal and e1 is the tangent of the deformed centre line
    E = np.stack([f["e1"], f["e2"], f["e3"]], axis=2)
    assert np.allclose(np.einsum("nki,nkj->nij", E, E), np.eye(3), atol=1e-12)
    s = f["X"][:, 0]
    kappa = np.pi / L
    tangent = np.stack([np.cos(kappa * s), 0 * s, np.sin(kappa * s)], axis=1)
    assert np.allclose(f["e1"], tangent, atol=TOL_POSITION)


def test_track_rotations_two_turns():
    """Roll-up to two full turns: the unwrapped tip angle follows 4πλ, the raw one does not."""
    model, _ = rollup_model(2.0)
    history = []

    def on_step(step):
        previous = history[-1][1] if history else None
        history.append((step.load_factor, track_rotations(previous, evaluate_points(model))))

    solve_static(model, steps=20, on_step=on_step)
    lam = np.array([h[0] for h in history])
    unwrapped = np.array([h[1]["b:end"]["angle_unwrapped"] for h in history])
    assert np.allclose(unwrapped, 4 * np.pi * lam, atol=1e-4)
    tip = history[-1][1]["b:end"]
    assert np.allclose(tip["rotation_vector_unwrapped"], [0, -4 * np.pi, 0], atol=1e-4)
    assert tip["angle"] == pytest.approx(0.0, abs=1e-4) or tip["angle"] == pytest.approx(
        2 * np.pi, abs=1e-4
    )
    assert np.linalg.norm(tip["position"]) < 2e-5 * L  # exact tip: back at the clamp


def test_track_rotations_follows_quaternion_path():
    axis = np.array([1.0, 2.0, -2.0]) / 3
    previous = None
    for angle in np.arange(0.0, 5 * np.pi, 0.4):
        q = np_quaternion(axis, angle)
        current = {"p": {"quaternion": q.tolist(), "rotation_vector": [0.0, 0.0, 0.0]}}
        previous = track_rotations(previous, current)
        assert np.allclose(previous["p"]["rotation_vector_unwrapped"], angle * axis, atol=1e-12)


def test_rotation_matrices_match_physics():
    rng = np.random.default_rng(1)
    q = rng.normal(size=(5, 4))
    assert np.allclose(rotation_matrices(True, q), np_rotation(q), atol=1e-14)
    theta = rng.normal(size=(5, 3))
    theta[0] = 1e-10
    R = rotation_matrices(False, theta)
    for t, Ri in zip(theta, R):
        angle = np.linalg.norm(t)
        assert np.allclose(Ri, np_rotation(np_quaternion(t, angle)), atol=1e-14)


def test_linear_cantilever_resultants_exact():
    """Linear Timoshenko cantilever, tip force P: N = P and M_y = -P (L - s), reproduced
    exactly by the recovery (polynomials of degree < k), and the tip deflection is exact."""
    P = 100.0
    spec = Model(
        beams=(Beam("b", Line((0, 0, 0), (L, 0, 0)), SECTION, 4, 2),),
        supports=(Support("b:start", ("ux", "uy", "uz", "rx", "ry", "rz")),),
        point_loads=(PointLoad("b:end", force=(0, 0, P)),),
        kinematics=Kinematics(finite=False),
    )
    model = BeamModel(spec)
    solve_static(model)
    tip = evaluate_points(model, ["b:end"])["b:end"]
    w = P * L**3 / (3 * EI) + P * L / SECTION.GA_z
    assert tip["position"][2] == pytest.approx(w, rel=1e-10)
    assert tip["rotation_vector"][1] == pytest.approx(-P * L**2 / (2 * EI), rel=1e-10)
    assert "quaternion" not in tip
    f = nodal_fields(model)
    if comm.rank == 0:
        s = f["X"][:, 0]
        assert np.allclose(f["M"][:, 1], -P * (L - s), atol=1e-9 * P * L)
        assert np.allclose(f["N"][:, 2], P, atol=1e-9 * P)


def read_frame(path):
    """(points, {point array}, {cell array}, cell types, cells as point index lists) of a
    .vtu or .pvtu (pieces merged in file order)."""
    import pyvista as pv

    grid = pv.read(path)
    offsets, conn = np.asarray(grid.cell_offsets), np.asarray(grid.cell_connectivity)
    cells = [conn[a:b] for a, b in itertools.pairwise(offsets)]
    point_data = {k: np.asarray(grid.point_data[k]) for k in grid.point_data}
    cell_data = {k: np.asarray(grid.cell_data[k]) for k in grid.cell_data}
    return np.asarray(grid.points), point_data, cell_data, np.asarray(grid.celltypes), cells


def pvd_entries(path):
    """[(time, file)] of a .pvd; parsing it checks that it is valid XML."""
    root = ET.parse(path).getroot()
    return [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")]


def frame_file(folder, stem, step):
    return os.path.join(folder, f"{stem}_{step:04d}.{'vtu' if comm.size == 1 else 'pvtu'}")


def test_frames_read_back_equal_the_fields(half_circle, tmp_path):
    """The centre line frame: one Lagrange curve of k + 1 points per element, through the
    nodes in the order ends first; points X + u and every array equal to the fields."""
    model, _ = half_circle
    folder = shared_tmp(tmp_path)
    writer = FrameWriter(folder, model, OutputSettings(), model.spec.beams, comm)
    for step, t in ((1, 0.5), (2, 1.0)):
        writer.write(step, t)
        comm.barrier()
        if comm.rank == 0:  # the index is valid after every frame and lists them all
            assert pvd_entries(os.path.join(folder, "deformed.pvd"))[-1][0] == t
            assert len(pvd_entries(os.path.join(folder, "deformed.pvd"))) == step
    writer.close()
    f = nodal_fields(model)
    if comm.rank != 0:
        return
    # a section given by its stiffnesses only has no outline: no surface
    assert writer.files() == {"pvd": "deformed.pvd", "script": "open_in_paraview.py"}
    assert [e[0] for e in pvd_entries(os.path.join(folder, "deformed.pvd"))] == [0.5, 1.0]
    points, point_data, cell_data, types, cells = read_frame(frame_file(folder, "deformed", 2))
    assert len(cells) == ELEMENTS and np.all(types == 68)  # VTK_LAGRANGE_CURVE
    assert all(len(c) == DEGREE + 1 for c in cells)
    order = np.argsort(cell_data["cell"])
    assert np.array_equal(cell_data["cell"][order], np.arange(ELEMENTS))
    along = np.array([0, DEGREE, *range(1, DEGREE)])  # VTK: the two ends, then the interior
    nodes = np.concatenate([np.asarray(cells[c])[np.argsort(along)] for c in order])
    assert np.allclose(points[nodes], f["X"] + f["u"], rtol=0, atol=1e-14 * L)
    for name in ("X", "u", "e1", "e2", "e3", "N", "M"):
        assert np.array_equal(point_data[name][nodes], f[name]), name
    assert np.array_equal(cell_data["beam"], np.zeros(ELEMENTS))


def test_surface_frame_is_the_swept_section(half_circle, tmp_path):
    """The surface of the rectangle: every face lies at half the section from the centre
    line, the end caps close the beam's two ends, the cell data name the element."""
    from dataclasses import replace

    model, _ = half_circle
    folder = shared_tmp(tmp_path)
    h, w = 0.2, 0.1
    section = replace(SECTION, shape=("rectangle", h, w))
    beams = tuple(replace(b, section=section) for b in model.spec.beams)
    writer = FrameWriter(folder, model, OutputSettings(formats=("surface",)), beams, comm)
    assert writer.files() == {"surface": "surface.pvd"}  # no centre line, so no script
    writer.write(1, 1.0)
    comm.barrier()
    if comm.rank != 0:
        return
    points, point_data, cell_data, types, _ = read_frame(frame_file(folder, "surface", 1))
    assert set(np.unique(cell_data["cell"])) == set(range(ELEMENTS))
    assert np.sum(types == 7) == 2  # VTK_POLYGON: one cap at each end of the beam
    assert np.sum(types == 9) == ELEMENTS * 4 * 4  # quads: 4 sides, 4 subdivisions
    # the half circle of radius L/π about (0, ·, L/π) in the x-z plane: the section's height
    # h along e3 lies in that plane, its width w along y
    centre = np.array([0.0, 0.0, L / np.pi])
    radial = np.hypot(points[:, 0] - centre[0], points[:, 2] - centre[2])
    sides = np.isclose(np.abs(points[:, 1]), w / 2, atol=1e-12)
    assert sides.all()
    assert np.allclose(
        np.sort(np.unique(np.round(radial, 4))), [L / np.pi - h / 2, L / np.pi + h / 2], atol=1e-4
    )
    assert {"u", "N", "M"} <= set(point_data)


def test_resume_keeps_earlier_frames_and_drops_later_ones(half_circle, tmp_path):
    model, _ = half_circle
    folder = shared_tmp(tmp_path)
    settings = OutputSettings(formats=("vtu",))
    writer = FrameWriter(folder, model, settings, model.spec.beams, comm)
    for step in range(1, 5):
        writer.write(step, 0.25 * step)
    restarted = FrameWriter(folder, model, settings, model.spec.beams, comm)
    restarted.resume(0.5)
    comm.barrier()
    index = os.path.join(folder, "deformed.pvd")
    if comm.rank == 0:
        assert [t for t, _ in pvd_entries(index)] == [0.25, 0.5]
        assert os.path.exists(frame_file(folder, "deformed", 2))
    comm.barrier()
    restarted.write(3, 0.75)  # overwrites the dropped frame of the same name
    restarted.close()  # deletes the dropped frames not written again
    comm.barrier()
    if comm.rank == 0:
        assert [t for t, _ in pvd_entries(index)] == [0.25, 0.5, 0.75]
        assert os.path.exists(frame_file(folder, "deformed", 3))
        assert not [n for n in os.listdir(folder) if n.startswith("deformed_0004")]
    comm.barrier()
    fresh = FrameWriter(folder, model, settings, model.spec.beams, comm)  # a new run
    fresh.write(1, 1.0)
    comm.barrier()
    if comm.rank == 0:
        assert [t for t, _ in pvd_entries(index)] == [1.0]
    fresh.close()
    comm.barrier()
    if comm.rank == 0:  # the old run's files, rewritten (1) or deleted (2, 3)
        frames = [n for n in os.listdir(folder) if n.startswith("deformed_")]
        assert os.path.basename(frame_file(folder, "deformed", 1)) in frames
        assert all(n.startswith("deformed_0001") for n in frames), frames


def _frames(policy, times):
    """The steps a run of ``times`` writes, asking ``policy`` and recording as the writer does."""
    out = []
    for step, t in enumerate(times, start=1):
        if policy.want(step, t, last=step == len(times)):
            policy.record(step, t)
            out.append(step)
    return out


def test_output_policy_every_times_and_last():
    steps = np.arange(1, 11) * 0.1  # 10 steps to t = 1 (0.30000000000000004, ...)
    assert _frames(FramePolicy(OutputSettings()), steps) == list(range(1, 11))
    assert _frames(FramePolicy(OutputSettings(every=3)), steps) == [3, 6, 9, 10]  # + the last
    assert _frames(FramePolicy(OutputSettings(every=5)), steps) == [5, 10]  # the last once
    # the first step at or past each time (0.3 reached by 0.30000000000000004); one frame
    # where a step passes two times
    policy = FramePolicy(OutputSettings(times=(0.25, 0.3, 0.32, 0.7)))
    assert _frames(policy, steps) == [3, 4, 7, 10]
    policy = FramePolicy(OutputSettings(times=(0.25, 0.55)))
    policy.resume(0.5)  # restarted at 0.5: 0.25 is done, 0.55 still to come
    assert not policy.want(6, 0.52) and policy.want(7, 0.6)
    assert default_every("transient", 1440) == 14 and default_every("static", 40) == 1


def test_missing_vtk_is_reported_before_the_solve(monkeypatch):
    from beamfx.io.output import prepare_output
    from beamfx.io.vtkfiles import OutputUnavailable

    monkeypatch.setitem(sys.modules, "vtkmodules.vtkIOXML", None)  # import -> ImportError
    with pytest.raises(OutputUnavailable, match="pip install vtk"):
        prepare_output(OutputSettings())
    prepare_output(OutputSettings(formats=("xdmf",)))  # DOLFINx's own writer: no VTK needed


def test_output_settings_problems():
    assert list(OutputSettings().problems()) == []
    keys = [k for k, _ in OutputSettings(every=2, times=(1.0,)).problems()]
    assert keys == ["times"]
    assert [k for k, _ in OutputSettings(times=(2.0, 1.0)).problems()] == ["times"]
    assert [k for k, _ in OutputSettings(formats=("vtu", "vtu")).problems()] == ["formats"]
    assert OutputSettings().formats == ("vtu", "surface", "reactions")  # XDMF is not a default


def test_json_atomic_and_writable(tmp_path):
    folder = shared_tmp(tmp_path)
    path = os.path.join(folder, "out", "result.json")
    check_writable(os.path.dirname(path))
    obj = {"a": np.arange(3), "b": np.float64(1.5), "c": {"d": np.eye(2)}}
    write_json_atomic(path, obj)
    write_json_atomic(path, {**obj, "b": 2.5})  # replaces
    comm.barrier()
    if comm.rank == 0:
        with open(path) as fh:
            assert json.load(fh) == {"a": [0, 1, 2], "b": 2.5, "c": {"d": [[1.0, 0.0], [0.0, 1.0]]}}
        assert os.listdir(os.path.dirname(path)) == ["result.json"]  # no temporary left
        with open(os.path.join(folder, "plain"), "w") as fh:  # as any file open() makes
            fh.write("x")
        assert (
            os.stat(path).st_mode & 0o777 == os.stat(os.path.join(folder, "plain")).st_mode & 0o777
        )
        with open(os.path.join(folder, "a_file"), "w") as fh:
            fh.write("x")
    bad = os.path.join(folder, "a_file", "results")
    with pytest.raises(OSError, match="cannot write results to .*a_file"):
        check_writable(bad)


def test_json_levels_one_item_a_line_with_the_values_of_json():
    """results.json's layout: the first two levels one item a line (indented as indent=1),
    deeper values on their item's line; the same values as json.dumps, NumPy included."""
    from beamfx.io.results import dumps

    obj = {"a": [1.5, {"b": [2, 3]}], "c": {"d": np.arange(2)}, "e": [], "f": {}, "g": {1: 2}}
    text = dumps(obj)
    assert json.loads(text) == {**obj, "c": {"d": [0, 1]}, "g": {"1": 2}}
    assert text.splitlines() == [
        "{",
        ' "a": [',
        "  1.5,",
        '  {"b": [2, 3]}',
        " ],",
        ' "c": {',
        '  "d": [0, 1]',
        " },",
        ' "e": [],',
        ' "f": {},',
        ' "g": {"1": 2}',
        "}",
    ]


class _Tty(io.StringIO):
    def isatty(self):
        return True


def test_log_and_progress(capsys):
    log("hello")
    out = capsys.readouterr().out
    assert out == ("hello\n" if comm.rank == 0 else "")
    plain = io.StringIO()
    with Progress(3, "steps", stream=plain) as p:
        for i in range(1, 4):
            p.update(i, f"λ = {i / 3:.2f}")
    tty = _Tty()
    with Progress(2, "steps", stream=tty) as p:
        p.update(1, "long note")
        p.update(2)
    if comm.rank == 0:
        assert plain.getvalue().splitlines() == [
            "steps 1/3 λ = 0.33",
            "steps 2/3 λ = 0.67",
            "steps 3/3 λ = 1.00",
        ]
        assert tty.getvalue() == "\rsteps 1/2 long note\rsteps 2/2" + " " * 10 + "\n"
    else:
        assert plain.getvalue() == tty.getvalue() == ""
