"""Beams on a spinning hub: steady state, gyroscopic modes, Campbell diagram (Schwab & Meijaard
2009, 2.10, and closed-form results for a uniform cantilever)."""

import json
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI
from scipy.integrate import solve_bvp
from scipy.optimize import brentq

from beamfx.analyses.campbell import campbell
from beamfx.analyses.modal import solve_modes
from beamfx.analyses.model import BeamModel
from beamfx.analyses.rotating import (
    RotatingFrame,
    assemble_operators,
    axis_fraction,
    solve_rotating_modes,
    solve_steady,
)
from beamfx.bench import schwab_meijaard_rotating as smr
from beamfx.bench._builders import CLAMP, straight
from beamfx.physics import sections
from beamfx.physics.kinematics import Kinematics
from beamfx.runner import run_scene
from beamfx.solvers.snes import SolveFailed
from beamfx.spec import Beam, Model, Support

E, RHO = smr.E, smr.RHO
GAUSS_X, GAUSS_W = np.polynomial.legendre.leggauss(60)
X01, W01 = (GAUSS_X + 1) / 2, GAUSS_W / 2  # Gauss-Legendre on [0, 1]


def cantilever_mode(b, x):
    """φ, φ', φ'' of the clamped-free mode with root β = b (L = 1), not normalised."""
    s = (np.cosh(b) + np.cos(b)) / (np.sinh(b) + np.sin(b))
    bx = b * np.asarray(x)
    return (
        np.cosh(bx) - np.cos(bx) - s * (np.sinh(bx) - np.sin(bx)),
        b * (np.sinh(bx) + np.sin(bx) - s * (np.cosh(bx) - np.cos(bx))),
        b**2 * (np.cosh(bx) + np.cos(bx) - s * (np.sinh(bx) + np.sin(bx))),
    )


def clamped_free_modes(n):
    """β_k (L = 1) and (φ, φ', φ'') at X01 of the first n cantilever modes, ∫φ² = 1."""
    betas = np.array(
        [
            brentq(
                lambda b: np.cos(b) * np.cosh(b) + 1, (k - 0.5) * np.pi - 1, (k - 0.5) * np.pi + 1
            )
            for k in range(1, n + 1)
        ]
    )
    modes = []
    for b in betas:
        values = cantilever_mode(b, X01)
        norm = np.sqrt(np.sum(W01 * values[0] ** 2))
        modes.append(tuple(v / norm for v in values))
    return betas, modes


def southwell_coefficients(n=6):
    """K_s and K_2 of the first flap mode, ω²/ω0² = 1 + K_s α² − K_2 α⁴ + ..., α = Ω/ω0:
    first- and second-order perturbation of ω² by the centrifugal stiffness
    ∫ ρAΩ²(L² − X²)/2 v'² (the same K_2 for lead-lag, whose extra −ρAΩ² v² is a multiple
    of the mass and shifts ω² without changing the modes)."""
    betas, modes = clamped_free_modes(n)
    N = (1 - X01**2) / 2
    V = np.array([[np.sum(W01 * N * a[1] * b[1]) for b in modes] for a in modes])
    lam = betas**4
    return V[0, 0], lam[0] * np.sum(V[0, 1:] ** 2 / (lam[1:] - lam[0]))


def blade(n, p, extensible, f=smr.F_STIFF, fix=CLAMP, section=None):
    """SM 2.10's beam (Euler-Bernoulli limit: shear, and unless ``extensible`` extension,
    f EI/L² stiff) with no rotary inertia, spinning about z through the root."""
    spec = smr.blade_model(n, p, f, extensible)
    if section is not None or fix is not CLAMP:
        spec = Model(
            beams=(Beam("b", straight(1.0), section or spec.beams[0].section, n, p),),
            supports=(Support("b:start", fix),),
            kinematics=spec.kinematics,
        )
    model = BeamModel(spec)
    return model, RotatingFrame(model, rotary="none")


def flap_lag(frame, alpha):
    flap, lag, _ = smr.first_flap_and_lead_lag(frame, alpha)
    return flap, lag


