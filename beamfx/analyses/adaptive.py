r"""Discretisation chosen from a tolerance: p- then h-refinement until a probe quantity settles.

The scene names a quantity at a probe (``[accuracy] quantity = "tip.position"``) and a
tolerance. Starting from ``start_elements`` elements of degree ``start_degree`` per beam, the
driver raises the degree up to ``max_degree`` (each step a new polynomial space on the same
mesh), then doubles the elements at that degree, solving each model from scratch. The change
of the quantity between two successive models,

    e_k = |Q_k − Q_{k−1}|   (Euclidean norm for vectors),

estimates the error of the coarser model Q_{k−1}; under monotone convergence it also bounds
the error of Q_k, which is the answer reported. The driver stops at the first k with
e_k ≤ tolerance (times |Q_k| if ``relative``): the coarser model k − 1 then meets the criterion
in the sense of Bathe–Bolourchi's 1 mm ("the answer moves by less than the tolerance when the
model is refined"), and the finer one is the answer. Where the successive differences fall
geometrically (ρ = e_k / e_{k−1} < 1), ``richardson`` = e_k ρ / (1 − ρ) is the sharper estimate
of Q_k's own error; it is reported beside e_k, not used to stop.
"""

import time
from dataclasses import replace
from typing import NamedTuple

import numpy as np

DEGREES = (1, 2, 3, 4)
#: probe entries of :func:`beamfx.io.probes.evaluate_points` that a tolerance may name
QUANTITIES = (
    "position",
    "displacement",
    "rotation_vector",
    "angle",
    "section_force",
    "section_moment",
)


class Trial(NamedTuple):
    """One solve of the refinement: its mesh, value, change from the previous trial and cost."""

    elements: int  # per beam, before scaling by length
    degree: int
    unknowns: int
    value: tuple  # the quantity
    change: float | None  # e_k: distance to the previous trial's value (None for the first)
    newton_iterations: int
    seconds: float  # model set-up, compilation (or cache load) and solve
    solve_seconds: float  # the static solve alone


class Refinement(NamedTuple):
    """The outcome of :func:`refine_to_tolerance`: the finest scene solved and all its trials."""

    scene: object  # the scene with the chosen elements and degree (the finest model solved)
    trials: tuple
    reached: bool
    estimate: float | None  # e_k of the last trial
    richardson: float | None

    def entry(self, settings):
        """The ``accuracy`` entry of results.json."""
        last = self.trials[-1]
        return {
            **settings,
            "reached": self.reached,
            "estimate": self.estimate,
            "richardson_estimate": self.richardson,
            "value": list(last.value),
            "elements": last.elements,
            "degree": last.degree,
            "unknowns": last.unknowns,
            "criterion_model": (
                dict(zip(("elements", "degree", "unknowns"), self.trials[-2][:3]))
                if len(self.trials) > 1
                else None
            ),
            "trials": [t._asdict() for t in self.trials],
        }


def ladder(start_elements, start_degree, max_degree):
    """(elements, degree) to try: p-refinement on the coarse mesh, then h at ``max_degree``."""
    for p in range(start_degree, max_degree + 1):
        yield start_elements, p
    n = start_elements
    while True:
        n *= 2
        yield n, max_degree


def with_discretisation(model, elements, degree):
    """The model with ``elements`` on its longest beam (others in proportion to their length,
    at least 1) and ``degree`` on every beam."""
    longest = max(b.curve.length for b in model.beams)
    beams = tuple(
        replace(b, elements=max(1, round(elements * b.curve.length / longest)), degree=degree)
        for b in model.beams
    )
    return replace(model, beams=beams)


def _quantity(values, what):
    v = np.atleast_1d(np.asarray(values[what], float))
    return tuple(float(x) for x in v)


def solve_once(model_spec, scene, comm, probe_at, what):
    """Build and solve one discretisation; returns (BeamModel, StaticResult, value, seconds)."""
    from ..io.probes import evaluate_points
    from .planar_condensed import build_model
    from .static import solve_static

    t0 = time.perf_counter()
    model = build_model(model_spec, comm, [probe_at], scene.condense)
    result = solve_static(model, steps=scene.steps, options=scene.solver_options)
    value = _quantity(evaluate_points(model, [probe_at])[probe_at], what)
    return model, result, value, time.perf_counter() - t0


def refine_to_tolerance(scene, comm, log=None, solve=solve_once):
    """Refine the scene's discretisation until ``scene.accuracy`` is met (see module doc).

    Returns a :class:`Refinement`; ``reached`` is False if the next model would exceed
    ``max_unknowns`` (the finest model solved is then returned, and the log says so).
    """
    acc = scene.accuracy
    probe, what = acc["quantity"].split(".")
    probe_at = scene.probes[probe]
    trials, estimate, rich = [], None, None
    for n, p in ladder(acc["start_elements"], acc["start_degree"], acc["max_degree"]):
        spec = with_discretisation(scene.model, n, p)
        kin = spec.kinematics
        per_node = 3 if scene.condense else kin.displacement_size + kin.rotation_size
        nodes = sum(b.elements * p + 1 for b in spec.beams)  # upper bound (joints share nodes)
        if trials and nodes * per_node > acc["max_unknowns"]:
            break
        model, result, value, seconds = solve(spec, scene, comm, probe_at, what)
        change = None
        if trials:
            change = float(np.linalg.norm(np.subtract(value, trials[-1].value)))
        trial = Trial(
            n,
            p,
            model.unknowns(),
            value,
            change,
            result.newton_iterations,
            seconds,
            result.seconds["total"] - result.seconds.get("compile", 0.0),
        )
        trials.append(trial)
        if log:
            moved = "" if change is None else f", changed by {change:.3g}"
            log(f"accuracy: {n} x P{p}, {trial.unknowns} unknowns: {what} {value}{moved}")
        if change is None:
            continue
        scale = float(np.linalg.norm(value)) if acc["relative"] else 1.0
        estimate = change / scale if scale > 0 else change
        previous = trials[-2].change
        if previous:
            rho = change / previous
            rich = estimate * rho / (1 - rho) if rho < 1 else None
        if estimate <= acc["tolerance"]:
            return Refinement(replace(scene, model=spec), tuple(trials), True, estimate, rich)
    if log:
        log(
            f"accuracy: tolerance {acc['tolerance']:g} not reached within "
            f"{acc['max_unknowns']} unknowns (estimate {estimate})"
        )
    spec = with_discretisation(scene.model, trials[-1].elements, trials[-1].degree)
    return Refinement(replace(scene, model=spec), tuple(trials), False, estimate, rich)


__all__ = ["DEGREES", "QUANTITIES", "Refinement", "Trial", "ladder", "refine_to_tolerance"]
