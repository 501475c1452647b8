"""Stability from scene files (beamfx run): an arc-length run through a column's bifurcation
onto its buckled branch, and buckling about a state beyond the first critical load."""

import json
import math

import pytest

from beamfx.runner import run_scene

EI_Z = 1e4 * 0.02 * 0.01**3 / 12
COLUMN = f"""
[[beams]]
name = "column"
curve = {{ shape = "line", start = [0, 0, 0], end = [1, 0, 0] }}
section = {{ type = "general", EA = 2, GA_y = 0.68, GA_z = 0.68, GJ = 4e-5, EI_y = {4 * EI_Z!r}, EI_z = {EI_Z!r} }}
elements = 8
degree = 3

[[supports]]
at = "column:start"
fix = "all"
"""
P_E = math.pi**2 * EI_Z / 4


def _run(tmp_path, text, log=lambda *a: None):
    scene = tmp_path / "scene.toml"
    scene.write_text(text + f'\n[output]\ndir = "{tmp_path / "out"}"\n')
    return run_scene(scene, log=log)


def test_arclength_scene_switches_onto_the_buckled_branch(tmp_path):
    text = (
        COLUMN
        + f"""
[[loads]]
at = "column:end"
force = [{-P_E!r}, 0, 0]

[analysis]
type = "arclength"
branch = "secondary"
max_arc_length = 0.05
displacement_limit = ["uy", 0.3]
"""
    )
    lines = []
    results = _run(tmp_path, text, lines.append)
    assert results["status"] == "converged" and results["stopped_by"] == "displacement_limit"
    # the log names the cause: the value reached at the last point, past the limit
    (line,) = [x for x in lines if x.startswith("stopped: displacement limit reached")]
    uy = results["path"][-1]["displacement"][1]
    assert f"uy of column:end = {uy:.6g}" in line and "past the limit |uy| = 0.3" in line
    assert "does not land on it" in line
    (point,) = results["critical_points"]
    assert point["kind"] == "bifurcation" and point["switched"]
    assert point["negative_eigenvalues"] == [0, 1]
    # P_b (1 − P_b/EA + P_b/GA) = P_e: λ_b − 1 ≈ P_e (1/EA − 1/GA), plus the mesh's 1e-7
    expected = 1 + P_E * (1 / 2 - 1 / 0.68)
    assert abs(point["load_factor"] - expected) < 1e-6
    path = results["path"]
    assert all(p["negative_eigenvalues"] == 0 for p in path if "note" not in p)
    assert abs(path[-1]["displacement"][1]) >= 0.3
    assert results["limit_points"] == []
    csv = (tmp_path / "out" / "path.csv").read_text().splitlines()
    assert csv[0].endswith("negative_eigenvalues,note") and "branch switch" in "".join(csv)
    written = json.loads((tmp_path / "out" / "results.json").read_text())
    assert written["critical_points"] == results["critical_points"]


@pytest.mark.parametrize("factor, passed", [(0.5, 0), (1.5, 1)])
def test_buckling_about_the_current_state_counts_the_critical_points_passed(
    tmp_path, factor, passed
):
    text = (
        COLUMN
        + f"""
[[loads]]
at = "column:end"
force = [{-factor * P_E!r}, 0, 0]

[analysis]
type = "buckling"
about = "current"
modes = 2
"""
    )
    results = _run(tmp_path, text)
    assert results["critical_points_passed"] == passed
    both = sorted(results["load_factors_both_signs"])
    # in units of the scene's load: the first critical load at 1/factor (to the
    # pre-buckling shortening, 1e-5), below the state (λ = 1) when it is passed
    first = min(both, key=lambda x: abs(x * factor - 1))
    assert abs(first * factor - 1) < 1e-4
    assert (first < 1) == (passed == 1)
    assert all(x > 1 for x in results["load_factors"])  # sign = "positive": above the state


def test_a_static_run_past_the_euler_load_counts_the_critical_point(tmp_path):
    """Load control along the perfect column's straight path to 1.5 P_e in 10 steps: the
    tangent has one negative eigenvalue from 1.05 P_e on (the weak axis buckles at P_e, the
    strong one at 4 P_e), and the log names the interval where the count changed."""
    text = (
        COLUMN
        + f"""
[[loads]]
at = "column:end"
force = [{-1.5 * P_E!r}, 0, 0]

[model]
plane = "none"

[analysis]
type = "static"
steps = 10
"""
    )
    messages = []
    scene = tmp_path / "scene.toml"
    scene.write_text(text + f'\n[output]\ndir = "{tmp_path / "out"}"\n')
    results = run_scene(scene, log=messages.append)
    assert results["status"] == "converged"
    counts = [p["negative_eigenvalues"] for p in results["path"]]
    assert counts == [0] * 6 + [1] * 4
    assert any("0 -> 1 between load factors 0.6 and 0.7" in m for m in messages), messages
