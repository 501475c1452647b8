"""Rotating analyses in the mixed (Hellinger–Reissner) form (issue 16): the displacement
form's steady state and frequencies at ordinary stiffness, and frequencies that follow their
trend in EA, GA where the displacement form loses its digits.

The mixed form's quadratic eigen solve keeps the section force unknowns (no mass) out of its
Krylov space (:mod:`beamfx.solvers.eigen_shell`); SLEPc's TOAR on the saddle point missed
frequencies by up to 1e-2 (SM 2.10's blade, 8 × P3, at the spin speed ω_By).
"""

from dataclasses import replace

import numpy as np
import pytest

from beamfx.analyses.model import BeamModel
from beamfx.analyses.rotating import RotatingFrame, solve_rotating_modes, solve_steady
from beamfx.analyses.rotating_checks import lowest_tangent_eigenvalue, steady_state_lost
from beamfx.bench import schwab_meijaard_rotating as smr
from beamfx.bench.pai_rotating import _scene as pai_scene
from beamfx.bench.stress_matrix import stiffened
from beamfx.io import evaluate_points


def _blade(factor, formulation, k_penalty=None, n=4, p=3, alpha=1.0):
    """SM 2.10's blade (shear f EI/L² stiff: ratio 1e7 at ×1) with EA, GA × ``factor``, at
    Ω = α ω_By: (six lowest rotating-frame ω, tip displacement, quaternion penalty)."""
    with stiffened(factor):
        spec = replace(smr.blade_model(n, p), formulation=formulation)
        model = BeamModel(spec, extra_points=["b:end"])
    if k_penalty is not None:
        model.k_penalty.value = k_penalty
    frame = RotatingFrame(model, rotary="none")
    solve_steady(frame, alpha * smr.OMEGA_BY, steps=1)
    tip = np.asarray(evaluate_points(model, ["b:end"])["b:end"]["position"])
    omega = solve_rotating_modes(frame, 6).omega
    frame.destroy()
    return omega, tip - (smr.L210, 0.0, 0.0), float(model.k_penalty.value)


def test_mixed_equals_displacement_at_ordinary_stiffness():
    """With the same quaternion penalty the two forms solve the same discrete equations: the
    steady stretch and the six lowest frequencies at Ω = ω_By agree to 1e-9 (observed 1e-10:
    the displacement form's round-off at ratio 1e7)."""
    omega_d, tip_d, k_p = _blade(1.0, "displacement")
    omega_m, tip_m, _ = _blade(1.0, "mixed", k_penalty=k_p)
    assert np.abs(tip_m - tip_d).max() <= 1e-9 * np.abs(tip_d).max()
    assert np.all(np.abs(omega_m - omega_d) <= 1e-9 * omega_d), (omega_m, omega_d)


def test_stiffened_frequencies_follow_their_trend():
    """EA, GA × 1e8 (ratio 1e15) in the mixed form: each frequency is its ×1 value corrected
    by the trend in the compliance 1/f, ω(f) = ω∞ + b/f + O(1/f²), extrapolated from f = 1
    and 100. The O(1/f²) remainder is of the order of the first-order move d times its
    relative size |d|/ω (a second-order term in the compliance); allowed: 10 times that, and
    1e-10 ω of round-off. (The displacement form's frequencies there moved 1e-5 … 1e-2.)"""
    at = {f: _blade(f, "mixed")[0] for f in (1.0, 1e2, 1e8)}
    d = at[1e2] - at[1.0]
    predicted = at[1e2] + d * (1e-2 - 1e-8) / (1.0 - 1e-2)
    tol = 10 * d**2 / at[1.0] + 1e-10 * at[1.0]
    assert np.all(np.abs(at[1e8] - predicted) <= tol), (at[1e8], predicted, tol)
    assert np.all(np.abs(d) > 1e-6 * at[1.0])  # the trend is there (the shear and stretch)


@pytest.fixture(scope="module")
def pai_frames():
    """The Pai strip (8 × P3) with EA, GA × 1e8 at rest in both forms: (displacement, mixed)
    rotating frames at speed 0 and load factor 0."""
    frames = []
    for formulation in ("displacement", "mixed"):
        with stiffened(1e8):
            model = BeamModel(replace(pai_scene(8, 3).model, formulation=formulation))
        frame = RotatingFrame(model, (0, 0, 1), (0, 0, 0))
        frame.set_speed(0.0)
        model.set_load_factor(0.0)
        frames.append(frame)
    yield frames
    for frame in frames:
        frame.destroy()


def test_the_tangent_check_knows_its_round_off(pai_frames):
    """At rest the Pai strip's tangent is positive definite (lowest ω² ≈ 115 s⁻²). The
    displacement form at ×1e8 computes a negative eigenvalue (−4.3), within its round-off
    estimate: not a loss of steady state. The mixed form resolves it: μ > 0, its round-off
    far below."""
    displacement, mixed = pai_frames
    mu_d, floor_d = lowest_tangent_eigenvalue(displacement)
    mu_m, floor_m = lowest_tangent_eigenvalue(mixed)
    assert mu_m > 100 and floor_m < 1e-6 * mu_m
    assert abs(mu_d - mu_m) <= floor_d
    lost, why = steady_state_lost(displacement, 0.0)
    assert not lost and "round-off" in why
    assert not steady_state_lost(mixed, 0.0)[0]
