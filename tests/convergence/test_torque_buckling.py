"""Torque buckling of a clamped shaft (Schwab & Meijaard 2009, 2.7) and the kind of the torque.

Theory in :mod:`beamfx.bench.schwab_meijaard_torque`: semitangential M_cr = π EI/L,
quasitangential π EI/(2L); the dead (axial) and the follower torque have no adjacent
equilibrium and are unstable by flutter.
"""

from dataclasses import replace

import numpy as np
import pytest
from mpi4py import MPI

from beamfx.analyses.buckling import solve_buckling
from beamfx.analyses.model import BeamModel
from beamfx.analyses.static import solve_static
from beamfx.bench import reference
from beamfx.bench import schwab_meijaard_torque as smt
from beamfx.spec import PointLoad

M_TH = smt.M_TH_27


def critical(n, p, kind, section=smt.S27):
    r = solve_buckling(BeamModel(smt.shaft(n, p, kind, section=section)), n_modes=1)
    return r.load_factors[0] / M_TH


@pytest.mark.parametrize("kind", ["semitangential", "quasitangential"])
def test_critical_torque_converges_as_h_to_the_2p(kind):
    """Cubic elements: the buckling torque is an eigenvalue, its error falls as h^(2p) = h^6.
    The observed orders must be near 6, and the finest error within twice its Richardson
    estimate (M_4 − M_8)/(2^6 − 1): the tolerance is what the rate predicts, not a number."""
    exact = smt.CRITICAL[kind]
    m = {n: critical(n, 3, kind) for n in (2, 4, 8)}
    e = {n: m[n] / exact - 1 for n in m}
    orders = [np.log2(e[2] / e[4]), np.log2(e[4] / e[8])]
    assert all(5.5 < r < 6.5 for r in orders), (e, orders)
    richardson = abs(m[4] - m[8]) / (2**6 - 1) / exact
    assert abs(e[8]) <= 2 * richardson, (e[8], richardson)
    assert abs(e[8]) < 1e-7


def test_quadratic_elements_reproduce_the_published_beamnl_column():
    """With the shear term at p Gauss points the rotations of the (shear-free) mode are free
    continuous P2 fields: the slopes of BEAMNL's C1 cubics. The paper prints ten digits."""
    table = reference(smt.FILE, "sm27_torque_buckling")["tables"]["BEAMNL"]
    for n, (published,) in zip(table["n_elements"][:4], table["rows"][:4]):
        assert abs(critical(n, 2, "semitangential") - published) < 1e-9, n


def test_two_crossed_quasitangential_couples_make_a_semitangential_torque():
    """Half the torque on an arm along y, half on an arm along z: to second order in the
    rotation their potential is −M·ψ, so the linear buckling analysis gives the same value."""
    half = [
        PointLoad("b:end", moment=(0.5, 0, 0), kind="quasitangential", arm=a)
        for a in ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    ]
    spec = replace(smt.shaft(4, 3, "semitangential"), point_loads=tuple(half))
    crossed = solve_buckling(BeamModel(spec), n_modes=1).load_factors[0] / M_TH
    assert abs(crossed / critical(4, 3, "semitangential") - 1) < 1e-9


@pytest.mark.parametrize("kind", ["dead", "follower"])
def test_dead_and_follower_torques_have_no_static_critical_load(kind):
    """No real root of det(K0 + μ K_g): the real eigenvalues of the discrete pencil sit at
    ~1e12 π EI/L and beyond (torsion and axial dofs, where K_g vanishes), the others are
    complex."""
    mu = smt.dense_pencil(BeamModel(smt.shaft(4, 3, kind), MPI.COMM_SELF)) / M_TH
    real = np.abs(mu.imag) <= 1e-6 * np.abs(mu)
    assert not np.any(real & (np.abs(mu) < 1e6)), mu[real]
    assert np.all(mu[~real].imag != 0)


def lowest_pair(kind, torque, section=smt.S27, n=8):
    """The two lowest ω² about the shaft twisted by ``torque`` (times π EI/L)."""
    spec = smt.shaft(n, 3, kind, torque * M_TH, section)
    model = BeamModel(spec, MPI.COMM_SELF)
    solve_static(model, steps=1)  # raises if it fails
    return smt.dense_modes(model)[:2]


@pytest.mark.parametrize("kind", ["dead", "follower"])
def test_dead_and_follower_torques_flutter_at_any_torque(kind):
    """Kinetic criterion: the double first bending frequency splits into a complex pair
    ω = ω_r ± i ω_i with ω_i ∝ M (first-order splitting of a double eigenvalue by the skew
    part of the tangent), while a conservative (semitangential) torque keeps it real."""
    im = []
    for torque in (0.02, 0.04):
        omega = np.sqrt(lowest_pair(kind, torque).astype(complex))
        assert np.allclose(omega[0], np.conj(omega[1]), rtol=1e-8), omega
        im.append(abs(omega[0].imag) / abs(omega[0]))
    assert im[0] > 1e-3 and abs(im[1] / im[0] - 2) < 0.02, im
    lam = lowest_pair("semitangential", 0.04)
    assert np.all(np.abs(lam.imag) < 1e-8 * np.abs(lam)), lam


