"""Nonlinear statics against independent integrations of the rod equations (rod_equations.py)."""

import numpy as np
import pytest
import rod_equations as rod

from beamfx.analyses.model import BeamModel
from beamfx.analyses.static import solve_static
from beamfx.bench import howcroft_2016 as hw
from beamfx.bench import schwab_meijaard_2009 as sm
from beamfx.bench._builders import arc, cantilever, straight
from beamfx.io import evaluate_points
from beamfx.physics.rotations import np_rotation


def solve_tip(model_spec, steps=10):
    model = BeamModel(model_spec, extra_points=["b:end"])
    solve_static(model, steps=steps)
    tip = evaluate_points(model, ["b:end"])["b:end"]
    return np.asarray(tip["position"]), np_rotation(tip["quaternion"])


def test_sm23_end_moments_match_the_rod_equations_with_8_elements():
    """Schwab & Meijaard 2.3 as stated: 8 cubic elements within 1e-6 (relative to L = 1)."""
    r_ref, R_ref = rod.pure_end_moments(1.0, sm.S23.C_M, sm.M23)
    x, R = solve_tip(cantilever(straight(1.0), sm.S23, 8, 3, moment=sm.M23))
    assert np.linalg.norm(x - r_ref) < 1e-6
    assert np.linalg.norm(R - R_ref) < 1e-6
    # and it is not the published table (about five times larger): see the reference's CAUTION
    published_u = np.array(sm.P23["tables"]["BEAM"]["rows"][-1][:3])
    assert np.linalg.norm(x - [1, 0, 0]) < 0.3 * np.linalg.norm(published_u)


@pytest.mark.parametrize("follower", [False, True])
def test_bend45_matches_shooting_on_the_rod_equations(follower):
    """45° bend, dead and follower tip force, 8 cubic elements vs shooting (to 1e-4 of the tip)."""
    g = hw.V["geometry"]
    curve = rod.arc_curve(100.0, 45.0, g["start"], g["start_tangent"], g["centre"], degrees=True)
    s = hw.SECTION
    r_ref, _ = rod.cantilever_shooting(curve, s.C_N, s.C_M, (0, 0, hw.F), follower=follower)
    x, _ = solve_tip(cantilever(arc(g), s, 8, 3, (0, 0, hw.F), follower=follower))
    assert np.linalg.norm(x - r_ref) < 1e-4 * np.linalg.norm(r_ref), (x, r_ref)


@pytest.mark.parametrize(
    "k, u, w, phi", [(1, 0.0564332, 0.3017208, 0.4613519), (10, 0.5549956, 0.810609, 1.4302855)]
)
def test_mattiasson_elastica(k, u, w, phi):
    """Dead transverse tip force on a (nearly) inextensible cantilever, Mattiasson's table."""
    from beamfx.bench.classic import MATT_SECTION

    x, R = solve_tip(cantilever(straight(1.0), MATT_SECTION, 8, 4, force=(0, 0, k)))
    assert np.allclose([1 - x[0], x[2]], [u, w], atol=2e-6)
    assert abs(np.arccos(np.clip((np.trace(R) - 1) / 2, -1, 1)) - phi) < 2e-6
