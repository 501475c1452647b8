"""BeamDyn's static regression cases (meshes/beamdyn_rtest, beamfx/bench/beamdyn_static.py):
the gravity cantilever against BeamDyn's number within the two discretisation errors, the
model of BeamDyn's element that explains that number, and the twisted beam's frames (linear,
against the flexibility integral) and equilibrium (nonlinear, root reactions)."""

import numpy as np
import pytest

pytest.importorskip("openfast_io")

from beamfx.bench import beamdyn_lsfe as lsfe
from beamfx.bench import beamdyn_static as bd
from beamfx.runner import run_scene


def _run(path, elements, degree, tmp_path, **analysis):
    scene = bd.scene(path, elements, degree, **analysis)
    run = run_scene(scene.file, tmp_path, log=lambda *a, **k: None, scene=scene)
    assert run.converged, run.result.reason
    return run.result


def test_the_model_of_beamdyns_element_gives_beamdyns_number():
    """One order-5 Legendre spectral element with 6 Gauss points (BeamDyn's discretisation,
    planar) lands within a quarter of its own error (its distance to the exact beam) of what
    BeamDyn printed: BeamDyn's 3.9 % is its discretisation error. The bench's constants are
    these computations; order 7 is 8 times closer to the exact beam than order 5 (the element
    converges spectrally to the exact beam: the two solve the same equations)."""
    five, exact = lsfe.one_element(5)._asdict(), lsfe.elastica()._asdict()
    assert bd.relative_spread(five, bd.LSFE_ORDER5) < 1e-9
    assert bd.relative_spread(exact, bd.EXACT) < 1e-8
    error5 = bd.relative_spread(five, exact)
    assert bd.relative_spread(lsfe.one_element(7, steps=10)._asdict(), exact) < error5 / 5
    ref = bd.reference("cantilever")
    for k in bd.CANTILEVER_KEYS:
        assert abs(ref[k] - five[k]) < 0.25 * abs(exact[k] - five[k]), k


def test_the_coarse_gravity_cantilever_meets_beamdyn_within_both_discretisation_errors(
    tmp_path,
):
    """4 x P3 against BeamDyn's number. Tolerance per value: beamfx's discretisation error
    (estimated by the difference to 8 x P3) plus BeamDyn's (order-5 element against the exact
    beam, times Roache's 1.25). Against the exact beam: the error halves at least from 4 to 8
    elements, so the coarse error is at most twice the difference of the two meshes."""
    coarse, fine = (bd.read(_run(bd.GRAVITY, n, 3, tmp_path), bd.CANTILEVER_KEYS) for n in (4, 8))
    ref = bd.reference("cantilever")
    for k in bd.CANTILEVER_KEYS:
        ours = abs(coarse[k] - fine[k])
        theirs = bd.SAFETY * abs(bd.EXACT[k] - bd.LSFE_ORDER5[k])
        assert abs(coarse[k] - ref[k]) <= ours + theirs, k
        error, error_fine = abs(coarse[k] - bd.EXACT[k]), abs(fine[k] - bd.EXACT[k])
        assert error_fine <= error / 2 and error <= 2 * ours, k


def _flexibility_tip(force, length, twist_rad, C):
    """Linear tip (u, θ) of a straight cantilever along global z under a tip ``force``: the
    section axes e1 = z, e2, e3 turned by ``twist_rad(s)`` about z from (x, y), compliance
    Λ C⁻¹ Λᵀ with Λ = blockdiag(Q, Q), Q = [e1 e2 e3]; resultant (F, (L − s) e1 × F).
    θ(L) = ∫κ, u(L) = ∫γ + (∫(L − s) κ ds) × e1 (Gauss quadrature, 400 points)."""
    s, w = np.polynomial.legendre.leggauss(400)
    s, w = (s + 1) * length / 2, w * length / 2
    e1, F = np.array([0.0, 0.0, 1.0]), np.asarray(force, float)
    G = np.linalg.inv(C)
    I0, I1 = np.zeros(6), np.zeros(6)
    for si, wi in zip(s, w):
        c, sn = np.cos(twist_rad(si)), np.sin(twist_rad(si))
        Q = np.column_stack([e1, [c, sn, 0.0], [-sn, c, 0.0]])
        Lam = np.block([[Q, np.zeros((3, 3))], [np.zeros((3, 3)), Q]])
        strain = Lam @ G @ Lam.T @ np.r_[F, (length - si) * np.cross(e1, F)]
        I0 += wi * strain
        I1 += wi * (length - si) * strain
    return I0[:3] + np.cross(I1[3:], e1), I0[3:]


def test_the_twisted_beam_under_a_small_load_is_its_flexibility_integral(tmp_path):
    """Linear statics of the twisted scene against the flexibility integral with the section
    turned by twist_deg = −initial_twist: checks the frames (BeamDyn's x1 = section y, the
    twist table, the BeamDyn order of the 6×6). The twist is linear in s and 16 cubic elements
    hold it to about h⁴ θ''''... (the section fields interpolate cos and sin of it): 1e-6."""
    from beamfx.physics.matrix_sections import from_beamdyn
    from beamfx.scene.beamdyn import read_blade

    result = _run(bd.TWISTED, 16, 3, tmp_path, type="linear_static")
    tip = result.path[-1]["probes"]["tip"]
    _, K, _ = read_blade(bd.FOLDER / "bd_static_twisted_with_k1_primary.dat")
    u, theta = _flexibility_tip(
        [0, -4e6, 0], 10.0, lambda s: -np.radians(9.0 * s), from_beamdyn(K[0])
    )
    assert np.allclose(tip["displacement"], u, rtol=0, atol=1.5e-7 * np.abs(u).max())
    assert np.allclose(tip["rotation_vector"], theta, rtol=0, atol=1.5e-7 * np.abs(theta).max())
    assert u[0] > 2.0  # the sense of BeamDyn's twist: +x (BeamDyn's nonlinear tip: +1.72 m)


def test_the_twisted_beams_root_reactions_balance_the_tip_load(tmp_path):
    """Nonlinear (2 x P3): the root reaction is minus the applied force, and its moment about
    the root is minus (deformed tip − root) × force, to the solver's tolerance (residual
    1e-10 of the load; 1e-9 of |F| and of |F| L here, L = 10 m)."""
    result = _run(bd.TWISTED, 2, 3, tmp_path)
    last = result.path[-1]
    (root,) = last["reactions"].values()
    tip = np.asarray(last["probes"]["tip"]["position"])
    F = np.array([0.0, -4e6, 0.0])
    scale = np.linalg.norm(F)
    assert np.allclose(root["force"], -F, rtol=0, atol=1e-9 * scale)
    arm = tip - np.asarray(root["position"])
    assert np.allclose(root["moment"], -np.cross(arm, F), rtol=0, atol=1e-9 * scale * 10.0)


def test_wiener_milenkovic_parameters_become_the_rotation_vector():
    """c = 4 tan(φ/4) n is the rotation φ about n (BeamDyn's TipRD), up to φ near 2π."""
    n = np.array([2.0, -1.0, 0.5]) / np.linalg.norm([2.0, -1.0, 0.5])
    for phi in (1e-8, 0.3, 1.5, 3.0, 6.0):
        assert np.allclose(bd.rotation_vector(4 * np.tan(phi / 4) * n), phi * n, atol=1e-14)
    assert not bd.rotation_vector(np.zeros(3)).any()