@pytest.mark.parametrize("kind", ["semitangential", "quasitangential"])
def test_conservative_torques_diverge_where_the_buckling_analysis_says(kind):
    """With the torsion 1e4 times stiffer (twist before buckling 4e-4 rad, which the theory
    neglects) ω² of the first mode changes sign between 0.99 and 1.01 of the critical torque
    of the buckling analysis on the same mesh: static and kinetic criteria agree."""
    rigid = replace(smt.S27, GJ=1e4 * smt.S27.GJ)
    m_cr = critical(8, 3, kind, rigid)
    below, above = (lowest_pair(kind, f * m_cr, rigid)[0] for f in (0.99, 1.01))
    assert abs(below.imag) < 1e-8 * abs(below) and abs(above.imag) < 1e-8 * abs(above)
    assert below.real > 0 > above.real, (below, above)


SCENE = """
[material]
E = 210e9

[[beams]]
name = "shaft"
curve = {{ shape = "line", start = [0, 0, 0], end = [1, 0, 0] }}
section = {{ type = "circle", d = 0.02 }}

[[supports]]
at = "shaft:start"
fix = "all"

[[loads]]
at = "shaft:end"
moment = [1, 0, 0]
{extra}
"""


def scene(extra):
    import tomllib

    from beamfx.scene.load import parse_scene

    return parse_scene(tomllib.loads(SCENE.format(extra=extra)), "scene.toml")


def test_quasitangential_load_needs_an_arm_normal_to_its_moment():
    from beamfx.scene import SceneError

    load = scene('kind = "quasitangential"\narm = [0, 2, 0]').model.point_loads[0]
    assert load.kind == "quasitangential" and load.arm == (0.0, 2.0, 0.0)
    bad = {
        'kind = "quasitangential"': "scene.toml: loads[0].arm: missing",
        'kind = "quasitangential"\narm = [1, 1, 0]': "scene.toml: loads[0].arm: must be a non-zero",
        "arm = [0, 1, 0]": "scene.toml: loads[0].arm: only a kind = 'quasitangential' moment",
    }
    for extra, message in bad.items():
        with pytest.raises(SceneError) as e:
            scene(extra)
        assert str(e.value).startswith(message), str(e.value)


def test_a_double_root_split_by_round_off_is_taken_as_real():
    """EA and GA ×1e4 (the stress matrix): the semitangential shaft's double root (two bending
    planes) comes out of the unsymmetric solve as μ ± 1e-4 i (|Im μ|/|μ| = 2e-8, above the
    former 1e-8 test; its residual 3e-7), so no root was kept and the bench case raised an
    IndexError. It is real to its own residual (buckling.is_real): M_cr is the one at ×1 to
    1e-6 (the matrix's tolerance; the stiffening moves it by ~1e-7)."""
    from beamfx.bench.stress_matrix import stiffened

    at_1 = critical(4, 3, "semitangential")
    with stiffened(1e4):
        stiff = critical(4, 3, "semitangential")
    assert stiff == pytest.approx(at_1, rel=1e-6)


def test_real_roots_are_told_from_complex_ones_by_their_residual():
    from beamfx.analyses.buckling import REAL_CAP, is_real

    assert is_real(5181.55 + 9.94e-5j, 3e-7)  # round-off within the residual
    assert not is_real(5181.55 + 9.94e-5j, 1e-12)  # a converged root: 1e-8 holds
    assert is_real(5181.55 + 4e-5j, 0.0)
    assert not is_real(5000.0 + 10.0j, 1.0)  # an unconverged complex root: capped
    assert not is_real(5000.0 + 5000.0 * 2 * REAL_CAP * 1j, 1.0)


def test_the_case_takes_the_mixed_form_where_a_scene_would():
    """EA and GA ×1e8 (the stress matrix's last factor): the critical torques do not depend on
    them (no axial or shear force before or in the mode), and the case's own run takes the
    formulation a buckling scene of the shaft gets (choose_formulation: the mixed form from a
    stiffness ratio of 1e8). In the displacement form they drifted by round-off ∝ the factor
    (1.8e-3 for 4 P3 at ×1e8); in the mixed form they keep the ×1 values to the displacement
    form's round-off there (measured 2e-9 at ×1e2 and 2e-11 at ×1e8)."""
    from beamfx.bench.stress_matrix import stiffened

    at_1 = smt._torque(4, 3)[0]
    with stiffened(1e8):
        spec = smt.as_scene_chooses(smt.shaft(4, 3, "semitangential"))
        stiff = smt._torque(4, 3)[0]
    assert spec.formulation == "mixed"
    for kind, ratio in at_1.items():
        assert stiff[kind] == pytest.approx(ratio, rel=1e-8), kind
