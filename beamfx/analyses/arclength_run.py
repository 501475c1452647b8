"""Arc-length continuation of a scene (``[analysis] type = "arclength"``): the equilibrium path
through limit points, written to ``path.csv`` (and the reactions to ``reactions.csv``, a row per
accepted point) as it goes, its limit points in the results; the
inertia of the tangent at every point, the critical points it passes, bifurcations located and
(``branch = "secondary"``) the secondary branch followed from the first one."""

from collections.abc import Iterator
from dataclasses import dataclass

from ..settings import option
from ..spec import DOF_NAMES, Model
from .context import RunContext
from .formulation import BeamFormulation
from .registry import Analysis
from .result import Result as _Base
from .result import entry


def _limit(value, fail):
    """``[component, value]`` of ``displacement_limit``."""
    ok = isinstance(value, list) and len(value) == 2 and value[0] in DOF_NAMES[:3]
    if not ok or isinstance(value[1], (str, bool)) or not isinstance(value[1], (int, float)):
        fail(f"write [component, value], component in {list(DOF_NAMES[:3])}; got {value!r}")
    return (value[0], float(value[1]))


@dataclass(frozen=True)
class Settings:
    """``[analysis]`` of an arc-length continuation."""

    control_point: str | None = option(
        None, doc="named point whose displacement is traced (default: the first point load's)"
    )
    max_steps: int = option(200, positive=True, doc="accepted arc-length steps before stopping")
    target_load_factor: float | None = option(None, doc="stop on reaching this load factor")
    arc_length: float | None = option(
        None, positive=True, doc="first arc length (default: from a first load increment 0.05)"
    )
    method: str = option("crisfield", choices=("crisfield", "riks"), doc="constraint")
    displacement_limit: object = option(
        None,
        parse=_limit,
        word="[component, value], component ux, uy or uz",
        doc="stop when the control point's displacement component passes the value",
    )
    max_arc_length: float | None = option(
        None,
        positive=True,
        doc="largest arc length of a step (default: 10 first arc lengths, and at least a step "
        "moving every displacement dof by 0.4 % of the model's size)",
    )
    min_arc_length: float | None = option(
        None, positive=True, doc="smallest arc length before failing (default: 1e-8 of the first)"
    )
    branch: str = option(
        "primary",
        choices=("primary", "secondary"),
        doc="at the first bifurcation: go on along the path, or switch to the secondary branch",
    )
    switch_amplitude: float | None = option(
        None,
        positive=True,
        doc="arc length of the first step along the buckling mode (default: 1 % of the size)",
    )

    def points(self) -> tuple[str, ...]:
        """Named points the model must have beyond the scene's probes."""
        return () if self.control_point is None else (self.control_point,)

    def problems_in(self, model: Model) -> Iterator[tuple[str, str]]:
        """The control point must be a point of the model."""
        from ..spec import resolve_point

        if self.control_point is not None:
            try:
                resolve_point(model, self.control_point)
            except ValueError as e:
                yield "control_point", str(e)

    def problems(self) -> Iterator[tuple[str, str]]:
        """(key, message) of contradictions between the keys: the trace needs a way to stop."""
        if self.target_load_factor is None and self.displacement_limit is None:
            yield "type", "arclength needs target_load_factor or displacement_limit to stop"


@dataclass(frozen=True, kw_only=True)
class Result(_Base):
    """The traced path and its limit points."""

    control_point: str = entry("the traced point")
    path: tuple = entry("load factor, displacement and arc length of every accepted point")
    limit_points: tuple = entry("maxima and minima of the load factor along the path")
    stopped_by: str = entry(
        "target, displacement_limit (at the first point at or past it) or max_steps"
    )
    critical_points: tuple = entry(
        "limit and bifurcation points passed: where the number of negative eigenvalues of the "
        "tangent changed, the step and load-factor interval, the located load factor (and "
        "the bracket of load factors the inertia puts it in)"
    )

    def summary(self) -> dict:
        """The numbers of a sweep table: limit and critical points, why the trace stopped."""
        return {
            "limit_points": list(self.limit_points),
            "critical_points": [(c["kind"], c["load_factor"]) for c in self.critical_points],
            "stopped_by": self.stopped_by,
        }


