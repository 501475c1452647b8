r"""Bifurcation of an Euler column on an arc-length path: detected by the inertia of the
tangent, located, and the buckled branch entered by mode injection; the imperfect column
bends smoothly with no critical point; buckling factors of both signs and about a state
beyond the first critical load.

The column: clamped at x = 0, free at x = L = 1, a compressive end force P (load factor λ),
rectangular section with EI_z = EI_y / 4 (the weak plane is x-y), EA L²/EI_z = 1.2e5.

**Where the straight (primary) path bifurcates.** The Simo–Reissner rod under a dead end
force P, linearised about the compressed straight state (axial strain ε = P/EA), with θ the
section rotation and v the lateral displacement: shear GA(v' − (1 − ε)θ) = Pθ and moment
EIθ'' + Pv' = 0, so EIθ'' + P(1 − P/EA + P/GA)θ = 0, and

.. math::  P_b (1 - P_b/EA + P_b/GA) = P_e = π² EI / (4 L²).

Linear buckling (K_σ from the pre-stress rate about the undeformed state) drops the
pre-buckling shortening: P_lin (1 + P_lin/GA) = P_e. Both hold for the discrete model with the
mesh's own P_e,h; so the located bifurcation must match the linear buckling factor of the same
mesh through the first relation to the location tolerance (1e-7 of the step) and round-off:
1e-8 relative. Against the analytic P_b the error is the mesh's, measured on its linear
buckling factor against the analytic P_lin.

**The buckled branch** is the elastica (Timoshenko & Gere 1961, §2.7): with k = sin(α/2), α
the tip rotation, P/P_e = (2K(k)/π)² and the tip's lateral deflection δ = 2kL/K(k), K the
complete elliptic integral of the first kind (scipy's ellipk(m = k²)), P_e replaced by the
located P_b. Measured largest error of λ/λ_b up to δ = 0.5 L: 1.5e-5 with 4 cubic elements,
2.1e-7 with 8 (the h⁶ of cubic elements: 1.5e-5 / 64 = 2.3e-7), 2.6e-7 with 16: a floor set by
the rod's extension and shear, which the inextensible elastica lacks. The test takes 8
elements and 1e-6.
"""

import math

import numpy as np
import pytest

L = 1.0


def section():
    from beamfx.physics import sections

    return sections.rectangle(1e4, 4e3, 1.0, 0.02, 0.01)  # h (z) = 2 w (y): EI_z = EI_y / 4


def column(elements=4, degree=3, lateral=0.0, axial=-1.0):
    """The spec: end force (axial, lateral) · P_e along x and y."""
    from beamfx.bench._builders import cantilever, straight

    s = section()
    P_e = math.pi**2 * s.EI_z / (4 * L**2)
    return cantilever(straight(L), s, elements, degree, force=(axial * P_e, lateral * P_e, 0))


def bifurcation_load(P_e, EA, GA):
    """P_b with P (1 − P/EA + P/GA) = P_e, the root near P_e."""
    a = 1 / GA - 1 / EA
    return (-1 + math.sqrt(1 + 4 * a * P_e)) / (2 * a)


def trace(spec, branch="primary", max_steps=60, limit=0.5):
    from beamfx.analyses.continuation import trace_path
    from beamfx.analyses.model import BeamModel
    from beamfx.solvers.arclength import ArcLengthSettings

    model = BeamModel(spec)
    settings = ArcLengthSettings(branch=branch, bounds=(None, 0.05 * L))
    return trace_path(
        model,
        max_steps=max_steps,
        first_load_increment=0.1,
        displacement_limit=("uy", limit * L) if limit else None,
        target_load_factor=None if limit else 1.5,
        settings=settings,
    )


@pytest.fixture(scope="module")
def linear_factor():
    from beamfx.analyses.buckling import solve_buckling
    from beamfx.analyses.model import BeamModel

    return solve_buckling(BeamModel(column()), n_modes=1).load_factors[0]


