"""The balance of the statically condensed model's reactions with its loads
(beamfx.analyses.condensed_reactions): the applied resultants from the model's own loads at
the current state, against the full model's (from its nodal load vector) and closed forms.

Tolerances: a pure end moment rolls the planar condensed beam up exactly (θ = M s/EI is in the
space), so the recovered clamp moment, and the balance, are at round-off (measured 5e-14); the
condensed and the full model of the same mesh reach states that differ by their discretisations
(tip positions 1e-9 apart, rotations 3e-10, measured), so their applied resultants agree to
1e-8 of the load scale, where a moment of the wrong kind would be off by ½|ψ||M| ≈ 1e3 (1e-2).
"""

import tomllib

import numpy as np
import pytest
from scenekit import CONDENSED_LOADS
from test_reaction_output import csv_rows
from test_reactions import _quiet

from beamfx.analyses.condensed import CondensedModel
from beamfx.analyses.condensed_reactions import load_resultant
from beamfx.analyses.model import BeamModel
from beamfx.analyses.reactions import Reaction, entries, load_balance
from beamfx.analyses.static import solve_static
from beamfx.bench.output_cost import ROLLUP
from beamfx.physics.rotations import np_left_jacobian as left_jacobian
from beamfx.runner import run_scene
from beamfx.scene.load import parse_scene


def test_rolled_up_beam_balances_its_end_moment_at_round_off(scene_file, tmp_path):
    """The roll-up (planar condensed, two turns in 4 steps): every row of reactions.csv holds
    the applied end moment λ M and a balance at round-off, no NaN."""
    text = ROLLUP.replace("steps = 40", "steps = 4").replace("elements = 16", "elements = 4")
    out = tmp_path / "out"
    run = run_scene(scene_file(text), out, log=_quiet)
    assert run["model"]["condensing"]["model"] == "planar_condensed"
    M = -104.71975511965977
    rows = csv_rows(out)
    assert [r["load_factor"] for r in rows] == [0.25, 0.5, 0.75, 1.0]
    for row in rows:
        lam = row["load_factor"]
        assert not any(np.isnan(v) for v in row.values())
        assert [row[f"applied_f_{c}"] for c in "xyz"] == [0.0, 0.0, 0.0]
        applied = [row[f"applied_m_{c}"] for c in "xyz"]
        # (the CSV's 12 significant digits)
        assert np.allclose(applied, [0, lam * M, 0], rtol=1e-11, atol=1e-11 * abs(M))
        assert row["balance_force"] == 0.0 and row["balance_moment"] < 1e-12
    assert run["reaction_balance"]["moment"] < 1e-12
    assert run["reaction_balance"]["recovered_moment_gap"] < 1e-12  # pure moment: exact


def test_a_wrong_reaction_shows_in_the_balance():
    """The balance is a check, not an identity: the clamp reaction of a tip force F at
    x = (2, 0.5, 0) balances it to round-off; 1 % off in the force or the moment shows."""
    F, x = np.array([3.0, -4.0, 12.0]), np.array([2.0, 0.5, 0.0])
    applied = load_resultant([("tip", F, np.zeros(3))], {"tip": x})
    right = Reaction((-F).tolist(), (-np.cross(x, F)).tolist(), [0.0, 0.0, 0.0])
    b = load_balance({"clamp": right}, *applied, 2.0)
    assert b.force < 1e-15 and b.moment < 1e-15
    assert b.applied_force == F.tolist() and np.allclose(b.applied_moment, np.cross(x, F))
    for wrong in (right._replace(force=(-1.01 * F).tolist()), right._replace(moment=[0, 0, 1])):
        b = load_balance({"clamp": wrong}, *applied, 2.0)
        assert max(b.force, b.moment) > 1e-3


