"""A transient analysis of a scene (``[analysis] type = "transient"``), written as it goes.

Every step adds a row to ``probes.csv`` and a line to ``probes.jsonl`` (time, step size,
Newton iterations, the probes' position, displacement and unwrapped rotation, and the
energy balance), written in blocks (:mod:`~beamfx.analyses.transient_history`); frames every
``output_every`` steps (or as ``[output]`` says), and at each frame (every step with
``[output] reaction_rows = "steps"``) a row of ``reactions.csv``
(:mod:`~beamfx.analyses.transient_reactions`); every ``checkpoint_every``
steps a checkpoint lets ``beamfx run --restart`` go on from there.
"""

import time
from collections.abc import Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..settings import option
from .context import RunContext
from .formulation import BeamFormulation
from .registry import Analysis
from .result import Result as _Base
from .result import entry
from .transient_history import History

if TYPE_CHECKING:  # heavy (UFL, PETSc): imported where used
    from ..spec import Model
    from .transient import TransientSettings

_now = time.perf_counter
SCHEMES = ("generalized_alpha", "hht", "newmark", "conserving", "extrapolated")
#: the schemes that use each scheme parameter (the others would ignore it: refused)
SCHEME_PARAMETERS = {"rho_inf": ("generalized_alpha", "extrapolated"), "hht_alpha": ("hht",)}


@dataclass(frozen=True)
class Damping:
    """``[analysis.damping]``: Rayleigh damping."""

    mass: float = option(0.0, low=0.0, doc="a0 (1/s): force a0 M q'")
    stiffness: float = option(0.0, low=0.0, doc="a1 (s): viscous stress a1 C (strain rate)")


@dataclass(frozen=True)
class Settings:
    """``[analysis]`` of a transient analysis."""

    t_end: float = option(positive=True, doc="end time (s)")
    dt: float = option(positive=True, doc="time step (s); cut back on failure, grown back")
    scheme: str = option("generalized_alpha", choices=SCHEMES, doc="time integrator")
    rho_inf: float = option(
        0.9, low=0.0, high=1.0, doc='generalized-α spectral radius (also of "extrapolated")'
    )
    hht_alpha: float = option(0.05, low=0.0, high=1 / 3, doc="HHT α")
    dt_min: float | None = option(None, positive=True, doc="smallest step (default dt/1000)")
    tolerance: float | None = option(
        None, positive=True, doc="local error per step, relative (default: iteration control)"
    )
    damping: Damping = option(Damping(), doc="Rayleigh damping")
    rotary_inertia: str = option("full", choices=("full", "polar", "none"), doc="rotary inertia")
    output_every: int | None = option(
        None, positive=True, doc="a frame every this many steps (default: about 100 per run)"
    )
    checkpoint_every: int | None = option(
        None,
        low=0,
        doc="steps between checkpoints (0: never); default: every 50 steps, at most one per "
        "10 s of wall time",
    )
    start: str = option("rest", choices=("rest", "static"), doc="from rest or a static state")
    steps: int = option(10, positive=True, doc="load steps of a static start")

    def problems(self):
        """(key, message) of settings that do not go together (the scene reader raises)."""
        if self.scheme == "extrapolated" and self.tolerance is not None:
            yield (
                "tolerance",
                (
                    'scheme = "extrapolated" steps on a fixed grid (its runs at dt and dt/2 must '
                    "share their steps): remove tolerance, or choose another scheme"
                ),
            )

    def problems_given(self, given: set) -> Iterator[tuple[str, str]]:
        """(key, message) of a parameter given for a scheme other than the chosen one (it
        would be ignored: ``rho_inf`` with ``scheme = "hht"``)."""
        for key, schemes in SCHEME_PARAMETERS.items():
            if key in given and self.scheme not in schemes:
                own = [k for k, s in SCHEME_PARAMETERS.items() if self.scheme in s]
                takes = f"it takes {own[0]!r}" if own else "it has no parameter"
                named = " or ".join(map(repr, schemes))
                yield (
                    key,
                    (
                        f"is a parameter of scheme = {named}, not of scheme = {self.scheme!r} "
                        f"({takes}); remove it or choose that scheme"
                    ),
                )

    def free_body(self, spec: "Model") -> bool:
        """A free structure may fly from rest (the mass makes the step's operator regular);
        a static start needs supports."""
        return self.start == "rest"

    @property
    def frames_every(self) -> int:
        """Frames every this many steps, unless ``[output]`` says otherwise."""
        from ..io.output import default_every

        return self.output_every or default_every("transient", self.t_end / self.dt)

    def solver(self) -> "TransientSettings":
        """The integrator's :class:`~beamfx.analyses.transient.TransientSettings`."""
        from .transient import TransientSettings

        return TransientSettings(
            t_end=self.t_end,
            dt=self.dt,
            scheme=self.scheme,
            rho_inf=self.rho_inf,
            hht_alpha=self.hht_alpha,
            dt_min=self.dt_min or self.dt / 1000,
            tolerance=self.tolerance,
            damping_mass=self.damping.mass,
            damping_stiffness=self.damping.stiffness,
            rotary_inertia=self.rotary_inertia,
            output_every=self.frames_every,
            checkpoint_every=self.checkpoint_every,
        )


