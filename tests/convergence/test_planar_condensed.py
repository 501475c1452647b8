"""The planar statically condensed model (the plane angle the only unknown): exact roll-ups,
point-force cantilevers against the planar Simo–Reissner model, and the automatic choice."""

from dataclasses import replace

import numpy as np
import pytest
from mpi4py import MPI

from beamfx.analyses.condensed import CondensedModel
from beamfx.analyses.formulation import BeamFormulation, Formulation
from beamfx.analyses.model import BeamModel
from beamfx.analyses.planar_condensed import (
    PlanarCondensedModel,
    build_model,
    chord_increments,
    gauss_increments,
    plane_complex,
)
from beamfx.analyses.static import solve_static
from beamfx.bench._builders import cantilever, straight
from beamfx.bench.classic import ROLL_SECTION, L
from beamfx.geometry.curves import Arc
from beamfx.io import evaluate_points
from beamfx.physics import sections
from beamfx.physics.kinematics import PLANES, Kinematics

XZ = Kinematics(plane="xz")
SEC = sections.rectangle(1e4, 0.5e4, 1.0, 0.1, 0.1, nu=0.0)  # EA / (EI/L²) = 1200: stretch shows


def _tip(cls, spec, steps=10):
    model = cls(spec, extra_points=["b:end"])
    result = solve_static(model, steps=steps)
    return model, result, np.array(evaluate_points(model, ["b:end"])["b:end"]["position"])


def _rollup(turns, elements, degree, kinematics=XZ):
    phi = 2 * np.pi * turns
    moment = (0.0, -phi * ROLL_SECTION.EI_y / L, 0.0)  # about -y: rolls up towards +z
    spec = cantilever(straight(L), ROLL_SECTION, elements, degree, moment=moment)
    exact = np.array([L * np.sin(phi) / phi, 0.0, L * (1 - np.cos(phi)) / phi])
    return replace(spec, kinematics=kinematics), exact


@pytest.mark.parametrize("turns", [0.25, 0.5, 1, 2, 5])
@pytest.mark.parametrize("elements, degree", [(1, 1), (1, 2), (4, 4)])
def test_rollup_is_exact_on_coarse_meshes(turns, elements, degree):
    """θ = M s/EI lies in P_k, so Galerkin gives it exactly (the energy ½EIθ'² − Mθ(L) is
    quadratic: one Newton iteration), and the centre line of a θ linear in the cell is
    integrated in closed form (P1) or by quadrature split to 0.25 rad parts (P2, P4: error of
    the p + 2 point Gauss rule ~1e-16). What is left is round-off: |θ| ≤ 10π times a few
    ulps in θ and in sin/cos of it, ~1e-14 of L; 1e-12 leaves a margin for round-off only
    (the full model's error at 16 x P4 is 8e-13, its 4 x P3 one 2e-5). 4 x P4 caught FFCx's
    table rounding (1e-8, :data:`~beamfx.analyses.condensed.EXACT_TABLES`)."""
    spec, exact = _rollup(turns, elements, degree)
    model, result, x = _tip(PlanarCondensedModel, spec, steps=4)
    assert model.unknowns() == elements * degree + 1  # one angle per node (clamped included)
    assert model.closed_form() == (degree == 1)
    assert np.abs(x - exact).max() / L < 1e-12
    assert result.newton_iterations <= 2 * len(result.steps)
    # no stretch or shear under a pure moment: the Kirchhoff rod gives the same circle
    rod = replace(spec.kinematics, shear=False, stretch=False)
    _, _, x_rod = _tip(PlanarCondensedModel, replace(spec, kinematics=rod), steps=4)
    assert np.abs(x_rod - exact).max() / L < 1e-12


def test_closed_form_chord_matches_quadrature():
    """The closed-form increment of a straight cell (θ linear, a section force, an anisotropic
    compliance) against 200-point Gauss quadrature of x_ξ = R c + σ h R A Rᵀ n, and its Δθ → 0
    limit (no 0/0)."""
    rng = np.random.default_rng(1)
    A = rng.normal(size=(3, 2, 2))
    A = A + A.transpose(0, 2, 1)
    theta0, theta1 = np.array([0.3, -2.0, 1.0]), np.array([7.1, 4.0, 1.0])
    c, h, sign = np.array([1 + 0.5j, -0.2j, 2.0]), np.array([1.2, 0.3, 2.0]), [1, -1, 1]
    n = np.array([0.4 - 1j, 2.0 + 0.1j, -0.3j])
    got = chord_increments(theta0, theta1, c, h, np.array(sign), A, n)
    gx, gw = np.polynomial.legendre.leggauss(200)
    xi, w = (gx + 1) / 2, gw / 2
    for k in range(3):
        th = theta0[k] + (theta1[k] - theta0[k]) * xi
        rn = np.exp(-1j * th) * n[k]  # Rᵀ n
        arn = (A[k, 0, 0] * rn.real + A[k, 0, 1] * rn.imag) + 1j * (
            A[k, 1, 0] * rn.real + A[k, 1, 1] * rn.imag
        )
        x_xi = np.exp(1j * th) * c[k] + sign[k] * h[k] * np.exp(1j * th) * arn
        assert abs(np.sum(w * x_xi) - c[k] - got[k]) < 1e-13


