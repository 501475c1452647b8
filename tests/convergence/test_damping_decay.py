"""Stiffness-proportional damping still damps as the linear modal theory says: a cantilever's
free vibration in its first mode decays with ζ = a1 ω / 2 (Rayleigh damping C = a1 K)."""

import numpy as np
import pytest
from scenekit import cantilever

from beamfx.analyses.model import BeamModel
from beamfx.analyses.transient import TransientSettings, solve_transient

A1, H, T_END = 4.4e-4, 0.001, 0.6  # ζ1 ≈ 0.02 at ω1 ≈ 90 rad/s; ω1 h ≈ 0.09


@pytest.mark.slow
def test_free_decay_rate_is_a1_omega_over_2():
    """A small pulse (tip deflection ~5e-4 of the length: linear) starts mostly mode 1; the
    higher modes die first (ζ ∝ ω). Over t ∈ [0.15, 0.6] s the mechanical energy T + Π
    falls as exp(−2ζωt) (it also wiggles at 2ω by about ζ, averaged out by the fit over
    whole half periods); ω_d = ω √(1 − ζ²) from the kinetic energy's minima (twice a
    period). With ρ∞ = 1 the integrator adds no numerical damping; the two-step backward
    difference of the strain rates changes the damping by (ωh)²/3 = 0.3 %, the trapezoidal
    rule by less: 1 % allowed."""
    spec = cantilever(force=(0.0, 3.0, 4.0))
    model = BeamModel(spec, extra_points=["b:end"])
    settings = TransientSettings(t_end=T_END, dt=H, damping_stiffness=A1, rho_inf=1.0)
    result = solve_transient(model, settings)
    t = np.array([s.time for s in result.steps])
    kinetic = np.array([s.energy["kinetic"] for s in result.steps])
    energy = kinetic + np.array([s.energy["strain"] for s in result.steps])
    late = t > 0.15
    i = np.nonzero(late[1:-1] & (kinetic[1:-1] < kinetic[:-2]) & (kinetic[1:-1] < kinetic[2:]))[0]
    minima = t[1:-1][i]
    half_period = np.mean(np.diff(minima))
    omega_d = np.pi / half_period
    window = (t >= minima[0]) & (t <= minima[-1])  # whole half periods
    sigma = -np.polyfit(t[window], np.log(energy[window]), 1)[0] / 2  # ζω
    zeta = sigma / np.hypot(omega_d, sigma)
    omega = np.hypot(omega_d, sigma)
    assert 80 < omega < 100 and len(minima) > 10
    assert zeta == pytest.approx(A1 * omega / 2, rel=0.01)


def test_restart_with_stiffness_damping_goes_on_exactly(tmp_path):
    """The strains of the last two steps are part of a checkpoint: a damped run stopped at
    t = 0.1 and restarted to 0.2 equals one run to 0.2 (to round-off)."""
    from scenekit import SPIN_HISTORY, run_whole_and_restarted, spun_beam

    def scene(t_end):
        text = spun_beam(SPIN_HISTORY, t_end, dt=0.01, checkpoint_every=3)
        return text.replace("[analysis]", "[analysis]\ndamping = { stiffness = 0.01 }")

    whole, parts = run_whole_and_restarted(tmp_path, scene(0.2), scene(0.1))
    assert len(parts) == len(whole) and whole["dissipated_damping"][-1] > 0
    for key in ("tip_x", "tip_y", "dissipated_damping"):
        assert np.allclose(parts[key], whole[key], rtol=1e-10, atol=1e-12), key
