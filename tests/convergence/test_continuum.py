"""The continuum-based (ANCF-style) beam: Timoshenko limit, Poisson locking factor, objectivity,
full-circle roll-up and free-free bending against the Reissner beam."""

import numpy as np
import pytest

from beamfx.bench import schwab_meijaard_2009 as sm
from beamfx.continuum.model import lame
from beamfx.continuum.solve import ContinuumBeam, ContinuumSpec
from beamfx.physics.sections import cowper_rectangle

E, NU, RHO = sm.E, sm.NU, sm.RHO
G = E / (2 * (1 + NU))
H, W, L = 0.02, 0.01, 1.0  # SM 2.1's section (h along e3 = z, w along e2 = y)
A, I_Y = W * H, W * H**3 / 12


def cantilever(variant, force=(0, 0, 0), moment=(0, 0, 0), elements=2, degree=3):
    spec = ContinuumSpec(E, NU, RHO, H, W, elements=elements, degree=degree, variant=variant,
                         force=force, moment=moment)  # fmt: skip
    beam = ContinuumBeam(spec)
    beam.solve_static(linear=True)
    return beam.end_values()


def test_corrected_variant_is_the_timoshenko_cantilever():
    """Tip force F on the linear cantilever: u = F L³/(3EI) + F L/(k G A), k Cowper's.

    The corrected variant's linear bending is Timoshenko's (E I, k G A) and its section fields
    decouple for a doubly symmetric section. The exact solution (w cubic, θ quadratic) lies in
    P3, and the reduced p-point rule of the axis energy integrates the exact (constant) shear
    strain times the test strains (degree ≤ p) exactly, so 2 × P3 returns it to round-off
    (condition number ~ E A L² / E I = 3e4 per element): tolerance 1e-9.
    """
    F = 1e4
    u = cantilever("corrected", force=(0, 0, F))["displacement"][2]
    exact = F * L**3 / (3 * E * I_Y) + F * L / (cowper_rectangle(NU) * G * A)
    assert u == pytest.approx(exact, rel=1e-9)


def test_full_variant_locks_by_the_poisson_factor():
    """Pure moment M_y: φ = M L/(E_b I) with E_b = E for the Poisson-free energy and
    E_b = λ + 2μ for plain St Venant–Kirchhoff.

    Derivation: x = r + η d2 + ζ d3 makes E_22 = ½(|d2|² − 1) and E_33 = ½(|d3|² − 1)
    constant over the section, while bending makes E_11 = ε − κζ linear in ζ. The ζ-linear part
    of ∫_A ψ dA, ψ = λ/2 (tr E)² + μ E:E, meets no ζ-linear transverse strain to relax it, so it
    acts as a uniaxial strain: ∫ (λ/2 + μ) κ² ζ² dA = ½ (λ + 2μ) I κ². The bending stiffness is
    (λ + 2μ) I, stiffer than E I by (1 − ν)/((1 + ν)(1 − 2ν)) = 1.346 at ν = 0.3. A constant
    curvature is exact in P3, so the factor holds to round-off: tolerance 1e-9.
    """
    M = 1e4
    lmbda, mu = lame(E, NU)
    phi_free = cantilever("corrected", moment=(0, M, 0))["rotation_vector"][1]
    phi_full = cantilever("full", moment=(0, M, 0))["rotation_vector"][1]
    assert phi_free == pytest.approx(M * L / (E * I_Y), rel=1e-9)
    assert phi_full / phi_free == pytest.approx(E / (lmbda + 2 * mu), rel=1e-9)
    assert phi_free / phi_full == pytest.approx((1 - NU) / ((1 + NU) * (1 - 2 * NU)), rel=1e-9)


def test_superposed_rigid_motion_is_strain_free():
    """Objectivity: a finite rigid rotation (90° about a skew axis) plus a translation of the
    whole beam, r → R X + c, d_i → R e_i, has zero strain, hence zero energy and residual."""
    import dolfinx.fem.petsc as fp
    from dolfinx import fem
    from petsc4py import PETSc
    from scipy.spatial.transform import Rotation

    from beamfx.solvers.forms import compile_form

    beam = ContinuumBeam(ContinuumSpec(E, NU, RHO, H, W, elements=2, degree=3, clamped=False))
    R = Rotation.from_rotvec(np.pi / 2 * np.array([1.0, 2.0, 3.0]) / np.sqrt(14)).as_matrix()
    _, e2, e3 = beam.frame
    c = np.array([0.3, -0.2, 0.1])
    Q = R - np.eye(3)

    def rigid(x):
        u = Q @ x + c[:, None]
        return np.vstack([u, np.tile((Q @ e2)[:, None], x.shape[1]),
                          np.tile((Q @ e3)[:, None], x.shape[1])])  # fmt: skip

    beam.w.interpolate(rigid)
    energy = beam.comm.allreduce(fem.assemble_scalar(compile_form(beam.energy())))
    residual = fp.assemble_vector(compile_form(beam.F))
    residual.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    # scale: the energy of a unit axial strain, E A L / 2, and its force E A
    assert abs(energy) < 1e-12 * E * A * L
    assert residual.norm() < 1e-9 * E * A
    residual.destroy()