def test_southwell_relation_with_its_second_order_term():
    """Southwell: ω² = ω0² + K_s Ω² (flap) and ω0² + (K_s − 1) Ω² (lead-lag), K_s = 1.19334,
    the first-order perturbation; the next term −K_2 Ω⁴/ω0² (K_2 = 0.0147) from the modal sum.

    Inextensible Euler-Bernoulli limit (the bench's extrapolation in the shear stiffness), 8
    quartic elements; each ratio is taken to the same mesh's zero-speed frequency, which
    leaves ~3e-8 in the ratios (see the bench), so ~6e-6 in a coefficient at Ω/ω0 = 0.1 (flap
    at α = 0.1; lead-lag at α = 1, where Ω is a tenth of the in-plane ω0). The remainder of
    the expansion, K_3 (Ω/ω0)², is ~2e-7: tolerance 2e-5. Southwell alone is off by
    K_2/100 = 1.5e-4, from above (Rayleigh quotient of the non-rotating mode). At α = 1 the
    flap ratio lies between the two- and the one-term expansions (an alternating series).
    """
    K_s, K_2 = southwell_coefficients()
    assert K_s == pytest.approx(1.193336, abs=1e-6) and K_2 == pytest.approx(0.01468, abs=1e-4)
    r, *_ = smr.rigid_limit_ratios(8, 4, False, (0.0, 0.1, 1.0))
    flap = np.array([r[f"flap alpha={a:g}"] for a in (0.0, 0.1, 1.0)])
    lag = np.array([r[f"lead_lag alpha={a:g}"] for a in (0.0, 0.1, 1.0)])
    K_flap = ((flap[1] / flap[0]) ** 2 - 1) / 0.1**2
    assert abs(K_flap - (K_s - K_2 * 0.1**2)) < 2e-5, (K_flap, K_s)
    assert K_s - 2e-4 < K_flap < K_s
    a2 = (smr.OMEGA_BY / smr.OMEGA_BZ) ** 2  # (Ω/ω0_lag)² at α = 1: 0.01
    K_lag = ((lag[2] / lag[0]) ** 2 - 1) / a2
    assert abs(K_lag - (K_s - 1 - K_2 * a2)) < 2e-5, (K_lag, K_s - 1)
    assert K_s - 1 - 2e-4 < K_lag < K_s - 1
    r2 = (flap[2] / flap[0]) ** 2
    assert 1 + K_s - K_2 < r2 < 1 + K_s, r2


def _extension_terms(omega0):
    """First-order change of the lead-lag Southwell coefficient by extension (L = 1):
    Coriolis −4 κ ∫φψ (ψ'' + κ ψ = −φ, ψ(0) = ψ'(1) = 0, the axial response to the Coriolis
    force) and stretch −κ (∫(1 − X²) φ''²/∫φ''² + (∫φ'² − φ'(1)²)/β⁴) (the bending strain is
    per reference length), κ = ρ ω0²/E."""
    betas, modes = clamped_free_modes(1)
    b = betas[0]
    phi, d1, d2 = modes[0]
    norm = np.sqrt(np.sum(W01 * cantilever_mode(b, X01)[0] ** 2))
    kappa = RHO * omega0**2 / E
    x = np.linspace(0, 1, 101)
    sol = solve_bvp(
        lambda x, y: np.vstack([y[1], -kappa * y[0] - cantilever_mode(b, x)[0] / norm]),
        lambda a, c: np.array([a[0], c[1]]),
        x,
        np.zeros((2, x.size)),
        tol=1e-10,
    )
    coriolis = 4 * kappa * np.sum(W01 * phi * sol.sol(X01)[0])
    d1_tip = cantilever_mode(b, 1.0)[1] / norm
    stretch = kappa * (
        np.sum(W01 * (1 - X01**2) * d2**2) / np.sum(W01 * d2**2)
        + (np.sum(W01 * d1**2) - d1_tip**2) / b**4
    )
    return coriolis, stretch