@pytest.mark.parametrize("degree", [2, 3, 4])
def test_numpy_quadrature_matches_the_compiled_one(degree):
    """Straight cells of P2–P4: the centre line's composite Gauss rule in NumPy
    (:func:`gauss_increments`, what :meth:`sync` uses there) against the same rule evaluated
    by the compiled expression of the spatial model (``_quadrature_increments``, what curved
    cells use), at a bent state with a section force and an anisotropic compliance (a
    follower tip force of 5 EI/L²; stretch and shear kept), for 1, 2 and 4 parts: the same
    sums of 20–80 terms of size ≤ h, so the same numbers to round-off (1e-14 of L = 1)."""
    force = (0.0, 0.0, 5 * SEC.EI_y)
    spec = cantilever(straight(1.0), SEC, 4, degree, force=force, follower=True, kinematics=XZ)
    model, _, _ = _tip(PlanarCondensedModel, spec)
    assert model.straight_cells() and not model.closed_form()
    xi = model._xi
    cells, c, h, sign, block, force_expr = model._data()
    theta = model.w.x.array[model._ends(xi)[1]]
    assert np.ptp(theta, axis=1).max() > 0.3  # bent: the parts matter
    n = plane_complex(force_expr.eval(cells).reshape(-1, 3), "xz")
    a, b, normal = PLANES["xz"]
    for parts in (1, 2, 4):
        got = gauss_increments(theta, xi, parts, c, h, sign, block, n)
        compiled = model._quadrature_increments(xi, parts)
        assert np.abs(got.real - compiled[..., a]).max() < 1e-14
        assert np.abs(got.imag - compiled[..., b]).max() < 1e-14
        assert np.abs(compiled[..., normal]).max() < 1e-14
    # the rule converges: 1 part against 4 differs by the rule's error, not round-off
    coarse = gauss_increments(theta, xi, 1, c, h, sign, block, n)
    fine = gauss_increments(theta, xi, 4, c, h, sign, block, n)
    assert np.abs(coarse - fine).max() < 1e-9


def test_curved_cells_keep_the_compiled_quadrature():
    """A plane arc (a quarter circle in xz): its cells are curved, so :meth:`sync` keeps the
    compiled quadrature (the NumPy rule assumes a constant |J| t0)."""
    curve = Arc((0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 0.0, 1.0), 90.0)
    spec = cantilever(curve, SEC, 4, 3, force=(0.0, 0.0, 0.1 * SEC.EI_y), kinematics=XZ)
    model = PlanarCondensedModel(spec)
    assert not model.straight_cells()


@pytest.mark.parametrize("follower", [False, True])
def test_point_force_cantilever_against_the_planar_model(follower):
    """A tip force (0, 0, 5 EI/L²), dead or follower, on a shear- and stretch-flexible beam:
    the condensed angle model converges to the planar Simo–Reissner model's answer (16 x P4,
    converged to ~1e-10) at the Galerkin order 2k of P_k (measured: P2 4.0, P3 5.6–6.0 per
    doubling); the condensed 16 x P3 lies within 1e-9 of it (measured 4e-11 and 1.4e-10)."""
    force = (0.0, 0.0, 5 * SEC.EI_y)
    spec = cantilever(straight(1.0), SEC, 16, 4, force=force, follower=follower, kinematics=XZ)
    _, _, ref = _tip(BeamModel, spec)
    errors = {}
    for p in (2, 3):
        for n in (4, 8, 16):
            coarse = replace(spec, beams=(replace(spec.beams[0], elements=n, degree=p),))
            model, result, x = _tip(PlanarCondensedModel, coarse)
            errors[p, n] = np.abs(x - ref).max()
            assert model.unknowns() == n * p + 1
            assert result.newton_iterations <= 3 * len(result.steps)  # follower: coupled tangent
    for p in (2, 3):
        rate = np.log2(errors[p, 4] / errors[p, 8])
        assert rate > 2 * p - 0.5, (p, errors)
    assert errors[3, 16] < 1e-9


def test_planar_condensed_model_is_a_formulation():
    spec, _ = _rollup(1, 3, 2)
    model = PlanarCondensedModel(spec)
    assert isinstance(model, Formulation) and not isinstance(model, BeamFormulation)
    assert model.unknowns() == 7 and model.w.function_space is model.W
    model.check_state()  # no range: an angle of any size is valid
    with pytest.raises(ValueError, match="planar model"):
        PlanarCondensedModel(replace(spec, kinematics=Kinematics()))


