"""The mixed (Hellinger–Reissner) formulation (issue 16): the displacement model's answers at
ordinary stiffness, and answers that do not move with EA, GA where the displacement form loses
its digits.

With the section force in DG_{p−1} and the shear/axial terms on the p Gauss points of the
reduced rule, the mixed model's stationarity gives n = C_N Γ at each of those points: the
discrete equations are the displacement model's, so the two agree to round-off (amplified by
the displacement tangent's condition), not only to the discretisation error.
"""

from dataclasses import replace

import numpy as np
import pytest

from beamfx.analyses.buckling import solve_buckling
from beamfx.analyses.mixed import PENALTY_FACTOR
from beamfx.analyses.modal import solve_modes
from beamfx.analyses.model import BeamModel
from beamfx.analyses.static import solve_static
from beamfx.bench import schwab_meijaard_eigen as sme
from beamfx.bench._builders import cantilever, straight
from beamfx.bench.stress_matrix import stiffened
from beamfx.io import evaluate_points
from beamfx.physics.kinematics import Kinematics
from beamfx.physics.sections import Section

#: a moderately stiff section: EA L²/EI = 1e4 (the displacement form keeps ~1e-9 there)
SECTION = Section(EA=1e4, GA_y=5e3, GA_z=4e3, GJ=1.5, EI_y=1.0, EI_z=2.0)


def _static(spec, formulation, steps=10, k_penalty=None):
    model = BeamModel(replace(spec, formulation=formulation), extra_points=["b:0.5"])
    if k_penalty is not None:
        model.k_penalty.value = k_penalty
    result = solve_static(model, steps=steps)
    return model, result, evaluate_points(model, ["b:end", "b:0.5"])


@pytest.mark.parametrize(
    "finite, section, tol",
    [
        # one linear solve: the same equations, round-off of a ratio-1e4 tangent
        (False, SECTION, (1e-10, 1e-10)),
        # Newton's answers (the same quaternion penalty): each within its residual test (1e-10
        # of the load) of the same solution, observed 5e-9 in position and 3e-7 in the moment
        # (a derivative, at a vertex); a softer section (ratio 1e2), as at 1e4 the
        # displacement form's Newton stops at its round-off floor 5e-7 away in position
        (True, replace(SECTION, EA=1e2, GA_y=50.0, GA_z=40.0), (1e-7, 1e-6)),
    ],
)
def test_static_mixed_equals_displacement(finite, section, tol):
    """A 3D cantilever under a tip force and moment (finite: ~60° of rotation): tip position,
    and section force and moment at mid-span, agree to ``tol`` (position, resultants) of
    their scale."""
    kin = Kinematics(finite=finite)
    spec = cantilever(
        straight(1.0), section, 4, 3, force=(0.0, 1.0, 2.0), moment=(0.5, 0, 0), kinematics=kin
    )
    disp, _, b = _static(spec, "displacement")
    mixed, _, a = _static(spec, "mixed", k_penalty=float(disp.k_penalty.value))
    rotation = 4 if finite else 3
    assert mixed.mixed and mixed.unknowns() == (3 + rotation) * 13 + 3 * 3 * 4
    for point in ("b:end", "b:0.5"):
        for key in ("position", "section_force", "section_moment"):
            t = tol[0] if key == "position" else tol[1]
            x, y = np.asarray(a[point][key]), np.asarray(b[point][key])
            assert np.abs(x - y).max() <= t * max(np.abs(y).max(), 1.0), (point, key, x, y)


def test_own_penalty_is_within_the_discretisation_error():
    """With its own quaternion penalty (c·max(EI, GJ)/h², not 10 EA) the mixed model's tip is
    the displacement model's: both within 1e-4 of a 16 × P4 reference at 4 × P3 (observed
    2.3e-7), and within 1e-10 of each other. What parts them is the nodal norm drift of each
    penalty, ∝ 1/k_p: the former mixed c = 10 moved the tip 1.4e-9, so c = 1e3 1.4e-11; the
    displacement form's 10 EA is c = 10 EA h²/max(EI) ≈ 3e3 here, so ≈ 5e-12."""
    spec = cantilever(straight(1.0), SECTION, 4, 3, force=(0.0, 1.0, 2.0), moment=(0.5, 0, 0))
    fine = replace(spec, beams=tuple(replace(b, elements=16, degree=4) for b in spec.beams))
    ref = np.asarray(_static(fine, "displacement")[2]["b:end"]["position"])
    tip, err = {}, {}
    for formulation in ("mixed", "displacement"):
        tip[formulation] = np.asarray(_static(spec, formulation)[2]["b:end"]["position"])
        err[formulation] = np.linalg.norm(tip[formulation] - ref) / np.linalg.norm(ref)
    apart = np.linalg.norm(tip["mixed"] - tip["displacement"]) / np.linalg.norm(ref)
    assert max(err.values()) < 1e-4 and apart < 1e-10, (err, apart)


