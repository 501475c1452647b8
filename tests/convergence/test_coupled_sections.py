r"""Coupled (6×6) sections against exact results.

**The flexibility integral** (linear Timoshenko kinematics, a straight cantilever of length L
clamped at s = 0, section axes Λ0 constant along it, the 6×6 stiffness C constant). The
resultant of the loads beyond s, reduced to the point s of the axis, is (section axes)

    r(s) = (n(s), m(s)),  n = F + q (L − s),  m = M + (L − s) e1 × F + ½ (L − s)² e1 × q

for a tip force F and moment M and a distributed force q per length. The sectional strains
are ε(s) = (γ, κ) = C⁻¹ r(s), and the kinematics of the linear beam are θ' = κ and
u' = γ + θ × e1 (Γ = u' + e1 × θ), with u = θ = 0 at the clamp. So

    θ(L) = ∫₀ᴸ κ ds,   u(L) = ∫₀ᴸ γ ds + ∫₀ᴸ θ(s) ds × e1 = ∫₀ᴸ γ ds + (∫₀ᴸ (L − s) κ ds) × e1,

integrated here by Gauss–Legendre quadrature exact for the polynomial integrands.
"""

import numpy as np
import pytest

from beamfx.analyses.modal import solve_modes
from beamfx.analyses.model import BeamModel
from beamfx.analyses.static import solve_static
from beamfx.geometry import Line
from beamfx.geometry.frames import section_axes_at
from beamfx.io import evaluate_points
from beamfx.physics.kinematics import Kinematics
from beamfx.physics.matrix_sections import MatrixSection, offset_mass, offset_stiffness
from beamfx.physics.sections import Section
from beamfx.spec import Beam, DistributedLoad, Model, PointLoad, Support

CLAMP = ("ux", "uy", "uz", "rx", "ry", "rz")
LINEAR = Kinematics(finite=False)


def coupled_stiffness(scale=(1e6, 3e5, 4e5, 2e3, 5e3, 8e3), seed=1):
    """A fully coupled, positive definite 6×6 stiffness (every off-diagonal entry non-zero:
    extension–twist, bending–twist, shear–bending...)."""
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(6, 6)) * 0.3
    d = np.sqrt(np.asarray(scale, float))
    C = d[:, None] * (np.eye(6) + 0.5 * (X + X.T)) * d[None, :]
    assert np.linalg.eigvalsh(C).min() > 0
    return 0.5 * (C + C.T)


def flexibility_tip(C, L, F, M, q=(0.0, 0.0, 0.0), breaks=(), points=20):
    """(u(L), θ(L)) of the module doc, section axes. ``C`` is a 6×6 matrix or a function of s
    (then integrated by ``points`` Gauss points between ``breaks``, where it has kinks)."""
    F, M, q = (np.asarray(x, float) for x in (F, M, q))
    e1 = np.array([1.0, 0.0, 0.0])
    edges = np.unique(np.r_[0.0, breaks, L])
    x, w = np.polynomial.legendre.leggauss(points)
    h = np.diff(edges)
    s = (edges[:-1, None] + h[:, None] * (x[None, :] + 1) / 2).ravel()
    w = (h[:, None] * w[None, :] / 2).ravel()
    a = L - s
    n = F[None, :] + a[:, None] * q[None, :]
    m = M + a[:, None] * np.cross(e1, F) + 0.5 * a[:, None] ** 2 * np.cross(e1, q)
    Cs = np.array([C(si) for si in s]) if callable(C) else np.broadcast_to(C, (len(s), 6, 6))
    eps = np.linalg.solve(Cs, np.c_[n, m][:, :, None])[:, :, 0]
    gamma, kappa = eps[:, :3], eps[:, 3:]
    theta = w @ kappa
    u = w @ gamma + np.cross(w @ (a[:, None] * kappa), e1)
    return u, theta


