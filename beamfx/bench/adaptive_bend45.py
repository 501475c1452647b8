"""The 45-degree bend with its discretisation chosen from a tolerance on the tip position
(:mod:`beamfx.analyses.adaptive`): estimate beside true error, unknowns and warm solve time.

Each setting is (start elements, start degree, tolerance in inches); the driver refines from
1 x P2 until the tip moves by less than the tolerance. The true error is against 16 x P4
(converged to ~1e-9 in). 1 mm = 1/25.4 in is Bathe–Bolourchi's criterion; the published
low-order models need 11 (vertical) and 15 (follower) states, so the target is at most twice
that, 22 and 30 unknowns. The bend is a cantilever under a point load, so the scene builder
picks the statically condensed model (:mod:`beamfx.analyses.condensed`): the rotation vector
is the only unknown, 3 per node instead of 7 (3 displacements and a quaternion), with shear
and stretch kept exactly; one P4 element has 5 nodes (15 unknowns, 12 free after the clamp).
"""

import time
from dataclasses import dataclass

import numpy as np

from .howcroft_2016 import _build, _measure
from .registry import Case, register

MM = 1.0 / 25.4  # the lengths are inches
_reference = {}


def _converged(follower):
    """Tip position of 16 x P4 (the reference of the true error), computed once."""
    if follower not in _reference:
        from ..analyses.model import BeamModel
        from ..analyses.static import solve_static
        from ..io.probes import evaluate_points

        spec, steps = _build(follower)(16, 4)
        model = BeamModel(spec, extra_points=["b:end"])
        solve_static(model, steps=steps)
        _reference[follower] = np.array(evaluate_points(model, ["b:end"])["b:end"]["position"])
    return _reference[follower]


def _scene(spec, steps, elements, degree, tolerance):
    """The scene of a setting, with its ``[accuracy]`` and the model the scene builder picks
    (:func:`~beamfx.bench.scenes.chosen_model`)."""
    from ..analyses import static_run
    from ..scene.load import Scene
    from .scenes import chosen_model

    scene = Scene(
        "bench",
        spec,
        settings=static_run.Settings(steps=steps),
        probes={"tip": "b:end"},
        accuracy={
            "quantity": "tip.position",
            "tolerance": tolerance,
            "relative": False,
            "start_elements": elements,
            "start_degree": degree,
            "max_degree": 4,
            "max_unknowns": 2000,
        },
    )
    return chosen_model(scene)


def _refine(scene):
    """(refinement, the model of its last trial, seconds) of :func:`refine_to_tolerance`."""
    from mpi4py import MPI

    from ..analyses.adaptive import refine_to_tolerance, solve_once

    kept = {}

    def solve(model_spec, scene, comm, probe_at, what):
        out = solve_once(model_spec, scene, comm, probe_at, what)
        kept["model"] = out[0]
        return out

    t0 = time.perf_counter()
    ref = refine_to_tolerance(scene, MPI.COMM_WORLD, solve=solve)
    return ref, kept["model"], time.perf_counter() - t0


def _warm_solve(model, steps):
    """(result, seconds) of the static solve of ``model`` again with a solver already used."""
    from ..analyses.static import solve_static
    from ..solvers import NewtonSolver

    solver = NewtonSolver(
        model.F, model.J, model.w, model.bcs, "beamfx_bench_adaptive_", coupling=model.coupling
    )
    model.reset()
    solve_static(model, steps=steps, solver=solver)  # first use of this solver
    model.reset()
    t1 = time.perf_counter()
    warm = solve_static(model, steps=steps, solver=solver)
    seconds = time.perf_counter() - t1
    solver.destroy()
    return warm, seconds


