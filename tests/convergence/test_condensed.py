"""The statically condensed model (rotations only) against the full Simo–Reissner model."""

from dataclasses import replace

import numpy as np
import pytest

from beamfx.analyses.condensed import CondensedModel, RotationRangeError
from beamfx.analyses.model import BeamModel
from beamfx.analyses.static import solve_static
from beamfx.analyses.trimming import condensed_fit
from beamfx.bench.howcroft_2016 import _build
from beamfx.io import evaluate_points
from beamfx.spec import PointLoad

POINTS = ["b:end", "b:0.5"]


def _solve(cls, spec, steps=10):
    model = cls(spec, extra_points=POINTS)
    result = solve_static(model, steps=steps)
    return model, result, evaluate_points(model, POINTS)


@pytest.mark.parametrize("follower", [False, True])
def test_same_answer_as_the_full_model(follower):
    """The elimination of Γ is exact: both discretisations converge to one solution.

    Condensed 8 x P4 (99 unknowns) against the full 16 x P4 (455, the bench's reference,
    converged to ~1e-9 in): the condensed model's 4 x P4 tip is already within 3e-7 in of it,
    so 1e-5 in at 8 x P4 leaves a margin for round-off, not for a wrong model. With a force
    at mid-length too (its indicator) and a moment (local work).
    """
    spec, steps = _build(follower)(8, 4)
    extra = PointLoad(
        "b:0.5", (0.0, -150.0, 0.0), (0.0, 0.0, 400.0), "follower" if follower else "dead"
    )
    spec = replace(spec, point_loads=(*spec.point_loads, extra))
    condensed, result, c = _solve(CondensedModel, spec, steps)
    assert condensed.unknowns() == 3 * 33
    fine = replace(spec, beams=_build(follower)(16, 4)[0].beams)
    _, _, f = _solve(BeamModel, fine, steps)
    # moments relative to the largest one along the beam (the tip moment is zero)
    M_scale = np.abs(f["b:0.5"]["section_moment"]).max()
    for name in POINTS:
        for key, tol, scale in (
            ("position", 1e-5, 1.0),
            ("rotation_vector", 1e-7, 1.0),
            ("section_moment", 1e-4, M_scale),  # M = C_M K, from g': one order lower
        ):
            a, b = np.asarray(c[name][key]), np.asarray(f[name][key])
            assert np.abs(a - b).max() < tol * scale, (name, key, a, b)
    # Newton converges quadratically with the follower coupling in the tangent
    assert result.newton_iterations <= 4 * len(result.steps)


def test_section_force_is_the_statically_determined_one():
    spec, steps = _build(True)(4, 4)
    _, _, v = _solve(CondensedModel, spec, steps)
    # the follower tip force is (0, 0, 600) in the tip's section axes... up to the
    # recovery from the Gauss points (a polynomial of degree p - 1 through them)
    N = np.asarray(v["b:end"]["section_force"])
    assert np.linalg.norm(N) == pytest.approx(600.0, rel=1e-3)


def test_linear_timoshenko_cantilever_keeps_shear():
    """Tip deflection F L³/(3EI) + F L/(k G A) at a load small enough to be linear."""
    from beamfx.bench._builders import cantilever, straight
    from beamfx.physics import sections

    L, E, G = 1.0, 2.1e11, 8.1e10
    sec = sections.rectangle(E, G, 7800.0, 0.05, 0.1, nu=0.3)
    F = 1e-3
    spec = cantilever(straight(L), sec, 2, 3, force=(0, 0, F))
    _, _, v = _solve(CondensedModel, spec, 1)
    EI, kGA = sec.EI_y, sec.GA_z
    expected = F * L**3 / (3 * EI) + F * L / kGA
    assert v["b:end"]["displacement"][2] == pytest.approx(expected, rel=1e-6)
    # and the Kirchhoff rod (shear and stretch dropped) gives Euler-Bernoulli
    rod = replace(spec, kinematics=replace(spec.kinematics, shear=False, stretch=False))
    _, _, v = _solve(CondensedModel, rod, 1)
    assert v["b:end"]["displacement"][2] == pytest.approx(F * L**3 / (3 * EI), rel=1e-6)


