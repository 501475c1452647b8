"""A rotating analysis of a scene (``[analysis] type = "rotating"``): steady state and
rotating-frame frequencies at each speed, the Campbell diagram as ``campbell.csv`` and
``campbell.png``, one frame per speed (the steady state)."""

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from ..settings import Vec3, option
from ..spec import Model
from .context import RunContext
from .formulation import BeamFormulation
from .registry import Analysis
from .result import Result as _Base
from .result import entry


def _hub(value, fail):
    """A hub: a named point (string) or three finite coordinates."""
    if isinstance(value, str):
        return value
    ok = isinstance(value, list) and len(value) == 3
    ok = ok and all(isinstance(v, int | float) and not isinstance(v, bool) for v in value)
    if not ok or not all(abs(float(v)) < float("inf") for v in value):
        fail(f"expected a named point or [x, y, z] (three finite numbers), got {value!r}")
    return tuple(float(v) for v in value)


def hub_position(spec, hub):
    """The hub's coordinates: a named point's, or the ones given."""
    from ..spec import resolve_point

    return resolve_point(spec, hub)[2] if isinstance(hub, str) else np.asarray(hub, float)


@dataclass(frozen=True)
class Settings:
    """``[analysis]`` of a rotating analysis."""

    axis: Vec3 = option((0.0, 0.0, 1.0), doc="spin axis (global axes, any length)")
    hub: object = option(
        None,
        doc="point on the spin axis: a named point or [x, y, z] anywhere, on a beam or not "
        "(default: the first support)",
        parse=lambda value, fail: _hub(value, fail),
        word="a named point or [x, y, z]",
    )
    modes: int = option(6, positive=True, doc="modes per speed")
    rotary_inertia: str = option("full", choices=("full", "none"), doc="rotary inertia")
    speeds_rad_s: tuple[float, ...] | None = option(None, doc="spin speeds (rad/s), in order")
    speed_rad_s: float | None = option(None, doc="one spin speed (rad/s) instead of a list")
    steps: int = option(10, positive=True, doc="load steps of the first steady state")

    def problems(self) -> Iterator[tuple[str, str]]:
        """(key, message) of contradictions: a zero axis, no hub, both or neither speed key."""
        if not any(self.axis):
            yield "axis", "must not be zero"
        if self.hub is None:
            yield "hub", "give the hub point (there is no support to default to)"
        if (self.speeds_rad_s is None) == (self.speed_rad_s is None):
            yield "speeds_rad_s", "give either speeds_rad_s = [...] or speed_rad_s = a number"

    @staticmethod
    def defaults(model: Model) -> dict:
        """The hub defaults to the first support's point."""
        return {"hub": model.supports[0].at} if model.supports else {}

    def problems_on_mesh(self, spec: Model, points: tuple) -> Iterator[tuple[str, str]]:
        """No more modes than the free dofs with mass of the mesh (:mod:`.mode_count`): the
        undamped gyroscopic problem has a pair ±iω per such dof."""
        from .mode_count import modes_problem, spec_nodes

        nodes = spec_nodes(spec, points)
        problem = modes_problem(spec, self.modes, "rotating", nodes, self.rotary_inertia)
        if problem:
            yield "modes", problem

    def problems_in(self, model: Model) -> Iterator[tuple[str, str]]:
        """A named hub must be a point of the model (coordinates may lie anywhere)."""
        from ..spec import resolve_point

        if not isinstance(self.hub, str):
            return
        try:
            resolve_point(model, self.hub)
        except ValueError as e:
            yield "hub", str(e)

    @property
    def speeds(self) -> tuple[float, ...]:
        """The speeds to solve (rad/s)."""
        return self.speeds_rad_s if self.speeds_rad_s is not None else (self.speed_rad_s,)


@dataclass(frozen=True, kw_only=True)
class Result(_Base):
    """Steady states and frequencies per speed (the Campbell diagram)."""

    axis: tuple = entry("unit spin axis")
    hub: dict = entry("hub point name and position")
    rotary_inertia: str = entry("rotary inertia used")
    speeds_rad_s: tuple = entry("speeds solved (fewer than asked when stopped)")
    frequencies_hz: tuple = entry("rotating-frame frequencies per speed")
    stable: tuple = entry("whether each steady state is stable")
    campbell: tuple = entry("branches followed across speeds (frequency, growth, MAC)")
    stopped_by: str | None = entry("why the sweep of speeds ended early (a lost steady state)")
    files: dict = entry("campbell.csv and campbell.png")
    steady_newton_iterations: tuple = entry("Newton iterations of each steady state")
    path: tuple = entry("speed and the probes' values of each steady state")

    def summary(self) -> dict:
        """The numbers of a sweep table: the frequencies (Hz) and why the sweep stopped."""
        return {"frequencies_hz": list(self.frequencies_hz), "stopped_by": self.stopped_by}