def test_left_jacobian_maps_rotation_vector_rates_to_spatial_rotations():
    """δθ = J(ψ) δψ: axial(δR Rᵀ) of R = exp(ψ̂) by central differences (error h² ~ 1e-10);
    the small-angle series at θ < 1e-4 agrees with the closed form."""
    from scipy.spatial.transform import Rotation

    h = 1e-5
    for psi in ([0.3, -1.2, 2.0], [1e-5, 2e-5, -3e-5], [0.0, 0.0, 0.0]):
        psi = np.asarray(psi)
        J = np.zeros((3, 3))
        for j in range(3):
            e = np.eye(3)[j] * h
            dR = Rotation.from_rotvec(psi + e) * Rotation.from_rotvec(psi - e).inv()
            J[:, j] = dR.as_rotvec() / (2 * h)
        assert np.allclose(left_jacobian(psi), J, rtol=0, atol=1e-9)


def _applied(cls, spec):
    model = cls(spec)
    solve_static(model, steps=4)
    return model, entries(model)


def test_condensed_applied_loads_are_the_full_models():
    """Follower force and moment, semitangential moment, dead force: the condensed model's
    applied resultants (from its loads at the current rotations and positions) equal the
    full model's (from its nodal load vector, an independent route); its force balance is at
    round-off; its reaction moment is the loads' statics about the clamp, so the moment
    balance is at round-off too, and the recovered section moment differs from it by its
    discretisation error (P3: 7e-5 on 4 cells, ``recovered_moment_gap``)."""
    spec = parse_scene(tomllib.loads(CONDENSED_LOADS)).model
    condensed, c = _applied(CondensedModel, spec)
    _, f = _applied(BeamModel, spec)
    a, b = c["reaction_balance"], f["reaction_balance"]
    scale = np.linalg.norm(b["applied_force"]) * 2.0  # the moment scale: force × length
    assert np.allclose(a["applied_force"], b["applied_force"], rtol=0, atol=1e-8 * scale / 2)
    assert np.allclose(a["applied_moment"], b["applied_moment"], rtol=0, atol=1e-8 * scale)
    assert a["force"] < 1e-14 and a["moment"] < 1e-14
    assert 1e-6 < a["recovered_moment_gap"] < 1e-3
    # the equilibrium reaction: the full model's residual reaction to its own discretisation
    rc, rf = c["reactions"]["b:start"], f["reactions"]["b:start"]
    assert np.allclose(rc["moment"], rf["moment"], rtol=0, atol=1e-3 * scale)
    assert "reactions_from" in a and "reactions_from" not in b
    # finite rotations (0.19 rad at the tip): a moment of the wrong kind would show
    assert np.linalg.norm(condensed.w.x.array.reshape(-1, 3), axis=1).max() > 0.1


@pytest.mark.parametrize("kind", ["dead", "follower", "semitangential"])
def test_moment_kinds_differ_by_the_rotation(kind):
    """A tip moment alone: the applied moment is the kind's (dead M, follower R M, semitangential J⁻ᵀ M) at the tip's rotation."""
    text = (
        CONDENSED_LOADS.split("[[loads]]")[0]
        + f"""
[[loads]]
at = "b:end"
moment = [0, 9e4, 6e4]
kind = "{kind}"
[model]
kinematics = "finite"
plane = "none"
"""
    )
    spec = parse_scene(tomllib.loads(text)).model
    model, c = _applied(CondensedModel, spec)
    from beamfx.analyses.condensed_reactions import point_unknowns

    g = point_unknowns(model, ["b:end"], {})["b:end"]
    M = np.array([0, 9e4, 6e4])
    want = {
        "dead": M,
        "follower": model.np_rotation(g) @ M,
        "semitangential": np.linalg.solve(left_jacobian(g).T, M),
    }[kind]
    bal = c["reaction_balance"]
    assert np.linalg.norm(g) > 0.3
    assert np.allclose(bal["applied_moment"], want, rtol=1e-13, atol=1e-9)
    # a spatial rotation field is not in the space: the recovered moment's error (2e-5 dead)
    assert bal["force"] == 0.0 and bal["moment"] < 1e-14
    assert 0.0 < bal["recovered_moment_gap"] < 1e-3