def _csv_writer(ctx):
    """``record(index, point)``: one line of ``path.csv`` per accepted point (rank 0)."""
    csv = ctx.folder / "path.csv"
    root = ctx.comm.rank == 0
    if root:
        csv.write_text(
            "step,load_factor,ux,uy,uz,arc_length,iterations,negative_eigenvalues,note\n"
        )

    def record(index, p):
        if root:
            u = ",".join(f"{x:.12g}" for x in p.displacement)
            n = "" if p.negative_eigenvalues is None else p.negative_eigenvalues
            with csv.open("a") as f:
                f.write(
                    f"{index},{p.load_factor:.12g},{u},{p.arc_length:.12g},{p.iterations},"
                    f"{n},{p.note}\n"
                )

    return record


def run(model: BeamFormulation, settings: Settings, ctx: RunContext) -> Result:
    """Trace the path from the unloaded state; probes and a frame at every accepted point."""
    from ..solvers.arclength import ArcLengthSettings
    from .continuation import limit_points, trace_path

    record, count, reactions = _csv_writer(ctx), [0], []

    def on_step(point):
        record(count[0], point)
        ctx.step(model, count[0], point.load_factor)
        reactions.append(ctx.latest_reactions["reactions"])
        count[0] += 1

    keys = ("control_point", "max_steps", "target_load_factor", "arc_length")
    result = trace_path(
        model,
        **{k: getattr(settings, k) for k in keys},
        displacement_limit=settings.displacement_limit,
        settings=ArcLengthSettings(
            method=settings.method,
            bounds=(settings.min_arc_length, settings.max_arc_length),
            branch=settings.branch,
            switch_amplitude=settings.switch_amplitude,
        ),
        options=ctx.solver_options,
        on_step=on_step,
        log=ctx.log,
    )
    path = [
        {
            "load_factor": p.load_factor,
            "displacement": p.displacement,
            "arc_length": p.arc_length,
            "negative_eigenvalues": p.negative_eigenvalues,
            **({"note": p.note} if p.note else {}),
            **({"reactions": r} if r is not None else {}),
        }
        for p, r in zip(result.path, [None] * (len(result.path) - len(reactions)) + reactions)
    ]
    found = located_limits(result, limit_points(result.path))
    limits = [
        {"kind": p.kind, "load_factor": p.load_factor, "displacement": p.displacement}
        for p in found
    ]
    for p in limits:
        ctx.log(
            f"  limit point ({p['kind']}): load factor {p['load_factor']:.6g} "
            f"at {result.control_point}"
        )
    critical = critical_points(result, found)
    for c in critical:
        ctx.log(
            f"  {c['kind']} point passed in step {c['step']} (load factor "
            f"{c['interval'][0]:.6g} to {c['interval'][1]:.6g}, negative eigenvalues "
            f"{c['negative_eigenvalues'][0]} -> {c['negative_eigenvalues'][1]})"
            + (f": at load factor {c['load_factor']:.8g}" if c["load_factor"] is not None else "")
            + (", secondary branch followed from here" if c["switched"] else "")
        )
    if result.reason == "displacement_limit":
        ctx.log(limit_line(result, settings.displacement_limit))
    short = result.reason == "max_steps"  # neither the target nor the limit was reached
    why = f"max_steps: {settings.max_steps} steps did not reach the end asked for"
    return Result(
        analysis=ctx.analysis,
        status="stopped" if short else "converged",
        reason=why if short else None,
        load_steps=tuple(result.steps),
        newton_iterations=int(sum(s.iterations for s in result.steps)),
        seconds=dict(result.seconds),
        control_point=result.control_point,
        path=tuple(path),
        limit_points=tuple(limits),
        stopped_by=result.reason,
        critical_points=tuple(critical),
    )


