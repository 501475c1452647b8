"""Static analyses of a scene: ``static`` (nonlinear, adaptive load stepping to load factor 1)
and ``linear_static`` (linear kinematics, one solve). A frame (with the reactions' frame), the
probes and a row of ``reactions.csv`` after every accepted load step."""

from dataclasses import dataclass
from typing import TYPE_CHECKING

from ..settings import option
from .context import RunContext
from .formulation import Formulation
from .registry import Analysis
from .result import Result as _Base
from .result import entry

if TYPE_CHECKING:  # heavy (PETSc): imported where used
    from .static import StaticResult


@dataclass(frozen=True)
class Settings:
    """``[analysis]`` of a static analysis."""

    steps: int = option(10, positive=True, doc="load steps to load factor 1 (halved on failure)")


@dataclass(frozen=True, kw_only=True)
class Result(_Base):
    """A static solve; ``fallback`` says why the condensed model gave way to the full one."""

    fallback: str | None = entry("why the statically condensed model was replaced, or None")
    path: tuple = entry("load factor and the probes' values after every accepted load step")
    condition_estimate: dict | None = entry(
        "condition number of the tangent at the last state (free dofs, scaled and unscaled; "
        "models of at most 2000 unknowns), or None"
    )


def solve(model: Formulation, settings: Settings, ctx: RunContext) -> tuple["StaticResult", tuple]:
    """Load stepping on ``model`` with the probes and frames of ``ctx`` after every step."""
    from .static import solve_static

    path = []

    def on_step(step):
        ctx.step(model, step.step, step.load_factor)
        values = {name: ctx.latest[at] for name, at in ctx.probes.items()}
        reactions = ctx.latest_reactions["reactions"]
        path.append({"load_factor": step.load_factor, "probes": values, "reactions": reactions})

    opts = ctx.solver_options
    solved = solve_static(
        model, steps=settings.steps, options=opts, on_step=on_step, log=ctx.log, inertia=True
    )
    for point, count in zip(path, solved.negative_eigenvalues):
        point["negative_eigenvalues"] = count
    for note in critical_points(solved.steps, solved.negative_eigenvalues):
        ctx.log(f"  {note}")
    if solved.steps:
        ctx.last_frame(solved.steps[-1].step, solved.steps[-1].load_factor)
    return solved, tuple(path)


def critical_points(steps, counts):
    """Sentences for each change of the tangent's negative eigenvalues between accepted load
    steps: a critical point (limit or bifurcation) passed in load control, the state beyond it
    unstable."""
    out, previous = [], (0.0, 0)
    for step, count in zip(steps, counts):
        if count != previous[1]:
            out.append(
                f"negative eigenvalues of the tangent {previous[1]} -> {count} between load "
                f"factors {previous[0]:.6g} and {step.load_factor:.6g}: a critical point passed"
                + (" (the state is unstable)" if count > 0 else "")
            )
        previous = (step.load_factor, count)
    return out


def run(model: Formulation, settings: Settings, ctx: RunContext) -> Result:
    """Solve to load factor 1; a condensed model that fails is replaced by the full one."""
    from ..solvers import SolveFailed
    from .condensed import RotationRangeError

    fallback = None
    try:
        solved, path = solve(model, settings, ctx)
    except (RotationRangeError, SolveFailed) as e:
        if ctx.rebuild is None:
            raise
        fallback = f"the statically condensed model failed ({e})"
        ctx.log(f"model: {fallback}; solving the full model")
        model = ctx.fallback()
        try:
            solved, path = solve(model, settings, ctx)
        except SolveFailed as full:  # both said: the condensed model's failure came first
            details = {**full.details, "fallback": fallback}
            first = getattr(e, "cause", None) or type(e).__name__
            message = (
                f"the statically condensed model failed first ({first}), then the full: {full}"
            )
            raise SolveFailed(message, full.history, full.cause, full.remedy, details) from e
    return Result(
        analysis=ctx.analysis,
        load_steps=solved.steps,
        newton_iterations=solved.newton_iterations,
        seconds=dict(solved.seconds),
        fallback=fallback,
        path=path,
        condition_estimate=solved.condition_estimate,
    )


ANALYSES = (
    Analysis("static", Settings, run, doc="nonlinear static equilibrium at load factor 1"),
    Analysis("linear_static", Settings, run, linear=True, doc="one linear solve"),
)
