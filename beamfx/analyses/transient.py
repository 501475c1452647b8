r"""Transient dynamics: the Lagrange equations of the beam stepped in time.

The settings and results of a run, and the march (:func:`solve_transient`): Newton steps
with cut-backs and step growth (or local error control). Its pieces live beside it: the
integrator's state and the inertia forces in :mod:`beamfx.analyses.dynamics`, the energy
bookkeeping in :mod:`beamfx.analyses.energy_balance`, and the checkpoints in
:mod:`beamfx.analyses.transient_checkpoint` (all their names importable from here too).
"""

import time
from dataclasses import dataclass
from typing import NamedTuple

from ..solvers import NewtonSolver
from ..solvers.integrators import generalized_alpha, hht, newmark
from ..solvers.step_control import EasyGrowth, ErrorBased, StepControl, StepTooSmall
from .checks import model_size
from .conserving import Projection
from .dynamics import Dynamics
from .energy_balance import EnergyBalance
from .extrapolation import Extrapolation
from .transient_checkpoint import (
    CHECKPOINT_SECONDS,
    CHECKPOINT_STEPS,
    checkpoint_due,
    checkpoint_state,
    control_state,
    restore_control,
    restore_state,
)
from .transient_failure import TransientFailed, step_failure

__all__ = [
    "CHECKPOINT_SECONDS",
    "CHECKPOINT_STEPS",
    "SCHEMES",
    "Dynamics",
    "EnergyBalance",
    "StepRecord",
    "TransientFailed",
    "TransientResult",
    "TransientSettings",
    "checkpoint_due",
    "checkpoint_state",
    "control_state",
    "restore_control",
    "restore_state",
    "solve_transient",
]

SCHEMES = ("generalized_alpha", "hht", "newmark", "conserving", "extrapolated")


@dataclass(frozen=True)
class TransientSettings:
    """What ``[analysis] type = "transient"`` says (see docs/scenes.md)."""

    t_end: float
    dt: float
    scheme: str = "generalized_alpha"
    rho_inf: float = 0.9  # generalized-α (and the base of "extrapolated")
    hht_alpha: float = 0.05  # HHT
    dt_min: float | None = None  # smallest step after cut-backs (default dt/1000)
    easy_iterations: int = 4  # a step in at most this many iterations may grow the next one
    tolerance: float | None = None  # local error per step, relative (None: iteration control)
    damping_mass: float = 0.0  # Rayleigh a0 (1/s): force a0 M q̇
    damping_stiffness: float = 0.0  # Rayleigh a1 (s): viscous stress a1 C ε̇
    rotary_inertia: str = "full"
    output_every: int = 1  # ParaView frames every n steps (probes and energies every step)
    # steps between checkpoints (0: never); None: every CHECKPOINT_STEPS steps, at most one per
    # CHECKPOINT_SECONDS of wall time (each costs a file written and flushed to disk)
    checkpoint_every: int | None = None

    def __post_init__(self):
        if self.scheme == "extrapolated" and self.tolerance is not None:
            raise ValueError('scheme "extrapolated" steps on a fixed grid: no tolerance')

    def parameters(self):
        """The :class:`~beamfx.solvers.integrators.AlphaParameters` of ``scheme``."""
        if self.scheme == "hht":
            return hht(self.hht_alpha)
        if self.scheme == "newmark":
            return newmark()
        if self.scheme == "conserving":  # trapezoidal steps, then projected (conserving.py)
            return generalized_alpha(1.0)._replace(name="conserving (trapezoidal + projection)")
        if self.scheme == "extrapolated":  # runs at h and h/2 combined (extrapolation.py)
            base = generalized_alpha(self.rho_inf)
            return base._replace(name=f"extrapolated (Richardson h, h/2) {base.name}")
        return generalized_alpha(self.rho_inf)


class StepRecord(NamedTuple):
    """An accepted time step: its size, Newton iterations, cut-backs and energies."""

    step: int
    time: float
    dt: float
    iterations: int
    residuals: tuple
    cutbacks: int
    energy: dict  # kinetic, strain, work_loads, work_supports, dissipated_damping, numerical


class TransientResult(NamedTuple):
    """The accepted time steps of a transient run and why it ended."""

    steps: tuple  # StepRecord of accepted steps (all of them)
    newton_iterations: int
    seconds: dict
    stopped_by: str  # "t_end" or the reason of a failure