def test_scene_falls_back_to_the_full_model_past_the_range(tmp_path):
    """A cantilever rolled up to a full circle by an end moment: condensed automatically, the
    rotation vector's range is passed, and the run goes on with the quaternion model."""
    from beamfx.runner import run_scene

    scene = tmp_path / "rollup.toml"
    scene.write_text(
        """
[material]
E = 1.0
nu = 0.0
[[beams]]
name = "b"
curve = { shape = "line", start = [0, 0, 0], end = [1, 0, 0] }
section = { type = "rectangle", h = 1.0, w = 1.0 }
elements = 8
degree = 2
[[supports]]
at = "b:start"
fix = "all"
[[loads]]
at = "b:end"
moment = [0, -0.5235987755982988, 0]
kind = "follower"
[model]
plane = "none"
[analysis]
steps = 10
[[probes]]
name = "tip"
at = "b:end"
"""
    )
    lines = []
    results = run_scene(scene, tmp_path / "out", log=lines.append)
    assert results["model"]["condensed"] is False
    assert any("solving the full model" in line for line in lines)
    assert np.allclose(results["probes"]["tip"]["position"], [0, 0, 0], atol=1e-3)


def test_where_it_applies():
    spec, _ = _build(False)(2, 2)
    assert condensed_fit(spec) is None
    assert "static" in condensed_fit(spec, "modal")
    assert "gravity" in condensed_fit(replace(spec, gravity=(0, 0, -9.81)))
    with pytest.raises(ValueError, match="does not apply"):
        CondensedModel(replace(spec, gravity=(0, 0, -9.81)))


def test_rotations_near_two_pi_stop_with_a_clear_error():
    """An end moment that rolls the tip to 342 degrees, past the rotation vector's range."""
    from beamfx.bench._builders import cantilever, straight
    from beamfx.physics import sections

    sec = sections.rectangle(1.0, 0.5, 1.0, 1.0, 1.0, nu=0.0)
    M = 1.9 * np.pi * sec.EI_y / 1.0  # the tip turns by 1.9 pi
    spec = cantilever(straight(1.0), sec, 4, 2, moment=(0, M, 0))
    model = CondensedModel(spec, extra_points=["b:end"])
    with pytest.raises(RotationRangeError, match='condense = "none"'):
        solve_static(model, steps=10)


def test_sync_integrates_once_per_state_and_again_when_it_changes():
    """Probes, reactions and frames each ask the condensed model for its displacement after a
    step: integrated once per (w, load factor), redone when either changes."""
    from beamfx.bench._builders import cantilever, straight
    from beamfx.physics import sections

    sec = sections.rectangle(1.0, 0.5, 1.0, 1.0, 1.0, nu=0.0)
    spec = cantilever(straight(1.0), sec, 4, 2, moment=(0, 0.5 * np.pi * sec.EI_y, 0))
    model = CondensedModel(spec, extra_points=["b:end"])
    solve_static(model, steps=2)
    model.sync()
    u = model.u.x.array.copy()
    model.u.x.array[:] = 0.0  # a second call with the same state leaves u alone
    model.sync()
    assert not model.u.x.array.any()
    model.w.x.array[:] *= 0.5  # another state: integrated anew
    model.sync()
    half = model.u.x.array.copy()
    assert np.abs(half - u).max() > 0.01
    model.w.x.array[:] *= 2.0
    model.sync()
    assert np.allclose(model.u.x.array, u, rtol=0, atol=1e-14)
    model.reset()
    assert not model.u.x.array.any()
    model.sync()  # the undeformed state after a reset: integrated, zero
    assert np.abs(model.u.x.array).max() < 1e-14
