"""Arc length stays on its branch where a nearly perfect bifurcation is a sharp limit point
(issue 16): Howcroft's shallow arch (``beamfx/scenes/shallow_arch_snap.toml``), 8×P4, with EA
and GA × 1e6 (:func:`beamfx.bench.stress_matrix.stiffened`).

Near inextensible, the arch's symmetric path is almost its membrane state, and the symmetric
snap-through a limit point that turns within a displacement of order q R²/EA. A step from
above the antisymmetric bifurcation converged past it onto the rising membrane path (its
inertia one more, as passing a bifurcation would leave it): the trace then climbed that path
through every higher mode (inertia +1 a step) to its 200 steps. The step's critical point
cannot be located on it (the probes, shorter steps from its start, follow the arch's own path
over the limit point): :class:`~beamfx.solvers.arclength.ArcLengthSolver` now redoes such a
step with half the arc length.

References, independent of beamfx: the antisymmetric bifurcation of the inextensible arch
where the thrust reaches 4π²EI/S² and a symmetric limit below the thrust 9π²EI/S² of the second
symmetric mode, over R (shallow-arch theory, O((rise/span)²) ≈ 1 % model error).
"""

import math

MODEL_ERROR = 0.01  # shallow-arch theory: O((rise/span)²) = (1.522/15.31)² ≈ 1 %


def run_arch(tmp_path, factor, elements, degree):
    """results of the shipped snap-through scene with EA, GA × ``factor``, as the stress
    matrix runs it (the mixed formulation at ×1e6)."""
    from beamfx.bench.shallow_arch import scene_data
    from beamfx.bench.stress_matrix import stiffened
    from beamfx.runner import run_scene
    from beamfx.scene.load import parse_scene

    with stiffened(factor):  # parsed stiffened: the scene builder picks the mixed form
        scene = parse_scene(scene_data("shallow_arch_snap", elements, degree), "arch.toml")
        run = run_scene(scene.file, tmp_path, log=lambda *a, **k: None, scene=scene)
    return run.result


def test_nearly_inextensible_arch_snaps_on_its_own_path(tmp_path):
    """×1e6, 8×P4: the trace reaches the displacement limit past the snap-through, its
    inertia never above 2 (the antisymmetric bifurcation and the limit point), the limit load
    between the bifurcation and the second symmetric mode's thrust bound."""
    from beamfx.bench.shallow_arch import Q_SNAP, E, I, R, S

    result = run_arch(tmp_path, 1e6, 8, 4)
    assert result.status == "converged" and result.stopped_by == "displacement_limit"
    assert max(p["negative_eigenvalues"] for p in result.path) == 2
    euler = math.pi**2 * E * I / S**2
    bifurcation, bound = 4 * euler / R / Q_SNAP, 9 * euler / R / Q_SNAP
    first = result.critical_points[0]
    assert first["kind"] == "bifurcation"
    assert abs(first["load_factor"] - bifurcation) <= MODEL_ERROR * bifurcation
    top = next(p for p in result.limit_points if p["kind"] == "maximum")
    assert bifurcation < top["load_factor"] <= (1 + MODEL_ERROR) * bound
    assert [c["kind"] for c in result.critical_points][:2] == ["bifurcation", "limit"]