def test_extension_and_coriolis_lower_the_lead_lag_coefficient():
    """The gyroscopic matrix at work: in the rotation plane the Coriolis forces 2ρA Ω × u̇
    couple lead-lag with extension. To first order in Ω² the extensible beam's lead-lag
    coefficient is the inextensible one minus the Coriolis and stretch terms of
    :func:`_extension_terms` (0.063 + 0.029 of 0.193 here: the in-plane ω0 is an eighth of
    the axial frequency). The next order is (Ω/ω0)² = 1e-2 of these: tolerance 1e-2."""
    coefficients = []
    for extensible in (False, True):
        _, frame = blade(8, 4, extensible)
        _, lag0 = flap_lag(frame, 0.0)
        _, lag = flap_lag(frame, 1.0)
        a2 = (frame.speed / lag0) ** 2
        coefficients.append(((lag / lag0) ** 2 - 1) / a2)
    coriolis, stretch = _extension_terms(lag0)
    change = coefficients[1] - coefficients[0]
    assert change == pytest.approx(-(coriolis + stretch), rel=1e-2), (change, coriolis, stretch)
    assert coriolis > 2 * stretch > 0  # the Coriolis coupling is the larger part


def test_gyroscopic_matrix_is_skew_and_blind_to_the_quaternion_norm():
    """G = ∂a/∂q − (∂a/∂q)ᵀ is skew by construction; T₁ depends on q/|q| only, so G (like M)
    annihilates the norm direction of the quaternions, at any state (here: a rotated, twisted
    and stretched one whose quaternions are not unit)."""
    section = sections.rectangle(E, E / 2.6, RHO, 0.02, 0.05)
    # free: a support zeroes rows and columns, and Σ_j G_ij q_j then misses the fixed j
    model = BeamModel(Model(beams=(Beam("b", straight(1.0), section, 3, 2),)))
    frame = RotatingFrame(model, axis=(0.3, -0.2, 1.0), hub=(-0.5, 0.1, 0.0), rotary="full")
    frame.set_speed(50.0)
    rng = np.random.default_rng(1)
    w = model.w.x.array
    w[:] = 0.05 * rng.standard_normal(w.shape)
    q_dofs = model.W.sub(1).collapse()[1]
    w[np.asarray(q_dofs).reshape(-1, 4)[:, 0]] += 1.3  # non-unit quaternions
    model.w.x.scatter_forward()
    model.set_load_factor(1.0)
    _, G, M = assemble_operators(frame)
    D = G.copy()
    D.axpy(1.0, G.transpose())
    assert G.norm() > 0 and D.norm() <= 1e-13 * G.norm()
    radial, out = G.createVecs()
    radial.setArray(np.where(np.isin(np.arange(len(w)), q_dofs), w, 0.0)[: radial.getLocalSize()])
    for A in (G, M):
        A.mult(radial, out)
        assert out.norm() <= 1e-14 * A.norm() * radial.norm()


def test_at_zero_speed_the_quadratic_problem_gives_the_modal_frequencies():
    """Ω = 0: no gyroscopic or centrifugal terms, λ = ±iω of K − ω² M (Timoshenko beam with
    full rotary inertia)."""
    section = sections.rectangle(E, E / 2.6, RHO, 0.02, 0.05)
    spec = Model(
        beams=(Beam("b", straight(1.0), section, 4, 3),),
        supports=(Support("b:start", CLAMP),),
        kinematics=Kinematics(),
    )
    model = BeamModel(spec)
    frame = RotatingFrame(model, rotary="full")
    solve_steady(frame, 0.0)
    r = solve_rotating_modes(frame, 6)
    m = solve_modes(model, 6, rotary="full")
    assert np.allclose(r.omega, np.sort(m.omega), rtol=1e-9), (r.omega, m.omega)
    assert np.all(np.abs(r.growth) < 1e-9 * r.omega)


