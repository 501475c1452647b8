"""OpenSeesPy on the demo frames (peers/opensees_frame.py, ``make bench-peers``): the same
displacements, rotations and reactions as the exact frame and beamfx, to 1e-8 relative.
Skipped where openseespy is not importable (it lives in .venv-peers, not in the test venv)."""

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

from beamfx.bench import frame_peers, frame_stiffness

PEERS = Path(__file__).resolve().parents[2] / "peers" / "opensees_frame.py"


def _opensees():
    pytest.importorskip("openseespy.opensees")
    spec = importlib.util.spec_from_file_location("opensees_frame", PEERS)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_exported_problems_are_plain_json(tmp_path):
    """The export the peer script reads (runs without openseespy)."""
    frame_peers.export(tmp_path)
    data = json.loads((tmp_path / "frame_problems.json").read_text())
    assert set(data) == set(frame_peers.FRAMES)
    tower = data["tower"]
    assert len(tower["members"]) == 96 and len(tower["nodes"]) == 28
    assert len(tower["fixed"]) == 4 and len(tower["loads"]) == 4
    assert all(tower["nodes"][int(k)][2] == 0 for k in tower["fixed"])  # the feet
    assert all(v == list(range(6)) for v in tower["fixed"].values())


@pytest.mark.parametrize("name", frame_peers.FRAMES)
def test_opensees_equals_the_exact_frame_and_beamfx(name, tmp_path):
    opensees = _opensees()
    frame_peers.export(tmp_path)
    problem = json.loads((tmp_path / "frame_problems.json").read_text())[name]
    values = opensees.solve(problem)
    u = np.asarray(values["displacements"])
    reactions = {int(k): np.asarray(v) for k, v in values["reactions"].items()}
    spec = frame_peers._specs()[name]
    exact, exact_r = frame_stiffness.solve(frame_stiffness.problem_from_model(spec))
    assert max(frame_peers.differences(u, reactions, exact, exact_r)) < 1e-8
    got, got_r, _ = frame_peers.beamfx_frame(spec)
    assert max(frame_peers.differences(got, got_r, u, reactions)) < 1e-8


@pytest.mark.parametrize("name", frame_peers.FRAMES)
def test_the_timed_scene_file_is_the_compared_frame(name, tmp_path):
    """The scene file whose whole run is timed (linear_static, P3, no gravity) is the frame
    the values are compared on."""
    from beamfx.scene import load_scene

    scene = load_scene(frame_peers.write_linear_scene(name, tmp_path))
    spec = frame_peers._specs()[name]
    assert scene.analysis == "linear_static" and not scene.model.kinematics.finite
    assert {b.degree for b in scene.model.beams} == {3} and not any(scene.model.gravity)
    a = frame_stiffness.problem_from_model(scene.model)
    b = frame_stiffness.problem_from_model(spec)
    for key in ("nodes", "members", "stiffness", "axes"):
        np.testing.assert_array_equal(getattr(a, key), getattr(b, key))
    assert a.fixed == b.fixed
    assert a.loads.keys() == b.loads.keys()
    assert all(np.array_equal(a.loads[k], b.loads[k]) for k in a.loads)


def test_frames_report(tmp_path):
    """The report section from rows as compare() writes them."""
    row = {
        "problem": "tower",
        "members": 96,
        "beamfx_vs_exact": [1e-14, 2e-13, 3e-14],
        "opensees_vs_exact": [1e-14, 1e-14, 1e-14],
        "beamfx_vs_opensees": [5e-14, 3e-13, 5e-14],
        "beamfx_whole_s": 1.0,
        "opensees_whole_s": 0.04,
        "beamfx_split_s": {"total": 0.2},
    }
    md = frame_peers.markdown([row], {"openseespy": "3.7.1.2", "import_s": 0.9})
    assert "| tower | 96 | 1.0e-14 / 2.0e-13 / 3.0e-14 |" in md
    assert "| tower | 1 | 0.2 | 0.04 |" in md and "**no** (25 x)" in md