def _branches(result):
    return tuple(
        {
            "branch": b + 1,
            "frequencies_hz": result.branches_hz[:, b].tolist(),
            "growth_rate_1_s": result.branches_growth[:, b].tolist(),
            "mac": result.mac[:, b].tolist(),
            "out_of_plane": result.out_of_plane[:, b].tolist(),
        }
        for b in range(result.branches_hz.shape[1] if len(result.speeds) else 0)
    )


def _seconds(result):
    """Assembly and solve times of the steady states (Newton) and eigen solves, and the total."""
    steady = [s.seconds for s in result.steady]
    assemble = sum(s.get("assemble_F", 0.0) + s.get("assemble_J", 0.0) for s in steady)
    solve = sum(s.get("solve", 0.0) for s in steady)
    assemble += sum(e.get("assemble", 0.0) for e in result.eigen_seconds)
    solve += sum(e.get("solve", 0.0) for e in result.eigen_seconds)
    total = sum(s["total"] for s in steady) + sum(sum(e.values()) for e in result.eigen_seconds)
    return {"assemble": float(assemble), "solve": float(solve), "total": float(total)}


def run(model: BeamFormulation, settings: Settings, ctx: RunContext) -> Result:
    """Steady state and frequencies at every speed; the Campbell files in the output folder."""
    from .campbell import campbell, write_campbell
    from .rotating import RotatingFrame

    ctx.require_mass(model, "rotating")
    hub = hub_position(ctx.spec, settings.hub)
    frame = RotatingFrame(model, settings.axis, hub, settings.rotary_inertia)
    ctx.log(
        f"rotating about {frame.axis.round(6).tolist()} through "
        f"{settings.hub if isinstance(settings.hub, str) else 'the hub'} "
        f"{np.round(hub, 6).tolist()}, {len(settings.speeds)} speed(s)"
    )
    path = []

    def on_speed(i, speed):  # the steady state: probes and a frame (no reactions: their
        ctx.probe_values(model)  # balance would need the centrifugal load, not a scene load)
        ctx.frames.write(i, float(speed))  # every speed: the Campbell diagram's states
        values = {name: ctx.latest[at] for name, at in ctx.probes.items()}
        path.append({"speed_rad_s": float(speed), "probes": values})

    result = campbell(
        frame,
        settings.speeds,
        settings.modes,
        steps=settings.steps,
        options=ctx.solver_options,
        on_speed=on_speed,
        log=ctx.log,
    )
    frame.destroy()
    write_campbell(result, ctx.folder, model.comm)
    steps = result.steady[-1].steps if result.steady else ()
    failure = result.failure  # numerical: "failed"; a lost steady state: "stopped"
    status = "failed" if failure else "stopped" if result.stopped_by else "converged"
    return Result(
        analysis=ctx.analysis,
        status=status,
        reason=str(failure).splitlines()[0] if failure else result.stopped_by,
        cause=getattr(failure, "cause", None),
        remedy=getattr(failure, "remedy", None),
        failure=dict(getattr(failure, "details", None) or {}) or None,
        load_steps=tuple(steps),
        newton_iterations=int(sum(s.iterations for s in steps)),
        seconds=_seconds(result),
        axis=tuple(frame.axis.tolist()),
        hub={
            "at": settings.hub if isinstance(settings.hub, str) else None,
            "position": np.asarray(hub).tolist(),
        },
        rotary_inertia=settings.rotary_inertia,
        speeds_rad_s=tuple(result.speeds.tolist()),
        frequencies_hz=tuple(result.frequencies_hz.tolist()),
        stable=tuple(result.stable.tolist()),
        campbell=_branches(result),
        stopped_by=result.stopped_by,
        files={"csv": "campbell.csv", "png": "campbell.png"},
        steady_newton_iterations=tuple(s.newton_iterations for s in result.steady),
        path=tuple(path),
    )


ANALYSES = (
    Analysis("rotating", Settings, run, plane=False, doc="steady states and Campbell diagram"),
)