def _begin(saved, dyn, balance, control, on_step, log):
    """(t, step) to march from: the checkpoint ``saved``, else t = 0 at rest (recorded)."""
    model = dyn.model
    if saved is not None:
        t, step = restore_state(saved, dyn, balance, control)
        model.set_time(t)
        log(f"restart from the checkpoint at t = {t:.6g} (step {step})")
        return t, step
    model.set_time(0.0)
    dyn.start()
    balance.reactions()
    record = StepRecord(0, 0.0, 0.0, 0, (), 0, balance.record(None, 0.0))
    if on_step:
        on_step(record)
    return 0.0, 0


class _March(NamedTuple):
    """What every step of a march uses."""

    model: object
    settings: TransientSettings
    dyn: Dynamics
    solver: NewtonSolver
    balance: EnergyBalance
    projection: object  # the conserving scheme's Projection, or None
    dt_min: float
    length: float  # the scale of the displacements, for the error estimate
    log: object
    reactions: object = None  # called at each converged step (transient_reactions.py)


def _step(m, control, t, step, failed):
    """Newton from ``t`` (after ``step`` accepted steps) at the control's step size, cut back
    until a step is accepted: (h, the size wanted before the end time shortened it, report,
    cut-backs, error estimate or None); ``model.w`` then holds q_{n+1}.

    Raises:
        TransientFailed: after a failure at the smallest step size (``dt_min`` is tried
            last), after ``failed()`` (the checkpoint); with the cause, the remedy and every
            attempt (:func:`~beamfx.analyses.transient_failure.step_failure`).
    """
    s, model, dyn = m.settings, m.model, m.dyn
    wanted = control.size  # kept if only the end time shortens this step
    h = control.size = min(wanted, s.t_end - t)
    cutbacks, tried, error = 0, [], None
    while True:
        report = _newton(m, t, h)
        if report.converged and s.tolerance:
            error = dyn.error_estimate(h, s.tolerance, m.length)
            if error <= 1.0 or h <= m.dt_min * (1 + 1e-9):
                return h, wanted, report, cutbacks, error
            tried.append((h, report, f"local error {error:.3g} x tolerance"))
            model.w.x.array[:] = dyn.q_n.x.array
            h, cutbacks = control.rejected(error), cutbacks + 1
            continue
        if report.converged:
            return h, wanted, report, cutbacks, error
        tried.append((h, report, report.reason))
        model.w.x.array[:] = dyn.q_n.x.array
        cutbacks += 1
        try:
            h_failed, h = h, control.rejected()
        except StepTooSmall:
            failed()
            raise step_failure(t, step, m.dt_min, tried) from None
        m.log(f"  t = {t:.6g}: {report.reason} with dt = {h_failed:.3g}; retrying with {h:.3g}")


def _newton(m, t, h):
    """The Newton solve(s) of the step from ``t`` to t + h: ``model.w`` then holds q_{n+1}."""
    dyn = m.dyn
    if dyn.extrapolation:
        return dyn.extrapolation.solve(t, h)
    dyn.set_step(h)
    m.model.set_time(t + h)
    dyn.predict(h)
    return m.solver.solve()


def _accept(m, t, h, q_old, step):
    """Move the state on from ``t`` to t + h (step ``step``) after a converged step (``q_old``
    gets q_n); returns the energy balance at t + h. The support reactions are taken before
    the state moves on: the residual's rates are expressions of the state at t_n."""
    q_old[:] = m.dyn.state_values[0]  # q_n
    if m.dyn.extrapolation:
        m.dyn.extrapolation.accept()
    else:
        residual = m.solver.residual_at_solution()
        m.balance.reactions(residual)
        if m.reactions is not None:
            m.reactions(step, t + h, t + h >= m.settings.t_end * (1 - 1e-12), residual)
        m.dyn.accept(h)
    if m.projection:
        m.projection.apply(t, t + h)
    return m.balance.record(q_old, h)


