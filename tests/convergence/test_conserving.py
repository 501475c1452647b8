"""Long undamped runs: the conserving scheme keeps energy and momenta to solver tolerance;
generalized-α damps each frequency by the spectral radius its ρ∞ predicts."""

from dataclasses import replace

import numpy as np
import pytest
from scenekit import CLAMP, RHO, E, G, flying_spaghetti, hat

from beamfx.analyses.model import BeamModel
from beamfx.analyses.static import solve_static
from beamfx.analyses.transient import TransientSettings, solve_transient
from beamfx.geometry import Line
from beamfx.physics.kinematics import Kinematics
from beamfx.physics.sections import Section, tube
from beamfx.solvers.integrators import generalized_alpha
from beamfx.spec import Beam, Model, PointLoad, PointMass, Support


def free_flight(spec, t_end, dt=0.05):
    """Energy T + Π, linear and angular momentum of every step after the pulse (t > 5 s)."""
    model = BeamModel(spec, extra_points=["b:end"])
    settings = TransientSettings(t_end=t_end, dt=dt, scheme="conserving", checkpoint_every=0)
    records = []
    result = solve_transient(model, settings, on_step=records.append)
    free = [r.energy for r in records if r.time > 5.0 + 1e-9]
    H = np.array([e["kinetic"] + e["strain"] for e in free])
    p = np.array([e["linear_momentum"] for e in free])
    L = np.array([e["angular_momentum"] for e in free])
    return H, p, L, result


def flying_spaghetti_3d(point_masses=()):
    """The flying spaghetti thrown out of its plane: quaternion rotations, all three
    components of the angular momentum."""
    section = Section(1e4, 1e4, 1e4, 500.0, 500.0, 500.0, 1.0, (20.0, 10.0, 10.0))
    beam = Beam("b", Line((6, 0, 0), (0, 8, 0)), section, 8, 2)
    load = PointLoad("b:start", (8.0, 0.0, 4.0), (20.0, 40.0, 80.0), "dead", hat)
    return Model((beam,), (), (load,), point_masses=point_masses)


TIP_BODY = PointMass("b:end", 2.0, ((1.0, 0.2, 0.0), (0.2, 0.5, 0.0), (0.0, 0.0, 0.5)))


@pytest.mark.parametrize(
    "spec",
    [
        pytest.param(flying_spaghetti(), id="xy"),
        # the quaternion path without a point mass: a second 3D conserving tangent (about 40 s
        # of cold JIT) that 3d-tip-body compiles with the body's terms added
        pytest.param(flying_spaghetti_3d(), id="3d", marks=pytest.mark.slow),
        pytest.param(flying_spaghetti_3d((TIP_BODY,)), id="3d-tip-body"),
    ],
)
def test_conserving_scheme_keeps_energy_and_momenta(spec):
    """35 s of free flight (the slowest flexible mode of the free-free beam has a period of
    1.26 s, so about 28 periods): energy and momenta hold to round-off relative to their
    size (Newton converges to ~1e-10 of the residual scale). The trapezoidal rule alone
    (generalized-α, ρ∞ = 1) lets energy and angular momentum wander by ~1e-4 (measured)."""
    H, p, L, result = free_flight(spec, t_end=40.0)
    assert result.stopped_by == "t_end" and len(result.steps) == 800  # no cut-backs
    assert np.ptp(H) < 1e-10 * H[0]
    scale = np.linalg.norm(L[0]) + np.linalg.norm(p[0]) * 10.0  # |x| ~ the beam's length
    assert np.ptp(p, axis=0).max() < 1e-10 * scale
    assert np.ptp(L, axis=0).max() < 1e-10 * scale


def tip_mass_oscillator():
    """A 1 kg tip mass on a light linear cantilever: a one-degree-of-freedom oscillator
    (the beam's own mass, 1e-4 of it, shifts ω by ~1e-5)."""
    section = replace(tube(E, G, RHO, 0.02), rho_A=1e-4, rho_I=(1e-10, 1e-10, 1e-10))
    beam = Beam("b", Line((0, 0, 0), (1.0, 0, 0)), section, 4, 3)
    release = PointLoad("b:end", (0.0, 0.0, 1.0), history=lambda t: (np.asarray(t) <= 0) * 1.0)
    spec = Model(
        (beam,),
        (Support("b:start", CLAMP),),
        (release,),
        point_masses=(PointMass("b:end", 1.0),),
        kinematics=Kinematics(finite=False, plane="xz"),
    )
    return BeamModel(spec, extra_points=["b:end"]), np.sqrt(3 * section.EI_y)


def spectral_radius(rho_inf, omega_h):
    """Largest |eigenvalue| of the Chung–Hulbert (1993) amplification matrix of
    ü + ω²u = 0, from their equations in (d, h v, h² a)."""
    am, af, beta, gamma, _ = generalized_alpha(rho_inf)
    w2 = omega_h**2
    lhs = np.array([[1, 0, -beta], [0, 1, -gamma], [w2 * (1 - af), 0, 1 - am]])
    rhs = np.array([[1, 1, 0.5 - beta], [0, 1, 1 - gamma], [-w2 * af, 0, -am]])
    return max(abs(np.linalg.eigvals(np.linalg.solve(lhs, rhs))))


@pytest.mark.parametrize("rho_inf, omega_h", [(0.5, 1.0), (0.5, 3.0), (0.8, 1.0), (0.8, 3.0)])
def test_generalized_alpha_decays_as_its_spectral_radius(rho_inf, omega_h):
    """Released from its static deflection, the oscillator's energy decays per step by the
    square of the amplification matrix's spectral radius ρ(ωh) (→ ρ∞ as ωh → ∞). The decay
    rate, fitted over the steps above 1e-10 of the start (below that Newton's tolerance
    shows), matches log ρ(ωh) to 1 %; the values for different ρ∞ differ by far more."""
    model, omega = tip_mass_oscillator()
    model.set_time(0.0)
    solve_static(model, steps=1)
    energy = []
    dt = omega_h / omega
    settings = TransientSettings(t_end=200 * dt, dt=dt, rho_inf=rho_inf, easy_iterations=99)
    solve_transient(model, settings, on_step=lambda r: energy.append(sum(
        r.energy[k] for k in ("kinetic", "strain"))))  # fmt: skip
    energy = np.array(energy[1:])
    # the steps before the energy first falls below 1e-10 of the start: beyond, it is the
    # round-off floor's noise, which may cross that line again at any later step
    above = energy > 1e-10 * energy[0]
    decaying = int(np.argmin(above)) if not above.all() else len(energy)
    assert decaying > 50
    slope = np.polyfit(np.arange(decaying), np.log(energy[:decaying]), 1)[0]
    predicted = np.log(spectral_radius(rho_inf, omega_h))
    assert slope / 2 == pytest.approx(predicted, rel=0.01)
