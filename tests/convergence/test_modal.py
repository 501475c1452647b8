"""Eigenfrequencies and linear buckling against beam theory (Schwab & Meijaard 2009 sections)."""

import numpy as np
import pytest

from beamfx.analyses.buckling import solve_buckling
from beamfx.analyses.modal import solve_modes
from beamfx.analyses.model import BeamModel
from beamfx.analyses.static import solve_static
from beamfx.bench import schwab_meijaard_eigen as sme
from beamfx.bench._builders import CLAMP, cantilever, straight
from beamfx.physics.kinematics import Kinematics
from beamfx.spec import Beam, Model, Support

RIGID = Kinematics(shear=False)  # Euler-Bernoulli limit: penalty 1e8 EI/L^2, error ~3e-8
S = sme.S29  # square steel 20 x 20 mm
W_EB = np.sqrt(S.EI_y / S.rho_A)  # L = 1
BETA_CLAMPED = np.array([1.8751040687, 4.6940911330, 7.8547574382])  # cantilever β_n L


def clamped_modes(n, p, kin=RIGID):
    spec = Model(
        beams=(Beam("b", straight(1.0), S, n, p),),
        supports=(Support("b:start", CLAMP),),
        kinematics=kin,
    )
    return solve_modes(BeamModel(spec), n_modes=6, rotary="polar")


@pytest.mark.parametrize("finite", [True, False])
def test_cantilever_bending_frequencies_converge_to_euler_bernoulli(finite):
    """ω_n = β_n² sqrt(EI/ρA); the square section gives each as a pair (y and z).

    The eigenvalue error falls as h^(2p) (twice the energy-norm order): measured 3.9-4.0 for
    quadratic and 5.9-6.4 for cubic elements. Below ~1e-6 the shear-rigid penalty (1e8 EI/L²)
    sets a conditioning floor that grows with refinement, so the cubic rate is taken where
    the error is above it (modes 2 and 3, 4 -> 8 elements).
    """
    kin = Kinematics(finite=finite, shear=False)
    exact = np.repeat(BETA_CLAMPED**2 * W_EB, 2)[::2]
    e2 = [np.abs(clamped_modes(n, 2, kin).omega[::2] / exact - 1) for n in (4, 8)]
    assert np.all(np.log2(e2[0] / e2[1]) > 3.8), e2
    assert np.all(e2[1] < 2e-3)
    e3 = [np.abs(clamped_modes(n, 3, kin).omega[::2] / exact - 1) for n in (4, 8)]
    assert np.all(np.log2(e3[0][1:] / e3[1][1:]) > 5.5), e3
    assert np.all(e3[1] < 2e-5)


def test_quaternion_and_rotation_vector_models_have_the_same_modes():
    """The quaternion's norm direction has no mass: no extra (spurious) low modes."""
    a = clamped_modes(4, 2, Kinematics()).eigenvalues
    b = clamped_modes(4, 2, Kinematics(finite=False)).eigenvalues
    assert np.allclose(a, b, rtol=1e-8)


def test_free_free_beam_has_six_rigid_modes_then_the_theory():
    """SM 2.8: six zero frequencies, then the first bending pair 22.373 sqrt(EI/(ρA L⁴))."""
    spec = Model(beams=(Beam("b", straight(1.0), sme.S28, 8, 4),), kinematics=RIGID)
    r = solve_modes(BeamModel(spec), n_modes=8, rotary="polar")
    b1 = sme.THEORY_28["omega_B1"]
    assert np.all(np.abs(r.omega[:6]) < 1e-3 * b1), r.omega[:6]
    assert np.allclose(r.omega[6:8], b1, rtol=1e-6), r.omega[6:8] / b1 - 1
    assert np.all(r.residuals[6:] < 1e-8)