def solve_cantilever(section, elements, degree, F, M, q=(0, 0, 0), direction=(1, 0, 0), twist=0):
    """Tip displacement and rotation (section axes) of the linear cantilever of length 2."""
    L = 2.0
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    curve = Line((0.0, 0.0, 0.0), tuple(L * d))
    orient = (0.0, 0.0, 1.0) if abs(d[2]) < 0.9 else (1.0, 0.0, 0.0)
    Lam = section_axes_at(curve, 0.0, orient, twist)
    beam = Beam("b", curve, section, elements, degree, orient, twist)
    spec = Model(
        beams=(beam,),
        supports=(Support("b:start", CLAMP),),
        point_loads=(PointLoad("b:end", tuple(Lam @ F), tuple(Lam @ M)),),
        distributed_loads=(DistributedLoad("b", tuple(Lam @ np.asarray(q, float))),)
        if np.any(q)
        else (),
        kinematics=LINEAR,
    )
    model = BeamModel(spec, extra_points=["b:end"])
    solve_static(model, steps=1)
    tip = evaluate_points(model, ["b:end"])["b:end"]
    return Lam.T @ np.asarray(tip["displacement"]), Lam.T @ np.asarray(tip["rotation_vector"])


F_TIP, M_TIP, Q = np.array([10.0, 20.0, -15.0]), np.array([5.0, -3.0, 4.0]), np.array([3, -8, 6.0])


def _error(C, elements, degree, q=(0, 0, 0), **frame):
    u, th = solve_cantilever(
        MatrixSection(C, np.zeros((6, 6))), elements, degree, F_TIP, M_TIP, q, **frame
    )
    u_ref, th_ref = flexibility_tip(C, 2.0, F_TIP, M_TIP, q)
    return max(
        np.abs(u - u_ref).max() / np.abs(u_ref).max(),
        np.abs(th - th_ref).max() / np.abs(th_ref).max(),
    )


def test_coupled_cantilever_tip_loads_exact_from_quadratic_elements_on_a_skew_twisted_beam():
    """Tip loads: γ and κ are linear, u cubic; the reduced rule makes P2 and P3 exact (the
    section force is constant, its compliance part integrates exactly), P1 converges as h²."""
    C = coupled_stiffness()
    frame = {"direction": (1.0, 2.0, -0.5), "twist": 35.0}
    for degree in (2, 3):
        for elements in (1, 2, 5):
            assert _error(C, elements, degree, **frame) < 1e-11
    e = [_error(C, n, 1, **frame) for n in (4, 8, 16)]
    assert np.allclose(np.log2(np.array(e[:-1]) / e[1:]), 2.0, atol=0.05), e


def test_coupled_cantilever_distributed_load_exact_from_quadratic_elements():
    """A distributed force: u is quartic, yet the tip of P2 and P3 is exact (as for the
    diagonal Timoshenko element with the reduced rule); P1 converges as h²."""
    C = coupled_stiffness(seed=2)
    for degree in (2, 3):
        assert _error(C, 2, degree, q=Q) < 1e-11
    e = [_error(C, n, 1, q=Q) for n in (4, 8, 16)]
    assert np.allclose(np.log2(np.array(e[:-1]) / e[1:]), 2.0, atol=0.05), e


def _station_section():
    """Three stations (s/L = 0, 0.5, 1) of different coupled matrices (a tapering section
    whose coupling changes along it)."""
    C0 = coupled_stiffness(seed=4)
    Cs = [f * C0 + 0.2 * coupled_stiffness(seed=k) for k, f in ((5, 2.0), (6, 1.0), (7, 0.6))]
    return MatrixSection(Cs, np.zeros((3, 6, 6)), (0.0, 0.5, 1.0), 2.0)


