"""Arc length at realistic stiffness ratios (issue 16): Howcroft's shallow arch
(``beamfx/scenes/shallow_arch_snap.toml``) with EA and GA multiplied as the stress matrix does
(:func:`beamfx.bench.stress_matrix.stiffened`).

A stiffer EA makes the arch's initial response a membrane shortening of order q R²/EA, so the
first arc length (a load increment of 0.05 along the initial tangent) shrinks with EA, while
the snap-through still moves the crown by twice the rise. Before the geometric bound of the
largest step and the step-size rule's count of the corrections that reached the round-off
floor, the trace at ×1e2 stopped at its 200 steps with the crown near its start, and at ×1e8
the first step did not converge (the energy criterion against a state of 1e-8 m).

References, independent of beamfx: the antisymmetric bifurcation from the symmetric path where
the thrust reaches the antisymmetric mode's Euler load 4π²EI/S² (shallow-arch theory,
:func:`beamfx.bench.shallow_arch.theory_loads`; O((rise/span)²) ≈ 1 % model error, so 1 %
tolerance); the symmetric limit load lies between that bifurcation and the thrust of the
second symmetric mode, 9π²EI/S², over R (the inextensible arch's symmetric limit: the symmetric
deflection stretches the arch at first order), plus the same 1 %.
"""

import math

import pytest

MODEL_ERROR = 0.01  # shallow-arch theory: O((rise/span)²) = (1.522/15.31)² ≈ 1 %


def run_arch(tmp_path, factor, elements=4, degree=3, **analysis):
    """results of the shipped snap-through scene with EA, GA × ``factor``."""
    from beamfx.bench.shallow_arch import scene_data
    from beamfx.bench.stress_matrix import stiffened
    from beamfx.runner import run_scene
    from beamfx.scene.load import parse_scene

    data = scene_data("shallow_arch_snap", elements, degree)
    data["analysis"].update(analysis)
    scene = parse_scene(data, "shallow_arch_snap.toml")
    with stiffened(factor):
        run = run_scene(scene.file, tmp_path, log=lambda *a, **k: None, scene=scene)
    return run.result


def loads():
    """(antisymmetric bifurcation of the inextensible shallow arch, thrust bound of the
    symmetric limit) as load factors of the scene's 5500 N/m."""
    from beamfx.bench.shallow_arch import Q_SNAP, E, I, R, S

    euler = math.pi**2 * E * I / S**2
    return 4 * euler / R / Q_SNAP, 9 * euler / R / Q_SNAP


def test_stiff_arch_snaps_through(tmp_path):
    """×1e2: the trace reaches the displacement limit (past the snap-through) well within its
    200 steps, passing the bifurcation and the limit point where theory puts them."""
    from beamfx.bench.shallow_arch import A, E, theory_loads

    result = run_arch(tmp_path, 1e2)
    assert result.status == "converged" and result.stopped_by == "displacement_limit"
    assert len(result.load_steps) < 100
    bifurcation = next(c for c in result.critical_points if c["kind"] == "bifurcation")
    expected = theory_loads(1e2 * E * A)["q_bifurcation"] / 5500.0
    assert abs(bifurcation["load_factor"] - expected) <= MODEL_ERROR * expected
    top = next(p for p in result.limit_points if p["kind"] == "maximum")
    assert bifurcation["load_factor"] < top["load_factor"] <= (1 + MODEL_ERROR) * loads()[1]
    bottom = next(p for p in result.limit_points if p["kind"] == "minimum")
    assert bottom["load_factor"] < 0  # snapped through: the inverted arch pulled back up


def test_first_steps_converge_at_extreme_stiffness(tmp_path):
    """×1e8: the first steps (a membrane state of 1e-8 m) converge at the round-off floor and
    the trace locates the antisymmetric bifurcation of the (now inextensible) arch."""
    result = run_arch(tmp_path, 1e8, max_steps=10)
    assert len(result.load_steps) == 10  # stopped by max_steps, every step converged
    bifurcation = next(c for c in result.critical_points if c["kind"] == "bifurcation")
    expected = loads()[0]
    assert abs(bifurcation["load_factor"] - expected) <= MODEL_ERROR * expected


def test_stiff_dome_factorises_past_mumps_workspace(tmp_path):
    """The star dome (demos/scenes/star_dome.toml) with EA, GA × 1e2: its first predictor
    leaves the tangent indefinite with a stiffness ratio whose delayed pivots overflow the
    workspace MUMPS sized at the analysis (INFOG(1) = -9). Each attempt then failed ("linear
    solve failed (KSP reason -11)") down to the smallest arc length; factorised again with a
    larger ICNTL(14) the steps converge and pass the dome's double bifurcation (0 -> 2
    negative eigenvalues: the asymmetric modes, double by symmetry)."""
    from beamfx.bench import star_dome
    from beamfx.bench.stress_matrix import stiffened
    from beamfx.runner import run_scene

    data = star_dome.scene_data(4, 2)
    data["analysis"].update(max_steps=3)
    data["model"]["formulation"] = "displacement"  # "auto" takes the mixed form (shear-rigid)
    scene = star_dome.scene(data=data)
    with stiffened(1e2):
        run = run_scene(scene.file, tmp_path, log=lambda *a, **k: None, scene=scene)
    result = run.result
    assert result.stopped_by == "max_steps" and len(result.load_steps) == 3
    assert [p["negative_eigenvalues"] for p in result.path][:3] == [0, 0, 2]


def test_workspace_is_grown_only_after_mumps_ran_out_of_it():
    """The retry rule alone: ICNTL(14) four times larger after INFOG(1) = -9 (from MUMPS's
    default 20 %), nothing after a success, another error or another solver."""
    from types import SimpleNamespace

    from beamfx.solvers.arclength import _larger_workspace

    def ksp(infog, icntl=20, kind="cholesky", solver="mumps"):
        F = SimpleNamespace(getMumpsInfog=lambda i: infog, getMumpsIcntl=lambda i: icntl)
        pc = SimpleNamespace(
            getType=lambda: kind, getFactorSolverType=lambda: solver, getFactorMatrix=lambda: F
        )
        return SimpleNamespace(getPC=lambda: pc)

    assert _larger_workspace(ksp(-9)) == 80
    assert _larger_workspace(ksp(-9, icntl=80)) == 320
    assert _larger_workspace(ksp(0)) is None
    assert _larger_workspace(ksp(-10)) is None  # a singular matrix: no workspace helps
    assert _larger_workspace(ksp(-9, solver="superlu_dist")) is None
    assert _larger_workspace(ksp(-9, kind="ilu")) is None


if __name__ == "__main__":  # pragma: no cover
    pytest.main([__file__, "-q"])
