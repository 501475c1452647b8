"""Modal analysis in the mixed (Hellinger–Reissner) form with stiff elastic sections (issue 16).

The section force unknowns have no mass: infinite eigenvalues which, as the compliance 1/EA,
1/GA goes to 0, become nearly defective. Shift-and-invert on the saddle point held them in its
Krylov space and converged 0 of 6 pairs on SM 2.10's blade with EA, GA × 1e8 (the default,
``formulation = "auto"``, picks the mixed form there). :func:`~beamfx.analyses.modal.solve_modes`
keeps them out (:mod:`beamfx.solvers.eigen_shell`); a free structure's singular K is shifted.
"""

from dataclasses import replace

import numpy as np
import pytest
from mpi4py import MPI

from beamfx.analyses.mixed import choose_formulation
from beamfx.analyses.modal import solve_modes
from beamfx.analyses.model import BeamModel
from beamfx.bench import schwab_meijaard_eigen as sme
from beamfx.bench import schwab_meijaard_rotating as smr
from beamfx.bench.stress_matrix import stiffened


def _modes(spec, factor, formulation, n_modes, rotary, k_penalty=None):
    """ω (rad/s) of the ``n_modes`` lowest modes with EA, GA × ``factor``."""
    with stiffened(factor):
        if formulation == "auto":
            formulation = choose_formulation(spec, "modal")[0]
        model = BeamModel(replace(spec, formulation=formulation))
    assert model.mixed == (formulation == "mixed")
    if k_penalty is not None:
        model.k_penalty.value = k_penalty
    return solve_modes(model, n_modes=n_modes, rotary=rotary).omega, model


def _predicted(at):
    """The ×1e8 values from the ×1 and ×100 ones by the trend in the compliance 1/f,
    ω(f) = ω∞ + b/f + O(1/f²), and the allowed miss: the O(1/f²) remainder is of the order of
    the first-order move d times its relative size |d|/ω; 10 times that, and 1e-10 ω of
    round-off (as tests/convergence/test_rotating_mixed.py)."""
    d = at[1e2] - at[1.0]
    predicted = at[1e2] + d * (1e-2 - 1e-8) / (1.0 - 1e-2)
    return predicted, 10 * d**2 / np.abs(at[1.0]) + 1e-10 * np.abs(at[1.0])


def test_stiff_blade_modes_follow_their_trend():
    """SM 2.10's clamped blade (8 × P3, no rotary inertia) with EA, GA × 1e8 (ratio 1e15):
    "auto" picks the mixed form, the six modes converge and each is its ×1 value corrected by
    the trend. At ×1 the mixed form equals the displacement form (same quaternion penalty)
    to 1e-9 (the displacement tangent's round-off at ratio 1e7)."""
    spec = smr.blade_model(8, 3)
    omega_d, disp = _modes(spec, 1.0, "displacement", 6, "none")
    at = {f: _modes(spec, f, "mixed", 6, "none", float(disp.k_penalty.value))[0] for f in (1, 1e2)}
    assert np.all(np.abs(at[1.0] - omega_d) <= 1e-9 * omega_d), (at[1.0], omega_d)
    stiff, model = _modes(spec, 1e8, "auto", 6, "none", float(disp.k_penalty.value))
    assert model.mixed
    predicted, tol = _predicted(at)
    assert np.all(np.abs(stiff - predicted) <= tol), (stiff, predicted, tol)
    assert np.all(np.abs(at[1e2] - at[1.0]) > 1e-9 * at[1.0])  # the trend is there


@pytest.mark.parametrize("rotary, rigid", [("full", 6), ("none", 5)])
def test_stiff_free_free_beam(rotary, rigid):
    """SM 2.8's free-free Timoshenko beam (4 × P3) in the mixed form with EA, GA × 1e8: its
    rigid-body modes at ~0 (|ω| ≤ 1e-4 of the lowest elastic one, as the ×1 comparison in
    test_mixed.py; without rotary inertia the rotation about the axis has no mass: five)
    and its elastic modes on their trend. Without rotary inertia no row has both mass and a
    stiffness of the rigid limit: the free shift comes from the bending scale EI/(ρA h⁴)
    (the force coupling's, EA/h² per mass, was 4e5 ω₁² here)."""
    spec = sme._free_free_timoshenko(4, 3)[0][0].model
    at = {f: _modes(spec, f, "mixed", 12, rotary)[0] for f in (1.0, 1e2, 1e8)}
    for omega in at.values():
        elastic = omega[rigid:]
        assert np.all(elastic > 1.0) and np.all(np.diff(elastic) > -1e-9 * elastic[1:])
        assert np.abs(omega[:rigid]).max() <= 1e-4 * elastic.min(), omega
    at = {f: omega[rigid:] for f, omega in at.items()}
    predicted, tol = _predicted(at)
    assert np.all(np.abs(at[1e8] - predicted) <= tol), (at[1e8], predicted, tol)


STIFF_ROD = """
[[beams]]
name = "b"
curve = { shape = "line", start = [0, 0, 0], end = [2, 0, 0] }
section = { type = "general", EA = 2e13, GA_y = 8e12, GA_z = 8e12, GJ = 1e4, EI_y = 1e4, \
EI_z = 4e4, rho_A = 2.0, rho_I = [1e-6, 1e-6, 1e-6] }
elements = 8
degree = 3

[analysis]
type = "modal"
modes = 7
rotary_inertia = "none"

[output]
dir = "OUT"
"""


@pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="a scene in each rank's own tmp_path")
def test_free_stiff_rod_scene_keeps_its_rigid_modes(tmp_path, scene_file):
    """A free rod with EA L²/EI = 8e9 through ``beamfx run`` ("auto": the mixed form), no
    rotary inertia: five rigid-body modes (the rotation about the axis has no mass), labelled,
    then the Euler–Bernoulli free-free bending frequency (β₁L = 4.7300407449; shear and
    discretisation move it by less than 1e-6: EI/(GA L²) = 3e-10). Before, shift-and-invert on
    the saddle point returned one rigid mode and the elastic ones."""
    from beamfx.runner import run_scene

    out = tmp_path / "out"
    results = run_scene(scene_file(STIFF_ROD.replace("OUT", str(out))), log=lambda *a: None)
    assert results["model"]["formulation"]["name"] == "mixed"
    f = np.asarray(results["frequencies_hz"])
    exact = 4.7300407449**2 / (2 * np.pi) * np.sqrt(1e4 / (2.0 * 2.0**4))
    assert results["rigid_body_modes"] == 5
    assert np.abs(f[:5]).max() <= 1e-6 * exact, f
    assert abs(f[5] - exact) <= 1e-6 * exact, (f[5], exact)
    assert (out / "deformed_0007.vtu").is_file()  # one ParaView step per mode
