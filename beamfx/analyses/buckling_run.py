"""Linear buckling of a scene (``[analysis] type = "buckling"``): load factors and modes about
the undeformed state or about the current (loaded) one; one frame per mode."""

from dataclasses import dataclass

from ..settings import option
from .context import RunContext
from .formulation import BeamFormulation
from .registry import Analysis
from .result import Result as _Base
from .result import entry


@dataclass(frozen=True)
class Settings:
    """``[analysis]`` of a buckling analysis."""

    modes: int = option(4, positive=True, doc="number of buckling modes")
    about: str = option(
        "undeformed",
        choices=("undeformed", "current"),
        doc="linearise about the undeformed state or the state under the scene's loads",
    )
    steps: int = option(10, positive=True, doc="load steps to the current state")
    sign: str = option(
        "positive",
        choices=("positive", "negative", "both"),
        doc="load factors of the loads as given, reversed (negative factors) or both",
    )


@dataclass(frozen=True, kw_only=True)
class Result(_Base):
    """Buckling load factors and mode shapes."""

    load_factors: tuple = entry("critical load factors of the sign asked, nearest first")
    about: str = entry("the state linearised about")
    critical_points_passed: int | None = entry(
        "negative eigenvalues of the tangent at that state: the critical points it is beyond "
        "(None for state-dependent loads)"
    )
    load_factors_both_signs: tuple = entry(
        "about the current state: the critical load factors of both signs, nearest first"
    )
    mode_shapes: tuple = entry("each mode's displacement at the probes (largest nodal = 1)")
    paraview_steps: str = entry("what the ParaView frames hold")

    def summary(self) -> dict:
        """The numbers of a sweep table: the critical load factors, critical points passed."""
        return {
            "load_factors": list(self.load_factors),
            "critical_points_passed": self.critical_points_passed,
        }


def run(model: BeamFormulation, settings: Settings, ctx: RunContext) -> Result:
    """The buckling eigenproblem (K + λ K_G) φ = 0 about the chosen state."""
    from .buckling import solve_buckling
    from .mode_shapes import PARAVIEW_STEPS, prestress, shapes

    steps = ()
    if settings.about == "current":
        steps = prestress(
            model, settings.steps, ctx, "buckling about the current state: static solve"
        ).steps
    current = settings.about == "current"
    res = solve_buckling(
        model,
        settings.modes,
        about=settings.about,
        options=ctx.solver_options,
        sign="both" if current else settings.sign,
    )
    both = tuple(res.load_factors.tolist()) if current else ()
    if current:
        res = _of_sign(res, settings.sign)
    for i, lam in enumerate(res.load_factors, start=1):
        ctx.log(f"  buckling mode {i}: load factor {lam:.8g}")
    if current:
        _report_state(ctx, res.negative_eigenvalues, both, float(model.load_factor.value))
    return Result(
        analysis=ctx.analysis,
        load_steps=tuple(steps),
        newton_iterations=int(sum(s.iterations for s in steps)),
        seconds=dict(res.seconds),
        load_factors=tuple(res.load_factors.tolist()),
        about=settings.about,
        critical_points_passed=res.negative_eigenvalues,
        load_factors_both_signs=both,
        mode_shapes=shapes(model, res.modes, ctx),
        paraview_steps=PARAVIEW_STEPS,
    )


def _of_sign(res, sign):
    """The roots of ``sign`` of a :class:`BucklingResult` holding both signs."""
    mu = res.increments
    keep = [i for i in range(len(mu)) if sign == "both" or (mu[i] > 0) == (sign == "positive")]
    return res._replace(
        load_factors=res.load_factors[keep],
        increments=mu[keep],
        modes=tuple(res.modes[i] for i in keep),
        residuals=res.residuals[keep],
    )


def _report_state(ctx, passed, both, lam):
    """Log how many critical points the current state is beyond, and warn if any."""
    listed = ", ".join(f"{x:.6g}" for x in both)
    if passed is None:
        ctx.log(f"  state-dependent loads: no inertia; load factors of both signs: {listed}")
    elif passed == 0:
        ctx.log(f"  the state at load factor {lam:.6g} is stable (no critical point passed)")
    else:
        ctx.log(
            f"warning: the state at load factor {lam:.6g} is beyond {passed} critical point(s) "
            f"(its tangent has {passed} negative eigenvalue(s)): the lowest positive load "
            f"factor is not the first buckling load; load factors of both signs: {listed}"
        )


ANALYSES = (Analysis("buckling", Settings, run, plane=False, doc="linear buckling loads"),)