def test_station_tables_converge_to_the_flexibility_integral_of_the_interpolated_matrices():
    """Entry-wise linear C(s) between stations (a vertex at each station): the tip converges
    to the integral of C(s)⁻¹ r(s) (no polynomial) at the rate h^2p of the element's nodal
    values: measured 1.99 (P1), 3.95 (P2), 5.88 (P3) from 8 to 16 elements."""
    sec = _station_section()
    u_ref, th_ref = flexibility_tip(
        lambda s: sec.matrices_at([s])[0][0], 2.0, F_TIP, M_TIP, Q, (1.0,)
    )

    def error(n, p):
        u, th = solve_cantilever(sec, n, p, F_TIP, M_TIP, Q)
        return max(
            np.abs(u - u_ref).max() / np.abs(u_ref).max(),
            np.abs(th - th_ref).max() / np.abs(th_ref).max(),
        )

    for p, order in ((2, 4.0), (3, 6.0)):
        e = [error(n, p) for n in (4, 8, 16)]
        rates = np.log2(np.array(e[:-1]) / e[1:])
        assert rates[-1] > order - 0.5 and e[-1] < 1e-5, (p, e, rates)


def test_thin_coupled_cantilever_does_not_lock():
    """A slender coupled section (force stiffness 1e6 times the bending ones per L²) under a
    distributed load: the quadratic element with the split energy keeps its exact tip on 4
    elements. Integrating the section-force part with the full rule instead gave the errors
    1.7e-2, 4.3e-3, 1.1e-3 on 4, 8, 16 elements (shear locking, measured once)."""
    C = coupled_stiffness(scale=(1e10, 3e9, 4e9, 2e3, 5e3, 8e3), seed=3)
    assert _error(C, 4, 2, q=Q) < 1e-11


def _offset_models(kinematics, centre=(0.03, -0.05)):
    """The same beam twice: a diagonal section on the line through the centre (0, y, z), and
    a matrix section on the x axis with the tension, shear and mass centres there."""
    s = Section(2e7, 6e6, 7e6, 3e3, 5e3, 9e3, rho_A=2.0, rho_I=(1e-3, 4e-4, 6e-4))
    C = offset_stiffness(s.EA, s.GA_y, s.GA_z, s.GJ, s.EI_y, s.EI_z, centre, centre)
    M = offset_mass(s.rho_A, s.rho_I, centre)
    y, z = centre

    def model(section, a):
        beam = Beam("b", Line(a, (a[0] + 1.5, a[1], a[2])), section, 6, 3, (0.0, 0.0, 1.0))
        return Model(beams=(beam,), supports=(Support("b:start", CLAMP),), kinematics=kinematics)

    return model(s, (0.0, y, z)), model(MatrixSection(C, M), (0.0, 0.0, 0.0))


@pytest.mark.parametrize("finite", [False, True])
def test_offset_centres_give_the_frequencies_of_the_translated_beam(finite):
    """Offsets by the standard transformations: a beam whose tension, shear and mass centres
    lie at ρ off its reference line is the diagonal beam on the line through ρ; the two
    discrete problems are the same up to the map u_ref = u − θ × ρ, so the frequencies agree
    to round-off on any mesh."""
    a, b = _offset_models(Kinematics(finite=finite))
    fa = solve_modes(BeamModel(a), 8).hz
    fb = solve_modes(BeamModel(b), 8).hz
    assert np.allclose(fa, fb, rtol=1e-9), (fa, fb)


def test_free_beam_with_offset_mass_has_six_rigid_body_modes():
    """No supports: six modes at zero frequency, whatever the offsets, then the elastic ones
    of the translated beam."""
    a, b = _offset_models(Kinematics())
    free = [Model(beams=x.beams, kinematics=x.kinematics) for x in (a, b)]
    fa, fb = (solve_modes(BeamModel(x), 8).hz for x in free)
    assert np.all(np.abs(fb[:6]) < 1e-4 * fb[6]), fb
    assert np.allclose(fa[6:], fb[6:], rtol=1e-8), (fa, fb)