def _accuracy(ref, tolerance, follower, per_node):
    """The ``accuracy`` entry of a row: estimate beside true error, and the criterion model
    (the last trial but one: the tip moved by less than the tolerance from it)."""
    x = np.array(ref.trials[-1].value)
    prev = ref.trials[-2] if len(ref.trials) > 1 else None
    true_prev = float(np.linalg.norm(np.array(prev.value) - _converged(follower))) if prev else None
    return {
        "tolerance": tolerance,
        "reached": ref.reached,
        "estimate": ref.estimate,
        "richardson_estimate": ref.richardson,
        "true_error": float(np.linalg.norm(x - _converged(follower))),
        "criterion_model": prev
        and {
            "elements": prev.elements,
            "degree": prev.degree,
            "unknowns": prev.unknowns,
            "free_unknowns": prev.unknowns - per_node,
            "true_error": true_prev,
        },
        "trials": [[t.elements, t.degree, t.unknowns, t.change] for t in ref.trials],
    }


@dataclass(frozen=True)
class AdaptiveCase(Case):
    """Settings are (start elements, start degree, tolerance)."""

    def scene(self, elements, degree, tolerance):
        """The scene of a setting: its ``[accuracy]`` and the model the scene builder picks."""
        spec, steps = self.build(elements, degree)
        return _scene(spec, steps, elements, degree, tolerance)

    def run_setting(self, elements, degree, tolerance):
        """One row of the table: the adaptive refinement from the setting, its value and costs."""
        follower = self.extra["follower"]
        scene = self.scene(elements, degree, tolerance)
        steps = scene.steps
        ref, model, cold = _refine(scene)
        warm, warm_s = _warm_solve(model, steps)
        per_node = 3 if scene.condense else 7  # unknowns of the clamped node
        last = ref.trials[-1]
        return {
            "elements": last.elements,
            "degree": last.degree,
            "unknowns": last.unknowns,
            "newton_iterations": warm.newton_iterations,
            "load_steps": len(warm.steps),
            "model": "statically condensed" if scene.condense else "full",
            "wall_s_cold": cold,
            "wall_s_warm": warm_s,
            "values": _measure({"tip": {"position": np.array(last.value).tolist()}}),
            "accuracy": _accuracy(ref, tolerance, follower, per_node),
        }


def accuracy_lines(r):
    """Report lines of an adaptive case (nothing for other cases)."""
    rows = [row for row in r["rows"] if "accuracy" in row]
    if not rows:
        return []
    out = [
        "",
        (
            "| tolerance in (mm) | chosen | unknowns | estimate in | true error in | Richardson in | "
            "criterion model (moves < tol) | its unknowns (free) | its true error in | warm s |"
        ),
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        a, c = row["accuracy"], row["accuracy"]["criterion_model"] or {}
        rich = a["richardson_estimate"]
        out.append(
            f"| {a['tolerance']:.3g} ({25.4 * a['tolerance']:.3g}) | {row['elements']} x "
            f"P{row['degree']} | {row['unknowns']} | {a['estimate']:.2e} | {a['true_error']:.2e} | "
            + (f"{rich:.2e}" if rich is not None else "-")
            + f" | {c.get('elements', '-')} x P{c.get('degree', '-')} | {c.get('unknowns', '-')} "
            f"({c.get('free_unknowns', '-')}) | "
            + (f"{c['true_error']:.2e}" if c.get("true_error") is not None else "-")
            + f" | {row['wall_s_warm']:.3f} |"
        )
    return out


for follower, states in ((False, "11"), (True, "15")):
    kind = "follower" if follower else "vertical"
    register(
        AdaptiveCase(
            f"bend45_{kind}_tolerance",
            "Howcroft et al. 2016",
            f"45-degree bend, {kind} tip load, discretisation chosen from a tolerance",
            _build(follower),
            _measure,
            None,
            MM,
            tuple((1, 2, tol) for tol in (MM, MM / 10, MM / 100)),
            scale=1.0,
            note=(
                f"p- then h-refinement from 1 x P2 until the tip moves by less than the "
                f"tolerance; the estimate is that move. Target of issue 7: the 1 mm criterion "
                f"with at most 2 x {states} unknowns and a warm static solve under 0.2 s."
            ),
            extra={"follower": follower},
        )
    )