def test_euler_buckling_of_a_cantilever():
    """SM 2.5: P_cr = π²EI/(4L²). The section is 100x stiffer in shear and extension, which
    leaves the Engesser shear term P/(100 GA) = 6.3e-7; cubic elements are within 1e-6 of that
    at 4 elements (the buckling load converges as h^6 like the frequencies)."""
    s = sme.stiffened(sme.S25, stretch=False)
    P_e = sme.F_TH_25
    model = BeamModel(cantilever(straight(1.0), s, 4, 3, force=(-1.0, 0, 0)))
    r = solve_buckling(model, n_modes=2)
    # the second root buckles in the stiff plane: I_y = 4 I_z
    expected = np.array([P_e / (1 + P_e / s.GA_y), 4 * P_e / (1 + 4 * P_e / s.GA_z)])
    assert np.allclose(r.load_factors, expected, rtol=1e-6), r.load_factors / expected - 1


def test_lateral_buckling_with_the_stress_stiffness():
    """SM 2.6: 4.0126 sqrt(EI_z GJ)/L² within 1e-6 with 4 quartic elements. The full path
    derivative of the tangent (kg="path") finds a spurious root far below it: the pre-buckling
    rotation times the shear stiffness enters K_g (see analyses.buckling)."""
    s = sme.stiffened(sme.S26, stretch=False)
    model = BeamModel(cantilever(straight(1.0), s, 4, 4, force=(0, 0, 1.0)))
    r = solve_buckling(model, n_modes=1)
    assert abs(r.load_factors[0] / sme.F_TH_26 - 1) < 1e-6
    assert solve_buckling(model, n_modes=1, kg="path").load_factors[0] < 0.5 * sme.F_TH_26


def test_buckling_about_a_preloaded_state_gives_the_same_critical_load():
    """Euler column statically loaded to half its critical load (load factor 1): the critical
    factor λ* + μ about that deformed state is 2."""
    s = sme.stiffened(sme.S25, stretch=False)
    p0 = solve_buckling(BeamModel(cantilever(straight(1.0), s, 4, 3, force=(-1.0, 0, 0))))
    half = 0.5 * p0.load_factors[0]
    model = BeamModel(cantilever(straight(1.0), s, 4, 3, force=(-half, 0, 0)))
    solve_static(model, steps=1)
    r = solve_buckling(model, n_modes=1, about="current")
    assert abs(r.increments[0] - 1) < 1e-5 and abs(r.load_factors[0] - 2) < 1e-5


def test_tension_raises_the_bending_frequency():
    """SM 2.9: ω = ω0 sqrt(1 + α), α = F L²/(π² EI), pinned-pinned, after a static solve."""
    for alpha in (0.0, 1.0):
        F = alpha * np.pi**2 * S.EI_y
        model = BeamModel(sme.pinned_in_tension(S, 1.0, F, 8, 3))
        solve_static(model, steps=1)
        omega = solve_modes(model, n_modes=2, rotary="polar").omega
        assert np.allclose(omega, np.pi**2 * W_EB * np.sqrt(1 + alpha), rtol=1e-6), omega


def test_effective_masses_of_a_cantilever():
    """Base excitation of a slender clamped beam: the first three bending modes carry 61.3 %,
    18.8 % and 6.5 % of the mass along their direction (Euler–Bernoulli:
    m_k = (∫φ_k)² / ∫φ_k², L/h = 100 leaves ~1e-4 of shear and rotary inertia); none along
    the axis. Each mode's effective mass converges to the beam's; their sum over all modes
    would be the mass of the free dofs (the clamped node's consistent-mass share is not
    excited)."""
    from beamfx.analyses.modal import effective_masses
    from beamfx.physics.sections import rectangle

    section = rectangle(210e9, 80e9, 7850.0, 0.01, 0.02)
    spec = cantilever(straight(1.0), section, 16, 3, kinematics=Kinematics(plane="xz"))
    model = BeamModel(spec)
    res = solve_modes(model, 4, rotary="polar")
    m = effective_masses(model, res.modes, "polar")
    bending = [k for k in range(4) if m[k, 2] > 1e-6 * m[:, 2].sum()]
    total = 7850.0 * 0.01 * 0.02 * 1.0
    fractions = m[bending, 2] / total
    assert fractions[:3] == pytest.approx([0.6131, 0.1883, 0.0647], abs=5e-4)
    assert np.all(m[:, 0] < 1e-9 * total)
    # the mass form the eigen solve compiled (a modal run's path) gives the same numbers
    assert np.array_equal(effective_masses(model, res.modes, "polar", res.mass_form), m)
