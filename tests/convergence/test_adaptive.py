"""Discretisation chosen from a tolerance (beamfx.analyses.adaptive): the estimate is the move
of the answer between successive models, and it bounds the true error of the answer."""

import json
import tomllib

import numpy as np
import pytest

from beamfx.analyses.adaptive import ladder, refine_to_tolerance
from beamfx.runner import run_scene
from beamfx.scene import SceneError, parse_scene

L = 10.0
PHI = np.pi  # a half circle: exact tip x = L sin φ/φ, z = L (1 - cos φ)/φ
ROLLUP = f"""
[[beams]]
name = "b"
curve = {{ shape = "line", start = [0, 0, 0], end = [{L}, 0, 0] }}
section = {{ type = "general", EA = 1e7, GA_y = 1e7, GA_z = 1e7, GJ = 1e3, EI_y = 1e3, EI_z = 1e3 }}
[[supports]]
at = "b:start"
fix = "all"
[[loads]]
at = "b:end"
moment = [0, {-PHI * 1e3 / L}, 0]
[analysis]
steps = 4
[[probes]]
name = "tip"
at = "b:end"
[accuracy]
quantity = "tip.position"
tolerance = 1e-5
"""
EXACT = np.array([L * np.sin(PHI) / PHI, 0.0, L * (1 - np.cos(PHI)) / PHI])


def test_ladder_raises_the_degree_then_halves_the_elements():
    steps = ladder(1, 2, 4)
    assert [next(steps) for _ in range(5)] == [(1, 2), (1, 3), (1, 4), (2, 4), (4, 4)]


def test_refinement_meets_the_tolerance_and_the_estimate_bounds_the_error():
    """On the full model: the condensed one the scene builder picks for ROLLUP is exact for
    this pure bending (every error and change is round-off, and which bounds which is luck)."""
    from mpi4py import MPI

    sc = parse_scene(tomllib.loads(ROLLUP + '\n[model]\ncondense = "none"\n'), "t.toml")
    assert sc.model.kinematics.plane == "xz"  # trimmed as well
    ref = refine_to_tolerance(sc, MPI.COMM_WORLD)
    assert ref.reached and ref.estimate <= 1e-5
    errors = [np.linalg.norm(np.array(t.value) - EXACT) for t in ref.trials]
    # the move to the next model bounds the coarser model's error, and the last one's
    for t, e_coarse in zip(ref.trials[1:], errors[:-1]):
        assert abs(t.change - e_coarse) <= 0.5 * e_coarse  # e_k ≈ error of Q_{k-1}
    assert errors[-1] <= ref.estimate
    assert ref.scene.model.beams[0].degree == ref.trials[-1].degree


def test_run_reports_the_estimate_beside_the_answer(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(ROLLUP)
    lines = []
    results = run_scene(path, tmp_path / "out", log=lines.append)
    acc = json.loads((tmp_path / "out" / "results.json").read_text())["accuracy"]
    assert acc["reached"] and acc["estimate"] <= acc["tolerance"] == 1e-5
    assert acc["unknowns"] == results["model"]["unknowns"]
    assert np.allclose(results["probes"]["tip"]["position"], acc["value"], atol=1e-12)
    assert any("estimated error" in x for x in lines)


@pytest.mark.parametrize(
    "edit, words",
    [
        ({"quantity": "nope.position"}, "probe one of ['tip']"),
        ({"quantity": "tip.speed"}, "quantity one of ['position'"),
        ({"tolerance": -1.0}, "accuracy.tolerance = -1.0: must be a finite number > 0"),
        ({"max_degree": 1}, "accuracy.max_degree: must be at least start_degree (2)"),
        ({"colour": 1}, "accuracy.colour: unknown key"),
    ],
)
def test_bad_accuracy_keys_name_the_key_and_allowed_values(edit, words):
    data = tomllib.loads(ROLLUP)
    data["accuracy"].update(edit)
    with pytest.raises(SceneError) as e:
        parse_scene(data, "t.toml")
    assert "t.toml: accuracy" in str(e.value) and words in str(e.value), str(e.value)


def test_accuracy_needs_a_static_analysis():
    data = tomllib.loads(ROLLUP)
    data["analysis"]["type"] = "modal"
    with pytest.raises(SceneError, match="static and linear_static"):
        parse_scene(data, "t.toml")