def test_a_blade_hinged_at_the_axis_flaps_at_the_spin_speed_on_any_mesh():
    """Rigid flapping about a hinge on the axis is the blade spinning about a tilted axis, so
    its frequency in the rotating frame is exactly Ω (∫ρA x² on both sides of the Rayleigh
    quotient), however stretched the blade and however coarse the mesh: the tension stiffness
    and the centrifugal load come from one potential."""
    _, frame = blade(2, 2, True, fix=("ux", "uy", "uz", "rx", "rz"))
    for alpha in (1.0, 30.0):
        flap, _ = flap_lag(frame, alpha)
        assert flap / frame.speed == pytest.approx(1.0, abs=1e-9)


def test_the_steady_stretch_is_the_rotating_rod_solution_and_diverges():
    """Radial rod, N = EA(x' − 1): x'' + k² x = 0, k² = ρΩ²/E, x(0) = 0, x'(L) = 1, so
    x(L) = tan(kL)/k, unbounded as Ω → (π/2) sqrt(E/ρ)/L (α = 77.4 for SM 2.10). Past it no
    steady state exists: at α = 100 the Newton solution has a folded centre line and is
    rejected."""
    model, frame = blade(4, 4, True)
    for alpha in (10.0, 70.0):
        solve_steady(frame, alpha * smr.OMEGA_BY, steps=1)
        ux = model.w.x.array[model.W.sub(0).sub(0).collapse()[1]]
        tip = model.comm.allreduce(float(np.max(ux, initial=0.0)), op=MPI.MAX)
        k = np.sqrt(RHO / E) * frame.speed
        assert 1 + tip == pytest.approx(np.tan(k) / k, rel=1e-6)
    assert smr.OMEGA_AXIAL / smr.OMEGA_BY == pytest.approx(77.38, abs=0.01)
    with pytest.raises(SolveFailed, match="folded"):
        solve_steady(frame, 100 * smr.OMEGA_BY, steps=1)


def test_campbell_follows_a_flap_branch_through_a_crossing():
    """A blade with w = 2h: lead-lag starts at twice the flap frequency, but flap stiffens
    faster (K_s against K_s − 1) and crosses it near Ω = 1.7 ω_flap. Sorted by frequency the
    lowest mode changes from flap to lead-lag; followed by MAC, branch 1 stays flap."""
    section = sections.rectangle(E, E / 2.6, RHO, 0.02, 0.04)
    model, frame = blade(4, 4, True, section=section)
    w0 = 3.516015 * np.sqrt(section.EI_y / section.rho_A)
    speeds = w0 * np.linspace(0.0, 3.0, 9)
    r = campbell(frame, speeds, n_modes=3)
    assert r.stopped_by is None and np.all(r.stable)
    flap, lag = r.out_of_plane[:, 0], r.out_of_plane[:, 1]
    assert np.all(flap > 0.999) and np.all(lag < 1e-3)
    assert np.all(r.mac > 0.9)
    assert np.all(np.diff(r.branches_hz[:, 0]) > 0)
    # the sorted lowest frequency is flap at rest and lead-lag at the top speed
    assert r.frequencies_hz[0, 0] == r.branches_hz[0, 0]
    assert r.frequencies_hz[-1, 0] == r.branches_hz[-1, 1] < r.branches_hz[-1, 0]
    v = solve_rotating_modes(frame, 1).vectors[0]
    assert axis_fraction(model, v, frame.axis) < 1e-3


SCENE = """
[material]
E = 210e9
rho = 7850

[[beams]]
name = "blade"
curve = {{ shape = "line", start = [0, 0, 0], end = [1, 0, 0] }}
section = {{ type = "rectangle", h = 0.02, w = 0.04 }}
elements = 4
degree = 3

[[supports]]
at = "blade:start"
fix = "all"

[[probes]]
name = "tip"
at = "blade:end"

[analysis]
type = "rotating"
speeds_rad_s = [0, 100, 200, 300]
modes = 3

[output]
dir = "{out}"
"""


