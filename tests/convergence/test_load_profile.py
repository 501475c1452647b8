"""Distributed loads with a ``profile`` along their beam: the triangular load on a linear
Timoshenko cantilever against its closed form, the reactions against the load's resultant, a
follower profile in section axes, and the bad-input messages."""

import numpy as np
import pytest

from beamfx.runner import run_scene
from beamfx.scene import SceneError, load_scene

L, EI, GA, Q0 = 2.0, 2.0e4, 5.0e6, 30.0

TEXT = f"""
[[beams]]
name = "b"
curve = {{ shape = "line", start = [0, 0, 0], end = [{L}, 0, 0] }}
section = {{ type = "general", EA = 1e8, GA_y = {GA}, GA_z = {GA}, GJ = 1e4, EI_y = {EI}, EI_z = {EI} }}
elements = 4
degree = 3

[[supports]]
at = "b:start"
fix = "all"

[[loads]]
beam = "b"
force_per_length = [0, 0, {Q0}]
PROFILE

[[probes]]
name = "tip"
at = "b:end"

[analysis]
type = "ANALYSIS"
"""


def _run(scene_file, tmp_path, profile, analysis="linear_static", extra=""):
    text = TEXT.replace("PROFILE", profile + extra).replace("ANALYSIS", analysis)
    return run_scene(scene_file(text), tmp_path / "out", log=lambda *_: None)


@pytest.mark.parametrize(
    "profile", ['profile = "s / L"', "profile = { s = [0, 2], values = [0, 1] }"]
)
def test_triangular_load_on_a_timoshenko_cantilever(scene_file, tmp_path, profile):
    """q(s) = q0 s/L, growing to the tip: tip deflection 11 q0 L^4 / (120 EI) + q0 L^2 / (3 GA)
    (the bending part by reciprocity with the tip-loaded cantilever, the shear part from the
    shear force q0 (L^2 - s^2) / (2L)). Cubic elements hold the linear profile exactly, and the
    nodal deflection of the linear Timoshenko element is exact for this load up to round-off;
    the root force is the load's resultant q0 L / 2 and the root moment its moment
    q0 L^2 / 3."""
    run = _run(scene_file, tmp_path, profile)
    w = run["probes"]["tip"]["displacement"][2]
    exact = 11 * Q0 * L**4 / (120 * EI) + Q0 * L**2 / (3 * GA)
    assert abs(w - exact) < 1e-9 * exact
    r = run["reactions"]["b:start"]
    assert np.allclose(r["force"], [0, 0, -Q0 * L / 2], rtol=0, atol=1e-9 * Q0 * L)
    assert np.allclose(r["moment"], [0, Q0 * L**2 / 3, 0], rtol=0, atol=1e-9 * Q0 * L**2)


def test_follower_profile_in_section_axes_balances_its_deformed_resultant(scene_file, tmp_path):
    """A follower load in section axes with a profile, large deflection: the reactions balance
    the applied loads as the forms state them (to Newton's tolerance)."""
    extra = '\nkind = "follower"\naxes = "section"'
    text = TEXT.replace("PROFILE", 'profile = "sqrt(1 - (s / L) ** 2)"' + extra)
    text = text.replace("ANALYSIS", "static").replace(f"{Q0}]", f"{200 * Q0}]")
    run = run_scene(scene_file(text), tmp_path / "out", log=lambda *_: None)
    assert run["probes"]["tip"]["displacement"][2] > 0.15 * L  # large deflection (about 0.18 L)
    bal = run["reaction_balance"]
    assert bal["force"] < 1e-8 and bal["moment"] < 1e-8


@pytest.mark.parametrize(
    "profile, words",
    [
        ('profile = "1 - s / L"\nbeam = "x"', ["loads[0]", "'x' is no beam"]),
        ('profile = "1 - t"', ["loads[0].profile", "s"]),
        ('profile = "1 / (s - 1)"', ["loads[0].profile", "finite"]),
        ("profile = { s = [0, 0], values = [1, 0] }", ["loads[0].profile", "increasing"]),
    ],
)
def test_bad_profiles_are_refused_before_the_solve(scene_file, profile, words):
    text = TEXT.replace("PROFILE", profile).replace("ANALYSIS", "linear_static")
    if 'beam = "x"' in profile:
        text = text.replace('beam = "b"\n', "")
    with pytest.raises(SceneError) as e:
        load_scene(scene_file(text))
    for w in words:
        assert w in str(e.value)


def test_a_profile_needs_its_beam(scene_file):
    text = TEXT.replace('beam = "b"\n', "").replace("PROFILE", 'profile = "1"')
    with pytest.raises(SceneError) as e:
        load_scene(scene_file(text))
    assert "loads[0].profile" in str(e.value) and "give 'beam'" in str(e.value)


def test_internal_moment_equals_the_moment_of_the_load_beyond_each_section(scene_file):
    """Howcroft et al.'s check along the span (beamfx.bench.span_equilibrium) on a cantilever
    under a follower profile in section axes at large deflection: the recovered moment of the
    cubic elements converges to the load's moment as h^3 (p = 3), so halving the elements
    divides the mismatch by about 8; at least 6 is asked."""
    from dataclasses import replace

    from beamfx.analyses.model import BeamModel
    from beamfx.analyses.static import solve_static
    from beamfx.bench.span_equilibrium import mismatch, span_moments

    extra = '\nkind = "follower"\naxes = "section"'
    text = TEXT.replace("PROFILE", 'profile = "1 - (s / L) ** 2"' + extra)
    text = text.replace("ANALYSIS", "static").replace(f"{Q0}]", f"{400 * Q0}]")
    spec = load_scene(scene_file(text)).model
    load = spec.distributed_loads[0]
    errors = []
    for elements in (4, 8):
        beams = (replace(spec.beams[0], elements=elements),)
        model = BeamModel(replace(spec, beams=beams))
        solve_static(model, steps=10)
        errors.append(mismatch(span_moments(model, load.force, load.profile)))
    assert errors[1] < 1e-3 and errors[0] / errors[1] > 6