def test_offset_centres_spin_like_the_translated_beam():
    """The two beams of the offsets test in a frame spinning about the z axis through the
    origin (off both beams: the offset one's reference line passes through it, the other's
    does not). The steady states differ only by the nonlinear map u_ref = u − (R − I) ρ, which
    the elements represent to their order: at 100 rad/s (the first frequency rises from 12.4
    to 17.9 Hz) they differed by 3.5e-9 of the highest, at rest by 4e-13."""
    from beamfx.analyses.rotating import RotatingFrame, solve_rotating_modes, solve_steady

    freqs = []
    for spec in _offset_models(Kinematics()):
        frame = RotatingFrame(BeamModel(spec), axis=(0.0, 0.0, 1.0), hub=(0.0, 0.0, 0.0))
        solve_steady(frame, 100.0, steps=4)
        freqs.append(solve_rotating_modes(frame, 6).hz)
        frame.destroy()
    assert np.allclose(freqs[0], freqs[1], rtol=1e-7), freqs


def _twisted_error(elements, degree, section_C, total_deg=90.0):
    """Relative tip error of the linear cantilever (length 2, along x) whose twist grows
    linearly from 0 to ``total_deg``, against the flexibility integral with the section
    matrix turned with the frame, C_g(s) = Q C Qᵀ, Q = diag(Λ0(s), Λ0(s))."""
    L = 2.0

    def twist(s):
        return total_deg * np.asarray(s, float) / L

    def Lam(s):
        c, sn = np.cos(np.deg2rad(twist(s))), np.sin(np.deg2rad(twist(s)))
        return np.array([[1.0, 0, 0], [0, c, -sn], [0, sn, c]])

    def C_global(s):
        Q = np.kron(np.eye(2), Lam(s))
        return Q @ section_C @ Q.T

    u_ref, th_ref = flexibility_tip(C_global, L, F_TIP, M_TIP, Q)
    beam = Beam(
        "b",
        Line((0, 0, 0), (L, 0, 0)),
        MatrixSection(section_C, np.zeros((6, 6))),
        elements,
        degree,
        (0.0, 0.0, 1.0),
        twist,
    )
    spec = Model(
        beams=(beam,),
        supports=(Support("b:start", CLAMP),),
        point_loads=(PointLoad("b:end", tuple(F_TIP), tuple(M_TIP)),),
        distributed_loads=(DistributedLoad("b", tuple(Q)),),
        kinematics=LINEAR,
    )
    model = BeamModel(spec, extra_points=["b:end"])
    solve_static(model, steps=1)
    tip = evaluate_points(model, ["b:end"])["b:end"]
    u, th = np.asarray(tip["displacement"]), np.asarray(tip["rotation_vector"])
    return max(
        np.abs(u - u_ref).max() / np.abs(u_ref).max(),
        np.abs(th - th_ref).max() / np.abs(th_ref).max(),
    )


def test_span_varying_twist_converges_to_the_twisted_flexibility_integral():
    """twist_deg as a function of s (0 to 90° along the beam) on a coupled section: the frame
    turns pointwise, and the tip converges at h^2p to the integral of the turned compliance
    (measured 4.66e-3, 4.17e-4, 2.91e-5 with P2 and 7.08e-5, 1.54e-6, 2.67e-8 with P3 on 4, 8,
    16 elements)."""
    C = coupled_stiffness(seed=8)
    for p, order, bound in ((2, 4.0, 1e-4), (3, 6.0, 1e-7)):
        e = [_twisted_error(n, p, C) for n in (4, 8, 16)]
        rates = np.log2(np.array(e[:-1]) / e[1:])
        assert rates[-1] > order - 0.5 and e[-1] < bound, (p, e, rates)


