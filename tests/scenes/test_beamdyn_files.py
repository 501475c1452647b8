"""BeamDyn files read with openfast-io into matrix sections (skipped without openfast-io)."""

import tomllib
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("openfast_io")

from beamfx.physics.matrix_sections import MatrixSection, from_beamdyn
from beamfx.scene.beamdyn import read_blade, read_primary
from beamfx.scene.load import parse_scene
from beamfx.scene.table import SceneError

FOLDER = Path(__file__).resolve().parents[2] / "meshes" / "nrel5mw"
PRIMARY = FOLDER / "NRELOffshrBsline5MW_BeamDyn.dat"
BLADE = FOLDER / "NRELOffshrBsline5MW_BeamDyn_Blade.dat"


def test_blade_and_primary_files_read_alike_and_map_to_beamfx_order():
    eta, K, M = read_blade(BLADE)
    eta2, K2, _ = read_blade(PRIMARY)  # through its BldFile
    assert len(eta) == 49 and eta[0] == 0 and eta[-1] == 1
    assert np.array_equal(eta, eta2) and np.array_equal(K, K2)
    C = from_beamdyn(K[0])
    assert C[0, 0] == 9.7944926e06  # BeamDyn K33, the extension stiffness, is our EA
    assert C[3, 3] == 7.5825971  # K66, torsion
    assert C[0, 4] == K[0][2, 3]  # extension - bending about x1 (our y)
    assert np.allclose(from_beamdyn(M[0])[:3, :3], 0.49983299 * np.eye(3))
    points, twist, _ = read_primary(PRIMARY)
    assert points.shape == (49, 3) and points[-1, 2] == 0.55 and not twist.any()


def _scene(section, folder=FOLDER):
    text = (FOLDER / "blade_modes.toml").read_text()
    data = tomllib.loads(text)
    data["beams"][0]["section"] = section
    data["beams"][0]["elements"] = 8
    return parse_scene(data, "blade_modes.toml", folder)


def test_the_scene_reads_the_files_as_a_matrix_section_with_49_stations():
    sec = _scene({"type": "beamdyn", "file": PRIMARY.name}).model.beams[0].section
    assert isinstance(sec, MatrixSection) and len(sec.stations) == 49
    assert np.isclose(sec.length, 0.55)


def test_a_file_the_reader_rejects_names_the_file_and_key(tmp_path):
    bad = tmp_path / "bad_blade.dat"
    bad.write_text("not\na\nBeamDyn\nfile\n")
    with pytest.raises(
        SceneError, match=r"beams\[0\]\.section\.file: .*bad_blade.dat: openfast-io"
    ):
        _scene({"type": "beamdyn", "file": str(bad)})
    with pytest.raises(SceneError, match="missing.dat: no such file"):
        _scene({"type": "beamdyn", "file": "missing.dat"})


def test_the_blade_at_rest_has_the_same_frequencies_in_the_rotating_and_modal_analyses(tmp_path):
    """Speed 0 of the rotating analysis (quadratic eigenproblem, PEP) against the modal analysis
    (GHEP) of the same coarse blade: the same problem solved two ways."""
    from beamfx.analyses.modal import solve_modes
    from beamfx.analyses.model import BeamModel
    from beamfx.analyses.rotating import RotatingFrame, solve_rotating_modes, solve_steady

    spec = _scene({"type": "beamdyn", "file": PRIMARY.name}).model
    modal = solve_modes(BeamModel(spec), 6).hz
    frame = RotatingFrame(BeamModel(spec), hub=(0.0, 0.0, 0.0))
    solve_steady(frame, 0.0)
    rotating = solve_rotating_modes(frame, 6).hz
    frame.destroy()
    assert np.allclose(modal, rotating, rtol=1e-8), (modal, rotating)
    assert 4.4 < modal[0] < 4.5  # the first flap mode (4.435 Hz converged, 384 P3 elements)


REAL = Path(__file__).resolve().parents[2] / "meshes" / "nrel5mw_blade"


def _elastodyn_table(path):
    """The distributed properties of an ElastoDyn blade file (BlFract, twist, mass, flap, edge)."""
    lines = path.read_text().splitlines()
    start = next(i for i, line in enumerate(lines) if "DISTRIBUTED BLADE PROPERTIES" in line) + 3
    return np.array([[float(v) for v in line.split()] for line in lines[start : start + 49]])


def test_the_nrel5mw_blade_files_agree_with_the_elastodyn_file_beside_them():
    """The BeamDyn files and the ElastoDyn file of the 61.5 m blade are two independent tables
    of the same blade: their stations, mass, flap and edge stiffness and twist must agree."""
    eta, K, M = read_blade(REAL / "NRELOffshrBsline5MW_BeamDyn_Blade.dat")
    points, twist, _ = read_primary(REAL / "NRELOffshrBsline5MW_BeamDyn.dat")
    ed = _elastodyn_table(REAL / "NRELOffshrBsline5MW_Blade.dat")
    assert np.array_equal(eta, ed[:, 0]) and points[-1, 2] == 61.5
    assert np.abs(points[:, 2] / 61.5 - eta).max() < 3e-5  # key points at the stations
    assert np.array_equal(twist, ed[:, 1])
    assert np.array_equal(M[:, 0, 0], ed[:, 2])
    assert np.array_equal(K[:, 4, 4], ed[:, 3]) and np.array_equal(K[:, 3, 3], ed[:, 4])
    for Ks, Ms in zip(K, M):  # symmetric positive definite at every station
        for A in (Ks, Ms):
            assert np.array_equal(A, A.T) and np.linalg.eigvalsh(A).min() > 0
    assert np.allclose(M[:, 5, 5], M[:, 3, 3] + M[:, 4, 4], rtol=0, atol=1e-9)  # polar = sum


def test_the_nrel5mw_blade_frequencies_converge_with_the_mesh(tmp_path):
    """Cubic elements with a vertex at every station: the tables are held exactly, so the
    frequencies converge as h^(2p); 48 and 96 cubic elements agree to far below 1e-6."""
    from beamfx.runner import run_scene

    base = tomllib.loads((REAL / "blade_modes.toml").read_text())
    freqs = []
    for n in (48, 96):
        data = {**base, "beams": [{**base["beams"][0], "elements": n}]}
        data["analysis"] = {"type": "modal", "modes": 6}
        scene = parse_scene(data, "blade_modes.toml", REAL)
        run = run_scene(scene.file, tmp_path / str(n), log=lambda *a, **k: None, scene=scene)
        freqs.append(np.array(run.result.frequencies_hz))
    assert np.abs(freqs[0] / freqs[1] - 1).max() < 1e-6
    assert 0.6 < freqs[1][0] < 0.8  # first flap: the blade's length and mass, not the old files'