def _scene(load, analysis="static"):
    return f"""
[material]
E = 1e4
nu = 0.0
rho = 1.0
[[beams]]
name = "b"
elements = 2
degree = 2
curve = {{ shape = "line", start = [0, 0, 0], end = [1, 0, 0] }}
section = {{ type = "rectangle", h = 0.1, w = 0.1 }}
[[supports]]
at = "b:start"
fix = "all"
[[loads]]
at = "b:end"
{load}
[analysis]
type = "{analysis}"
[[probes]]
name = "tip"
at = "b:end"
"""


@pytest.mark.parametrize(
    "load, plane, model",
    [
        ("force = [0, 0, 0.1]", "xz", PlanarCondensedModel),  # in the xz plane
        ("force = [0, 0.1, 0.1]", None, CondensedModel),  # out of every plane: 3D condensed
        ('moment = [0, -0.5, 0]\nkind = "follower"', "xz", PlanarCondensedModel),
    ],
)
def test_the_scene_builder_picks_the_planar_condensed_model(tmp_path, load, plane, model):
    """Plane problem and condensed fit: the angle model (log line, results.json say so); a
    load out of the plane keeps the 3D condensed model (rotation vector)."""
    from beamfx.runner import run_scene
    from beamfx.scene import load_scene

    path = tmp_path / "s.toml"
    path.write_text(_scene(load))
    scene = load_scene(path)
    assert scene.condense and scene.model.kinematics.plane == plane
    assert type(build_model(scene.model, MPI.COMM_WORLD, (), True)) is model
    lines = []
    run = run_scene(path, tmp_path / "out", log=lines.append)
    entry = run["model"]["condensing"]
    planar = model is PlanarCondensedModel
    assert entry["model"] == ("planar_condensed" if planar else "condensed")
    assert run["model"]["unknowns"] == (5 if planar else 15) == entry["unknowns"]
    assert any(("planar statically condensed" in x) == planar for x in lines if "condensed" in x)


def test_a_static_run_builds_no_inertia_and_splits_its_time(tmp_path):
    """The inertia field of a static model is made at first read only (a static run reads
    none), then with the section's values; results.json's wall_time_s has the model build and
    the per-step output (probes, reactions, frames), which fit in the whole run."""
    from beamfx.analyses.discretisation import Deferred
    from beamfx.runner import run_scene
    from beamfx.scene import load_scene

    path = tmp_path / "s.toml"
    path.write_text(_scene("force = [0, 0, 0.1]"))
    scene = load_scene(path)
    model = build_model(scene.model, MPI.COMM_WORLD, (), True)
    solve_static(model, steps=2)
    d = model.discretisation
    assert isinstance(d.mass, Deferred)
    rho_A = d.inertia.x.array.reshape(-1, 4)[:, 0]
    assert d.inertia is d.inertia and not isinstance(d.mass, Deferred)
    assert np.allclose(rho_A, 1.0 * 0.1 * 0.1, rtol=1e-14)
    seconds = run_scene(path, tmp_path / "out", log=lambda *a: None)["wall_time_s"]
    parts = ("model", "output_probes", "output_reactions", "output_frames")
    assert all(seconds[k] > 0 for k in parts)
    assert sum(seconds[k] for k in parts) + seconds["compile"] < seconds["run"]


def test_a_modal_plane_problem_is_neither_planar_nor_condensed(tmp_path):
    from beamfx.scene import load_scene

    path = tmp_path / "s.toml"
    path.write_text(_scene("force = [0, 0, 0.1]", "modal"))
    scene = load_scene(path)
    assert not scene.condense and scene.model.kinematics.plane is None


def test_compliance_blocks_match_the_ufl_frame():
    """The in-plane block of A = Λ0 C_N⁻¹ Λ0ᵀ that the closed-form centre line uses, built in
    NumPy per cell, equals the UFL expression of the model's own Λ0 and compliance (an
    inclined beam in the xz plane, shear and stretch kept) to round-off."""
    import ufl
    from dolfinx import fem

    from beamfx.geometry import Line
    from beamfx.physics.kinematics import PLANES

    force = (0.0, 0.0, 5 * SEC.EI_y)
    spec = cantilever(Line((0, 0, 0), (0.6, 0, 0.8)), SEC, 5, 1, force=force, kinematics=XZ)
    model = PlanarCondensedModel(spec, extra_points=["b:end"])
    assert model.closed_form()
    cells, _, _, _, block, _ = model._data()
    d = model.discretisation
    A = d.Lam0 * model.compliance * d.Lam0.T
    a, b, _ = PLANES["xz"]
    expr = fem.Expression(ufl.as_vector([A[a, a], A[a, b], A[b, b]]), np.array([[0.5]]))
    want = expr.eval(cells).reshape(-1, 3)
    got = np.stack([block[:, 0, 0], block[:, 0, 1], block[:, 1, 1]], axis=1)
    assert np.allclose(block[:, 0, 1], block[:, 1, 0], rtol=0, atol=0)
    assert np.abs(got - want).max() <= 1e-15 * np.abs(want).max()