def test_coupled_energy_is_objective_and_its_tangent_symmetric_positive():
    """Finite kinematics with a coupled section on a skew, twisted beam: a superposed rigid
    motion (u = (R − I) X + c, q = that rotation) stores no energy and leaves no internal
    force (round-off), and the tangent at rest is symmetric and, clamped, positive definite."""
    import dolfinx.fem.petsc as fp
    from dolfinx import fem
    from mpi4py import MPI

    from beamfx.analyses.modal import is_symmetric
    from beamfx.physics.rotations import np_quaternion
    from beamfx.solvers.forms import compile_form

    C = coupled_stiffness(seed=9)
    beam = Beam(
        "b", Line((0, 0, 0), (1.0, 2.0, -0.5)), MatrixSection(C, np.eye(6)), 4, 3, None, 30.0
    )
    model = BeamModel(Model(beams=(beam,), supports=(Support("b:start", CLAMP),)))
    axis, angle = np.array([0.3, -0.5, 0.8]), 2.2
    q = np_quaternion(axis / np.linalg.norm(axis), angle)
    R = np.array(
        [[1 - 2 * (q[2] ** 2 + q[3] ** 2), 2 * (q[1] * q[2] - q[0] * q[3]), 2 * (q[1] * q[3] + q[0] * q[2])],
         [2 * (q[1] * q[2] + q[0] * q[3]), 1 - 2 * (q[1] ** 2 + q[3] ** 2), 2 * (q[2] * q[3] - q[0] * q[1])],
         [2 * (q[1] * q[3] - q[0] * q[2]), 2 * (q[2] * q[3] + q[0] * q[1]), 1 - 2 * (q[1] ** 2 + q[2] ** 2)]]
    )  # fmt: skip
    K0 = fp.assemble_matrix(compile_form(model.J), bcs=model.bcs, diagonal=1.0)
    K0.assemble()
    assert is_symmetric(K0, 1e-12)
    dense = K0.convert("dense").getDenseArray()
    assert np.linalg.eigvalsh(0.5 * (dense + dense.T)).min() > 0
    V0, m0 = model.W.sub(0).collapse()
    _, m1 = model.W.sub(1).collapse()
    X = V0.tabulate_dof_coordinates()
    u = X @ (R - np.eye(3)).T + np.array([0.1, -0.2, 0.3])
    model.w.x.array[np.asarray(m0)] = u.ravel()
    model.w.x.array[np.asarray(m1)] = np.tile(q, len(m1) // 4)
    energy = model.comm.allreduce(fem.assemble_scalar(fem.form(model.Pi)), op=MPI.SUM)
    F = fp.assemble_vector(compile_form(model.F))
    scale = np.abs(C).max()
    assert abs(energy) < 1e-10 * scale and F.norm() < 1e-9 * scale, (energy, F.norm())


def test_vertices_at_stations_hold_the_table_exactly():
    """A station at s/L = 0.37, inside a cell of a uniform mesh: with vertices_at_stations the
    mesh gets a vertex there and the tip converges at h^2p as for aligned stations; without,
    the DG_p interpolant rounds the kink and the tip error is much larger on the same
    number of elements (measured with P3 on 4, 8, 16 elements: 1.2e-5, 3.1e-8, 5.4e-10 with
    the vertex, 1.8e-4, 1.6e-4, 6.8e-5 without)."""
    from dataclasses import replace

    sec = replace(_station_section(), stations=(0.0, 0.37, 1.0))
    u_ref, th_ref = flexibility_tip(
        lambda s: sec.matrices_at([s])[0][0], 2.0, F_TIP, M_TIP, Q, (0.74,)
    )

    def error(section, n):
        u, th = solve_cantilever(section, n, 3, F_TIP, M_TIP, Q)
        return max(
            np.abs(u - u_ref).max() / np.abs(u_ref).max(),
            np.abs(th - th_ref).max() / np.abs(th_ref).max(),
        )

    aligned = [error(replace(sec, vertices_at_stations=True), n) for n in (4, 8, 16)]
    rounded = [error(sec, n) for n in (4, 8, 16)]
    assert np.log2(aligned[-2] / aligned[-1]) > 5.5 and aligned[-1] < 1e-8, aligned
    assert all(r > 10 * a for r, a in zip(rounded, aligned)), (rounded, aligned)