def test_modal_mixed_equals_displacement():
    """The free-free Timoshenko beam of SM 2.8: the twelve lowest frequencies (six rigid, then
    bending, torsion, axial) agree to 1e-9 (the rigid ones to round-off near 0)."""
    spec = replace(sme._free_free_timoshenko(4, 3)[0][0].model, formulation="mixed")
    omega = []
    for formulation in ("mixed", "displacement"):
        model = BeamModel(replace(spec, formulation=formulation))
        omega.append(solve_modes(model, n_modes=12).omega)
    elastic = omega[1][6:]
    assert np.all(elastic > 1.0)
    assert np.abs(omega[0][6:] - elastic).max() <= 1e-9 * elastic.max()
    assert np.abs(omega[0][:6]).max() <= 1e-4 * elastic.min()


def _euler(factor, formulation, n=4, p=3):
    with stiffened(factor):
        spec = cantilever(
            straight(sme.L25), sme.stiffened(sme.S25, stretch=False), n, p, force=(-1.0, 0, 0)
        )
        model = BeamModel(replace(spec, formulation=formulation))
        return solve_buckling(model, n_modes=1).load_factors[0] / sme.F_TH_25


def test_euler_buckling_flat_to_1e8():
    """SM 2.5 with EA and GA ×1e8 (stiffness ratio 1.2e15): F_cr within 1e-6 of Euler's load
    (4 × P3: discretisation error 7e-8), and the mixed answer at ×1 is the displacement
    model's (the displacement form at ×1e8 gives 1e15: no digit left)."""
    at_1e8 = _euler(1e8, "mixed")
    assert abs(at_1e8 - 1.0) < 1e-6
    at_1 = _euler(1.0, "mixed")
    ref = _euler(1.0, "displacement")
    assert abs(at_1 - ref) < 1e-7  # the displacement form's own round-off at ratio 1.2e7
    assert abs(at_1 - 1.0) < 2e-6  # P/(100 GA) = 6e-7 of shear and stretch at ×1


@pytest.mark.parametrize("factor", [1.0, 1e8])
def test_penalty_model_converges(factor):
    """A shear-rigid, inextensible cantilever (SM 2.2's limits) under a tip force and moment,
    EA and GA ×``factor``: exact constraints in the mixed form, so the run converges at ×1e8
    (the penalty form's tangent is singular there), the answer is the ×1 one to round-off and
    the scaled condition number does not grow with the factor: it is set by the quaternion
    penalty c·max(EI, GJ)/h² against the bending terms EI/h² (≈ 6.8·c for large c: 6.8e6 at
    both factors with c = 1e6) or by the bending terms' own spread (below 1e6 with c = 10),
    so below max(1e6, 10·c) at both factors."""
    kin = Kinematics(shear=False, stretch=False)
    spec = cantilever(
        straight(1.0), SECTION, 4, 3, force=(0.0, 1.0, 2.0), moment=(0.5, 0, 0), kinematics=kin
    )
    with stiffened(factor):
        _, result, values = _static(spec, "mixed")
    with stiffened(1.0):
        _, _, ref = _static(spec, "mixed")
    x, y = np.asarray(values["b:end"]["position"]), np.asarray(ref["b:end"]["position"])
    assert np.abs(x - y).max() < 1e-12
    kappa = result.condition_estimate["value"]
    assert kappa is not None and kappa < max(1e6, 10 * PENALTY_FACTOR), result.condition_estimate


def test_condition_does_not_grow_with_stiffness():
    """An extensible, shear-flexible cantilever: the mixed tangent's scaled condition number
    at EA, GA ×1e8 is within a factor 10 of its value at ×1 (the displacement form's grows by
    the factor)."""
    spec = cantilever(straight(1.0), SECTION, 4, 3, force=(0.0, 1.0, 2.0))
    kappa = {}
    for factor in (1.0, 1e8):
        with stiffened(factor):
            kappa[factor] = _static(spec, "mixed")[1].condition_estimate["value"]
    assert kappa[1e8] < 10 * kappa[1.0], kappa