def limit_line(result, displacement_limit):
    """The log line of a trace ended by ``displacement_limit`` (component, value): the value
    reached at the last point against the limit; the trace stops at the first accepted point
    at or past the limit, it does not land on it."""
    comp, value = displacement_limit
    last = result.path[-1]
    reached = float(last.displacement[DOF_NAMES.index(comp)])
    return (
        f"stopped: displacement limit reached: {comp} of {result.control_point} = "
        f"{reached:.6g} at load factor {last.load_factor:.6g} (step {len(result.path) - 1}), "
        f"past the limit |{comp}| = {abs(value):.6g} (the trace stops at the first point at or "
        "past the limit; it does not land on it)"
    )


def _near(result, limits, c):
    """Index in ``limits`` of the path's extremum within the step of the critical point
    ``c`` (or the steps next to it; the nearest to the step), or None."""
    s = [p.arc_length for p in result.path]
    lo, hi = s[max(c.step - 2, 0)], s[min(c.step + 1, len(s) - 1)]
    a, b = s[max(c.step - 1, 0)], s[min(c.step, len(s) - 1)]  # the step itself
    inside = [i for i, p in enumerate(limits) if lo <= p.arc_length <= hi]
    return min(
        inside,
        key=lambda i: max(a - limits[i].arc_length, limits[i].arc_length - b, 0.0),
        default=None,
    )


def located_limits(result, limits):
    """``limits`` (:func:`~beamfx.analyses.continuation.limit_points`, the path's parabola
    extrema) with the load factor of the limit point the inertia located in the same step,
    where there is one (:class:`~beamfx.solvers.arclength.ArcLengthSolver`: the zero of
    the tangent's eigenvalue, independent of the step sizes). Where the inertia is counted,
    an extremum without a limit point in its steps is left out: the load factor of a smooth
    path has an extremum only where the tangent is singular (K w' = λ' f = 0), so that one
    is a zigzag of the steps (a path so steep in the measured displacements, EA × 1e8, that
    round-off moves λ by more than the step does). A located limit point without an
    extremum in its steps (the path ends within a step past it) is placed in its step
    (:func:`~beamfx.analyses.continuation.limit_in_step`)."""
    from .continuation import limit_in_step

    counted = any(p.negative_eigenvalues is not None for p in result.path[1:])
    found, alone = {}, []
    for c in result.critical_points:
        i = _near(result, limits, c) if c.kind == "limit" else None
        if i is not None:
            found.setdefault(i, c.load_factor)
        elif c.kind == "limit" and c.load_factor is not None:  # e.g. the path ends past it
            alone.append(limit_in_step(result.path, c.step, c.load_factor))
    out = []
    for i, p in enumerate(limits):
        if i not in found:
            if not counted:
                out.append(p)
            continue
        out.append(p if found[i] is None else p._replace(load_factor=found[i]))
    return sorted(out + alone, key=lambda p: p.arc_length)


def critical_points(result, limits):
    """The critical points of a :class:`~beamfx.analyses.continuation.ContinuationResult` as
    results.json entries; a limit point gets its located load factor, or else that of the
    path's extremum within its step (``limits``: :func:`located_limits`)."""
    out = []
    for c in result.critical_points:
        lam = c.load_factor
        if c.kind == "limit" and lam is None:
            i = _near(result, limits, c)
            lam = None if i is None else limits[i].load_factor
        out.append(
            {
                "kind": c.kind,
                "step": c.step,
                "interval": list(c.interval),
                "load_factor": lam,
                "negative_eigenvalues": [c.negative_before, c.negative_after],
                "switched": c.switched,
                "load_factor_bracket": None if c.bracket is None else list(c.bracket),
            }
        )
    return out


ANALYSES = (Analysis("arclength", Settings, run, doc="equilibrium path past limit points"),)