def test_bifurcation_detected_and_located_on_the_straight_path(linear_factor):
    s = section()
    P_e = math.pi**2 * s.EI_z / (4 * L**2)
    result = trace(column(), limit=None)
    assert result.reason == "target"
    assert result.path[0].negative_eigenvalues == 0
    (point,) = result.critical_points
    assert point.kind == "bifurcation" and (point.negative_before, point.negative_after) == (0, 1)
    assert point.interval[0] < point.load_factor < point.interval[1]
    # the mesh's Euler load from its linear buckling factor, then its bifurcation load
    P_lin = linear_factor * P_e
    P_eh = P_lin * (1 + P_lin / s.GA_y)
    P_b = bifurcation_load(P_eh, s.EA, s.GA_y)
    assert abs(point.load_factor * P_e / P_b - 1) < 1e-8, point.load_factor * P_e / P_b - 1
    # against the analytic value: the mesh's error, as measured on the linear factor
    mesh_error = abs(P_lin * (1 + P_lin / s.GA_y) / P_e - 1)
    exact = bifurcation_load(P_e, s.EA, s.GA_y)
    assert abs(point.load_factor * P_e / exact - 1) <= 2 * mesh_error + 1e-8
    # the straight path goes on past it, once unstable
    assert [p.negative_eigenvalues for p in result.path][-1] == 1
    assert np.abs(result.displacements[:, 1:]).max() < 1e-12


def test_branch_switching_follows_the_elastica(linear_factor):
    from scipy.optimize import brentq
    from scipy.special import ellipk

    result = trace(column(elements=8), branch="secondary")
    (point,) = result.critical_points
    assert point.switched and point.kind == "bifurcation"
    notes = [p.note for p in result.path]
    i = notes.index("bifurcation point")
    assert notes[i + 1] == "branch switch"
    after = result.path[i + 1 :]
    # the buckled branch is stable (no negative eigenvalue) and the tip moves sideways
    assert all(p.negative_eigenvalues == 0 for p in after)
    v = np.array([p.displacement[1] for p in after])
    assert np.all(np.diff(v) > 0) and v[-1] >= 0.5 * L
    assert result.reason == "displacement_limit"
    # the elastica: P/P_b(δ) = (2K(k)/π)² with 2k/K(k) = δ/L (K(m = k²))
    lam_b = point.load_factor
    errors = []
    for p in after[3:]:
        delta = p.displacement[1] / L  # 2k/K(k) rises to 0.80 at k = 0.8
        k = brentq(lambda k, d=delta: 2 * k / ellipk(k * k) - d, 1e-9, 0.8)
        errors.append(p.load_factor / lam_b / (2 * ellipk(k * k) / math.pi) ** 2 - 1)
    print(f"\nelastica: largest relative error of the load {np.abs(errors).max():.2e}")
    assert np.abs(errors).max() < 1e-6


def test_imperfect_column_bends_smoothly_without_a_critical_point(linear_factor):
    result = trace(column(lateral=1e-3), limit=0.3)
    assert result.critical_points == ()
    assert all(p.negative_eigenvalues == 0 for p in result.path)
    lam, v = result.load_factors, result.displacements[:, 1]
    assert np.all(np.diff(lam) > 0) and np.all(np.diff(v) > 0)
    # the lateral deflection grows like 1/(1 − λ/λ_cr) near the critical load: at 0.9 λ_cr
    # it is far above the linear response, and the path passes λ_cr with no singularity
    linear = v[1] / lam[1]
    at = np.interp(0.9 * linear_factor, lam, v)
    assert at > 5 * 0.9 * linear_factor * linear
    assert lam[-1] > linear_factor


def test_buckling_factors_of_both_signs(linear_factor):
    """The column in tension (the load reversed) buckles at load factor −λ_lin."""
    from beamfx.analyses.buckling import solve_buckling
    from beamfx.analyses.model import BeamModel

    model = BeamModel(column(axial=1.0))
    neg = solve_buckling(model, n_modes=1, sign="negative").load_factors
    assert abs(neg[0] / -linear_factor - 1) < 1e-8
    both = solve_buckling(model, n_modes=2, sign="both").load_factors
    assert abs(both[0] / -linear_factor - 1) < 1e-8
    pos = solve_buckling(BeamModel(column()), n_modes=1, sign="positive")
    assert abs(pos.load_factors[0] / linear_factor - 1) < 1e-12
    assert pos.negative_eigenvalues == 0


def test_buckling_about_a_state_beyond_the_first_critical_load(linear_factor):
    """On the straight path at 1.5 λ_cr: one critical point passed; the factor below the
    state (μ < 0) is the one passed, the lowest positive one the stiff plane's (4 λ_cr)."""
    from beamfx.analyses.buckling import solve_buckling
    from beamfx.analyses.model import BeamModel
    from beamfx.analyses.static import solve_static

    model = BeamModel(column(axial=-1.5))
    solve_static(model, steps=1)
    r = solve_buckling(model, n_modes=2, about="current", sign="both")
    assert r.negative_eigenvalues == 1
    lam = np.sort(r.load_factors * 1.5)  # in units of the reference force P_e
    assert abs(lam[0] / linear_factor - 1) < 1e-4  # the one passed (pre-buckling shortening)
    assert lam[1] > 3.5 * linear_factor