@dataclass(frozen=True, kw_only=True)
class Result(_Base):
    """A time history (its rows are in probes.csv / probes.jsonl)."""

    scheme: str = entry("the integrator")
    t_end: float = entry("end time asked (s)")
    time_steps: int = entry("accepted time steps")
    restarted_from: float | None = entry("time of the checkpoint restarted from, or None")
    energy: dict | None = entry(
        "energy balance at the last step (with a note where loads jump at t = 0)"
    )
    probe_history: dict = entry("the files of the probe history")
    reaction_history: dict | None = entry(
        "reactions.csv (the reactions at the output steps), its rows and the largest |force| "
        "and |moment| of each support over the run with their times; None without rows"
    )
    stopped_by: str = entry(
        '"t_end", or "interrupted by SIGINT" (SIGTERM) (a failed step raises, with its report)'
    )

    def summary(self) -> dict:
        """The numbers of a sweep table: why the run ended and the number of time steps."""
        return {"stopped_by": self.stopped_by, "time_steps": self.time_steps}


def motion_warnings(model, t_end, samples=4000):
    """Warnings for prescribed support motions that would need infinite acceleration: a value
    or slope that jumps (including at t = 0, where the run starts at rest).

    A smooth history's largest change of slope between samples halves when the sampling is
    refined; a jump in value or slope does not.
    """
    out = []
    for i, sup in enumerate(model.supports):
        moved = {}  # each distinct history once, by its key
        for part, (values, own) in enumerate(
            ((sup.displacement, "displacement_history"), (sup.rotation, "rotation_history"))
        ):
            f = sup.history_of(part)
            if any(values) and f is not None:
                moved.setdefault(f, own if getattr(sup, own) is not None else "history")
        for f, key in moved.items():
            out += _jumps(f"supports[{i}] at {sup.at!r}: the {key}", f, t_end, samples)
    return out


def _jumps(where_key, f, t_end, samples):
    """The warning (a list of none or one) for a history ``f`` that jumps in value or slope;
    ``where_key`` names it."""
    kinks = []
    for n in (samples, 2 * samples):
        t = np.linspace(0.0, t_end, n + 1)
        slope = np.diff(f(t)) / (t[1] - t[0])
        kinks.append(np.max(np.abs(np.diff(slope)), initial=0.0))
    scale = np.max(np.abs(f(np.linspace(0.0, t_end, 101)))) / t_end + 1e-300
    dt0 = t_end / samples
    slopes = [abs(float(f(d) - f(0.0))) / d for d in (dt0, dt0 / 2)]  # halves if smooth
    start = abs(float(f(0.0))) > 1e-9 * scale * t_end or (
        slopes[1] > 0.75 * slopes[0] and slopes[1] > 1e-6 * scale
    )
    if not (kinks[1] > 0.75 * kinks[0] and kinks[1] > 1e-6 * scale or start):
        return []
    where = "at t = 0 (the run starts at rest)" if start else "inside the run"
    text = getattr(f, "text", "")
    message = (
        f"{where_key} {text!r} jumps in value or slope {where}: that "
        "needs an infinite acceleration, and the response will ring; smooth it (e.g. a (1 - cos) "
        "ramp)"
    )
    return [message]


def _start(model, settings, ctx):
    """The checkpoint to go on from (restart), else a static start if asked; the checkpoint."""
    from .restart import load_restart

    saved = load_restart(ctx, settings, model) if ctx.restart else None
    if ctx.restart and ctx.comm.rank == 0:  # accepted: the earlier run's results go
        (ctx.folder / "results.json").unlink(missing_ok=True)
    if ctx.restart and saved is None:  # (those of other ranks only: refused before)
        ctx.log(f"note: no checkpoint in {ctx.folder}; starting from t = 0")
    if saved is None and settings.start == "static":
        from .static import solve_static

        model.set_time(0.0)
        opts = ctx.solver_options
        static = solve_static(model, steps=settings.steps, options=opts, log=ctx.log)
        ctx.log(f"static start: {static.newton_iterations} Newton iterations")
    if saved is not None:
        note = ctx.frames.resume(saved[0]["t"], saved[0]["step"])
        if note:
            ctx.log(note)
    return saved