def test_rotating_scene_writes_the_campbell_files(tmp_path):
    comm = MPI.COMM_WORLD
    folder = Path(comm.bcast(str(tmp_path)))  # one folder for all ranks; rank 0 writes
    out, scene = folder / "out", folder / "blade.toml"
    if comm.rank == 0:
        scene.write_text(SCENE.format(out=out))
    comm.barrier()
    results = run_scene(scene, log=lambda *a: None)
    assert results["analysis"] == "rotating" and results["speeds_rad_s"] == [0, 100, 200, 300]
    f = np.array(results["frequencies_hz"])
    assert f.shape == (4, 3) and np.all(np.diff(f, axis=1) >= 0)
    assert [b["branch"] for b in results["campbell"]] == [1, 2, 3]
    assert results["campbell"][0]["out_of_plane"][-1] > 0.99  # flap stays branch 1
    assert results["stable"] == [True] * 4 and results["stopped_by"] is None
    assert results["probes"]["tip"]["displacement"][0] > 0  # the last steady state stretches
    if comm.rank != 0:
        return
    lines = (out / "campbell.csv").read_text().splitlines()
    assert lines[0].split(",")[:3] == ["speed_rad_s", "speed_rpm", "branch_1_hz"]
    assert len(lines) == 5
    assert np.allclose(
        [float(x) for x in lines[-1].split(",")[2:5]],
        [b["frequencies_hz"][-1] for b in results["campbell"]],
    )
    assert (out / "campbell.png").stat().st_size > 1000
    assert json.loads((out / "results.json").read_text())["campbell"] == results["campbell"]


def test_a_speed_without_steady_state_stops_the_run_with_exit_status_3(tmp_path):
    """Past the rod's first axial frequency ((π/2) sqrt(E/ρ)/L = 8.1e3 rad/s here) Newton finds
    no steady state: results.json keeps the speeds reached with converged false, status
    "stopped" and the reason, and `beamfx run` exits 3, not 0."""
    from beamfx.cli import main

    comm = MPI.COMM_WORLD
    folder = Path(comm.bcast(str(tmp_path)))
    out, scene = folder / "out", folder / "blade.toml"
    if comm.rank == 0:
        text = SCENE.format(out=out).replace("[0, 100, 200, 300]", "[0, 1000, 12000]")
        scene.write_text(text.replace("modes = 3", "modes = 1"))
    comm.barrier()
    assert main(["run", str(scene)]) == 3
    results = json.loads((out / "results.json").read_text())
    assert results["converged"] is False and results["status"] == "stopped"
    assert results["reason"] == results["stopped_by"] and results["reason"]
    assert results["speeds_rad_s"] == [0, 1000]


def test_the_steady_state_of_each_speed_is_in_the_path_and_at_rest_it_is_the_static_one(tmp_path):
    """The pre-curved Pai beam under gravity (beamfx/scenes/pai_rotating.toml): results'
    ``path`` has the tip of every steady state; at 0 rad/s it is the static equilibrium under
    the same loads (the same full 3D model: no trimming; both solved to the convergence test's tolerance, about 1e-8 of
    the force scale), and spinning lifts the strip."""
    import tomllib
    from importlib import resources

    from beamfx.scene.load import parse_scene

    data = tomllib.loads(resources.files("beamfx.scenes").joinpath("pai_rotating.toml").read_text())
    data["beams"][0].update(elements=4, degree=2)
    data["analysis"].update(speeds_rad_s=[0.0, 12.0], modes=1)
    runs = {}
    for kind, analysis in (("rotating", data["analysis"]), ("static", {"type": "static"})):
        full = {"plane": "none", "condense": "none"}
        scene = parse_scene({**data, "analysis": analysis, "model": full}, "pai_rotating.toml")
        quiet = lambda *a, **k: None
        runs[kind] = run_scene(scene.file, tmp_path / kind, log=quiet, scene=scene).result
    path = runs["rotating"].path
    assert [p["speed_rad_s"] for p in path] == [0.0, 12.0]
    at_rest = np.array(path[0]["probes"]["tip"]["position"])
    static = np.array(runs["static"].path[-1]["probes"]["tip"]["position"])
    assert np.abs(at_rest - static).max() < 1e-7 * 0.479
    assert path[1]["probes"]["tip"]["position"][2] > at_rest[2] + 0.05  # lifted by 0.12 m
