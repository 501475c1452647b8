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
