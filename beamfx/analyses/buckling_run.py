"""Linear buckling of a scene (``[analysis] type = "buckling"``): load factors and modes about
the undeformed state or about the current (loaded) one; one frame per mode."""

from collections.abc import Iterator
from dataclasses import dataclass

from ..settings import option
from ..spec import Model
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

    def problems_in(self, spec: Model) -> Iterator[tuple[str, str]]:
        """Loads to multiply (:func:`loaded`)."""
        if not loaded(spec):
            yield "type", NO_LOADS

    def problems_on_mesh(self, spec: Model, points: tuple) -> Iterator[tuple[str, str]]:
        """No more modes than the free dofs of the mesh of ``spec`` (:mod:`.mode_count`)."""
        from .mode_count import modes_problem, spec_nodes

        problem = modes_problem(spec, self.modes, "buckling", spec_nodes(spec, points))
        if problem:
            yield "modes", problem


#: the message of a buckling scene without loads
NO_LOADS = (
    "a buckling analysis needs loads: its load factors multiply them, and none is given "
    "(no [[loads]] with a nonzero force, moment or gravity, no [[supports]] with a prescribed "
    "displacement or rotation); allowed: add the loads whose critical multiple you want"
)


def loaded(spec: Model) -> bool:
    """Whether the model (a :class:`~beamfx.spec.Model`) has a load a buckling analysis can
    multiply: a nonzero point or distributed load, gravity, or a prescribed support value."""
    loads = (*spec.point_loads, *spec.distributed_loads)
    return (
        any(any(ld.force) or any(ld.moment) for ld in loads)
        or any(spec.gravity)
        or any(any(s.displacement) or any(s.rotation) for s in spec.supports)
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
    note: str | None = entry(
        "why fewer load factors than modes came out (None: all did), e.g. none: loads that "
        "compress nothing"
    )

    def summary(self) -> dict:
        """The numbers of a sweep table: the critical load factors, critical points passed."""
        return {
            "load_factors": list(self.load_factors),
            "critical_points_passed": self.critical_points_passed,
        }


def run(model: BeamFormulation, settings: Settings, ctx: RunContext) -> Result:
    """The buckling eigenproblem (K + λ K_G) φ = 0 about the chosen state."""
    from .buckling import solve_buckling
    from .mode_count import check_modes, free_dofs_of, mesh_nodes
    from .mode_shapes import PARAVIEW_STEPS, prestress, shapes

    if not loaded(ctx.spec):  # a model made in code (a scene file is refused on reading)
        raise ValueError(f"{ctx.file}: analysis.type: {NO_LOADS}")
    check_modes(model, ctx.spec, settings.modes, "buckling", ctx.file)
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
        most=free_dofs_of(ctx.spec, mesh_nodes(model)),
    )
    both = tuple(res.load_factors.tolist()) if current else ()
    if current:
        res = _of_sign(res, settings.sign)
    for i, lam in enumerate(res.load_factors, start=1):
        ctx.log(f"  buckling mode {i}: load factor {lam:.8g}")
    if current:
        _report_state(ctx, res.negative_eigenvalues, both, float(model.load_factor.value))
    note = shortfall(res, settings, both)
    if note:
        ctx.log(f"warning: {note}")
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
        note=note,
    )


def shortfall(res, settings, both=()):
    """Why fewer load factors than ``modes`` came out, in words (None if all did): none at
    all (the loads put no member in compression, or only the reversed loads would buckle it),
    or fewer (SLEPc converged all the finite roots there are, fewer than asked)."""
    found, asked = len(res.load_factors), settings.modes
    if found >= asked:
        return None
    sign = settings.sign
    other = res.other_sign or tuple(x for x in both if x not in set(res.load_factors))
    pairs = f"SLEPc converged {res.converged} eigenpairs, {res.sought} sought"
    if found:
        return (
            f"found {found} of the {asked} buckling load factors asked of sign {sign!r} ({pairs}; "
            "the others are of the other sign, complex or infinite: no load reaches them)"
        )
    why = "no buckling load factor found"
    if sign != "both":
        why += f" of sign {sign!r}"
    hint = (
        f"; the reversed loads buckle at load factor(s) {', '.join(f'{x:.6g}' for x in other)} "
        "(sign = 'negative' or 'both' reports them)"
        if other and sign == "positive"
        else f"; load factors of the other sign: {', '.join(f'{x:.6g}' for x in other)}"
        if other
        else ""
    )
    return (
        f"{why}: the loads put no member in compression? (a column in tension, a lateral "
        f"force on a section that cannot tip, a load no dof feels; {pairs}){hint}"
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