def _warn(ctx, settings):
    """Log, before the march, the support motions that jump and the loads that act
    suddenly at t = 0 (:func:`~beamfx.analyses.energy_balance.sudden_loads`: the energy
    balance's first step); returns those loads."""
    from .energy_balance import jump_line, sudden_loads

    for w in motion_warnings(ctx.spec, settings.t_end):
        ctx.log(f"warning: {w}")
    jumps = sudden_loads(ctx.spec, settings.t_end, settings.start)
    if jumps:
        ctx.log(jump_line(jumps, settings.scheme))
    return jumps


def _reaction_steps(ctx):
    """``want(step, time, last)`` of the rows of reactions.csv: the frames' (default), or
    every step with ``[output] reaction_rows = "steps"``."""
    settings = getattr(ctx.frames, "settings", None)
    if getattr(settings, "reaction_rows", "frames") == "steps":
        return lambda step, time, last=False: True
    return ctx.frames.want


def _progress(comm, t_end):
    from ..io import Progress

    bar = Progress(label="transient", every=5.0, comm=comm)

    def progress(r):
        if not bar.due():  # the line is made only when it is shown
            return
        residual = r.residuals[-1] if r.residuals else 0.0
        bar.update(
            r.step,
            f"t = {r.time:.5g}/{t_end:g} s, dt = {r.dt:.3g}, {r.iterations} its, "
            f"|F| = {residual:.2e}",
        )

    return bar, progress


def run(model: BeamFormulation, settings: Settings, ctx: RunContext) -> Result:
    """March to ``t_end`` (or on from the last checkpoint), writing the history as it goes;
    a SIGINT or SIGTERM stops it at a step ("stopped", with a checkpoint)."""
    from ..interrupt import deferred
    from .energy_balance import JUMP_NOTE
    from .restart import checkpoint_writer
    from .transient import TransientFailed, solve_transient
    from .transient_reactions import ReactionSeries

    jumps = _warn(ctx, settings)
    saved = _start(model, settings, ctx)
    t_restart = saved[0]["t"] if saved else None
    history = History(ctx.folder, ctx.probes, ctx.comm, ctx.probe_blocks(model), t_restart)
    series = ReactionSeries(ctx.folder, ctx.comm, _reaction_steps(ctx), t_restart)
    energy, seconds = {}, ctx.seconds

    def on_step(r):
        t0 = _now()
        energy.update(r.energy)
        history.add(r)
        t1 = _now()
        seconds["probes"] += t1 - t0
        if ctx.frames.want(r.step, r.time):
            history.flush()
            t2 = _now()
            ctx.frames.write(r.step, r.time, series.at_step(r.step))
            seconds["probes"] += t2 - t1
            seconds["frames"] += _now() - t2

    bar, progress = _progress(model.comm, settings.t_end)
    collective = False  # whether the history may gather when it closes
    try:
        with deferred():  # a signal stops the march at a step, with a checkpoint
            result = solve_transient(
                model,
                settings.solver(),
                on_step=on_step,
                log=ctx.log,
                progress=progress,
                options=ctx.solver_options,
                checkpoint=checkpoint_writer(ctx, settings, model, history),
                saved=saved,
                reactions=series,
            )
        collective = True
    except TransientFailed:  # collective; the model holds the last accepted state again
        collective = True
        history.flush()  # the rows kept, and the rotations tracked up to that state
        ctx.probe_values(model)  # its full values, for results.json
        raise
    finally:  # another error may be one rank's: nothing collective then (no hang)
        bar.close()
        t0 = _now()
        history.close(gather=collective)
        seconds["probes"] += _now() - t0
        series.close()
        seconds["reactions"] += series.seconds
        ctx.latest_reactions = series.entries()
    if result.steps:
        last = result.steps[-1]
        ctx.last_frame(last.step, last.time, series.at_step(last.step) or {})
    ctx.probe_values(model)  # all the values at the final state, tracked as the history
    stopped = result.stopped_by != "t_end"
    return Result(
        analysis=ctx.analysis,
        status="stopped" if stopped else "converged",
        reason=result.stopped_by if stopped else None,
        newton_iterations=int(sum(s.iterations for s in result.steps)),
        seconds=dict(result.seconds),
        scheme=settings.solver().parameters().name,
        t_end=settings.t_end,
        time_steps=len(result.steps),
        restarted_from=t_restart,
        energy={**energy, **({"note": JUMP_NOTE} if jumps else {})} if energy else None,
        probe_history={"csv": history.csv.name, "jsonl": history.jsonl.name},
        reaction_history=series.summary() if series.latest is not None else None,
        stopped_by=result.stopped_by,
    )


ANALYSES = (Analysis("transient", Settings, run, doc="time history: dynamics", restart=True),)