def test_rollup_closes_the_circle():
    """Full circle, M = 2πEI/L (follower couple, 8 load steps), L/h = 1000, corrected variant,
    8 and 16 cubic elements.

    The continuum model's own pure-bending state (uniform, no discretisation,
    :func:`beamfx.bench.continuum.uniform_bending`) misses the start point by 1.25e-5 L: the
    St Venant–Kirchhoff fibres shorten the axis by O((κh)²). The finite elements converge to
    that state, at O(h⁴) or faster for P3 nodal values: the error at 16 elements must be 16
    times below the one at 8, and below 1e-6 L (measured: 2.6e-5 and 3.9e-7). The tip is then
    back at the start within the model's miss plus that bound.
    """
    from beamfx.bench.continuum import uniform_bending

    h = w = 1e-3
    M = 2 * np.pi * E * w * h**3 / 12 / L
    _, own = uniform_bending("corrected", E, NU, h, w, L, M)
    assert np.linalg.norm(own) / L == pytest.approx(1.25e-5, rel=0.01)
    miss = {}
    for n in (8, 16):
        spec = ContinuumSpec(E, NU, RHO, h, w, elements=n, degree=3, variant="corrected",
                             moment=(0, -M, 0), follower=True)  # fmt: skip
        beam = ContinuumBeam(spec)
        beam.solve_static(steps=8)
        tip = np.array(beam.end_values()["position"])[[0, 2]]
        miss[n] = np.linalg.norm(tip - own) / L
    assert miss[16] < miss[8] / 16
    assert miss[16] < 1e-6
    assert np.linalg.norm(tip) / L < np.linalg.norm(own) / L + 1e-6


def test_free_free_bending_matches_the_reissner_beam():
    """SM 2.8 (free-free, square 20 mm): the first bending frequency of the corrected variant
    against the Reissner beam, both 8 × P3.

    In linear bending the corrected variant is the Reissner beam's Timoshenko beam (E I, k G A,
    ρA, rotary ρI from the mass of d3), the section fields decouple, and both integrate the
    shear on p Gauss points: the same discrete bending problem. Tolerance 1e-6, far above the
    eigen-solver's 1e-10 and far below the effects at stake (shear and rotary inertia 1.4e-3,
    Poisson locking 16 %). Also: exactly six rigid-body modes below it (the reduced axis rule
    adds no mechanism).
    """
    from beamfx.analyses.modal import assemble_pair, free_shift, solve_modes
    from beamfx.analyses.model import BeamModel
    from beamfx.bench import schwab_meijaard_eigen as se
    from beamfx.bench._builders import straight
    from beamfx.solvers.eigen import solve_eigen
    from beamfx.solvers.forms import compile_form
    from beamfx.spec import Beam, Model

    target = se.THEORY_28["omega_B1"]
    reissner = BeamModel(Model(beams=(Beam("b", straight(1.0), se.S28, 8, 3),)))
    omega_beam = solve_modes(reissner, 1, target=target**2, prefix="test_ct_bm_").omega[0]

    spec = ContinuumSpec(se.E, se.NU, se.RHO, 0.02, 0.02, elements=8, degree=3, clamped=False)
    beam = ContinuumBeam(spec)
    omega, _ = beam.modes({"B1": ("bending", target)})
    assert omega["B1"] == pytest.approx(omega_beam, rel=1e-6)

    K, Mm = assemble_pair(compile_form(beam.J), compile_form(beam.mass()), beam.bcs)
    pairs = solve_eigen(K, Mm, 8, 0.0, "test_ct_eig_", shift=free_shift(K, Mm))
    w = np.sqrt(np.abs(pairs.values.real))
    assert np.sum(w < 1e-3 * omega["B1"]) == 6
    assert np.min(w[w >= 1e-3 * omega["B1"]]) == pytest.approx(omega["B1"], rel=1e-9)
    for obj in (K, Mm, *pairs.vectors):
        obj.destroy()