def _march(model, s, options, prefix, log, reactions=None):
    """The :class:`_March` of ``model`` with ``settings`` ``s``, and the forms' compile time."""
    from ..solvers.forms import compile_seconds

    c0 = compile_seconds[0]
    dyn = Dynamics(model, s)
    solver = NewtonSolver(dyn.F, dyn.J, model.w, model.bcs, prefix, options)
    solver.set_atol(max(1e-14 * float(model.k_penalty.value), 1e-14))
    balance = EnergyBalance(dyn, solver.F)
    if balance.moving or reactions:  # the reactions of each step from Newton's last residual
        solver.keep_residual()
    if reactions and s.scheme != "extrapolated":  # (a combination has no residual of its own)
        reactions.start(dyn, solver.F, balance.f_loads)
    else:
        reactions = None
    projection = Projection(dyn, balance) if s.scheme == "conserving" else None
    if s.scheme == "extrapolated":
        dyn.extrapolation = Extrapolation(dyn, solver, balance)
    dt_min = s.dt_min or s.dt / 1000
    length = model_size(model.spec)
    quiet = log or (lambda _: None)
    m = _March(model, s, dyn, solver, balance, projection, dt_min, length, quiet, reactions)
    return m, compile_seconds[0] - c0


def solve_transient(
    model,
    settings,
    on_step=None,
    log=None,
    progress=None,
    options=None,
    checkpoint=None,
    saved=None,
    prefix="beamfx_transient_",
    reactions=None,
):
    """March from t = 0 (at rest in the model's current state) to ``settings.t_end``.

    Each step is one Newton solve (SNES) for q_{n+1}. A step that fails is retried with half
    the step size down to ``dt_min``; after ``easy_iterations`` or fewer the step grows by 1.5
    up to ``dt``; with ``settings.tolerance`` the local error estimate
    (:meth:`Dynamics.error_estimate`) rejects and sizes the steps instead.
    ``on_step(record)`` is called after every accepted step (and at t = 0 with step 0), so
    output is written as the run goes. ``checkpoint(header, arrays)`` is called every
    ``checkpoint_every`` steps (:func:`checkpoint_due`), at the end, before a failure is
    raised and when the march is interrupted (:mod:`beamfx.interrupt`: a SIGINT or SIGTERM
    stops it at an accepted step, ``stopped_by`` then names the signal), with
    :func:`checkpoint_state`; pass such a state as ``saved`` to go on from it.
    ``reactions``: its ``start(dyn, residual, loads)`` once, then ``reactions(step, t, last,
    residual)`` at every converged step before the state moves on
    (:class:`~beamfx.analyses.transient_reactions.ReactionSeries`; not with "extrapolated").

    Raises:
        TransientFailed: naming the time, the step size and the residual history, after the
            last good state was checkpointed.
    """
    from ..interrupt import pending, reason

    t_start, s = time.perf_counter(), settings
    m, compile_time = _march(model, s, options, prefix, log, reactions)
    dyn, balance, solver = m.dyn, m.balance, m.solver
    growth = ErrorBased() if s.tolerance else EasyGrowth(1.5, s.easy_iterations, 2, clean=True)
    control = StepControl(s.dt, s.dt, m.dt_min, growth, reach_smallest=True)

    def save(t, step):
        if checkpoint:
            checkpoint(*checkpoint_state(dyn, balance, control, t, step))

    model.set_load_factor(1.0)
    t, step = _begin(saved, dyn, balance, control, on_step, m.log)
    if m.projection:
        m.projection.remember()
    records, iterations, stopped_by = [], 0, "t_end"
    saved_at = [time.perf_counter()]  # wall time of the last checkpoint (or of the start)
    q_old = model.w.x.array.copy()
    while t < s.t_end * (1 - 1e-12):
        h, wanted, report, cutbacks, error = _step(
            m, control, t, step, lambda t=t, step=step: save(t, step)
        )
        energy = _accept(m, t, h, q_old, step + 1)
        t, step, iterations = t + h, step + 1, iterations + report.iterations
        record = StepRecord(step, t, h, report.iterations, report.residuals, cutbacks, energy)
        records.append(record)
        if on_step:
            on_step(record)
        if progress:
            progress(record)
        if not cutbacks and h < wanted:
            control.size = wanted
        control.accepted(report.iterations, cutbacks, error)
        signum = pending(model.comm)
        if signum:
            stopped_by = reason(signum)
            break
        if checkpoint_due(s.checkpoint_every, step, saved_at, model.comm):
            save(t, step)
            saved_at[0] = time.perf_counter()
    save(t, step)
    seconds = {"compile": compile_time, **solver.seconds, "total": time.perf_counter() - t_start}
    solver.destroy()
    return TransientResult(tuple(records), iterations, seconds, stopped_by)
