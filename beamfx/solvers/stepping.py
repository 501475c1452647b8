"""Adaptive load stepping: cut back and retry a failed step, grow after easy steps."""

from typing import NamedTuple

from .convergence import describe, remedy
from .snes import DEFAULT_OPTIONS, SolveFailed

#: causes whose usual remedy is a smaller load step (convergence.REMEDIES)
STEP_CAUSES = ("divergence", "stagnation above the floor", "max iterations", "nan")


class SavedState:
    """Save/restore of the unknowns in the Function ``w``, for :func:`step_load`'s cut-backs."""

    def __init__(self, w):
        self.w, self.saved = w, w.x.array.copy()

    def save(self):
        """Keep the current unknowns."""
        self.saved[:] = self.w.x.array

    def restore(self):
        """Put the kept unknowns back (ghosts updated)."""
        self.w.x.array[:] = self.saved
        self.w.x.scatter_forward()


class LoadStep(NamedTuple):
    """An accepted load step: load factor, Newton iterations, residuals and cut-backs."""

    step: int
    load_factor: float
    iterations: int
    residuals: tuple
    cutbacks: int
    converged_by: str = "residual"  # the criterion that held: 'residual', 'floor', 'relative'
    force_scale: float = 0.0  # what the residual was measured against (load or reactions)


def step_load(
    solve_at,
    state,
    steps=10,
    min_fraction=1e-4,
    easy_iterations=4,
    growth=1.5,
    on_step=None,
    log=None,
):
    """March the load factor from 0 to 1.

    Args:
        solve_at: ``solve_at(load_factor) -> SolveReport``; starts from the current state.
        state: object with ``save()`` and ``restore()`` of the unknowns, used on failure, and
            optionally ``predict(load_factor, target)``, which sets the starting point of
            the step from the converged state at ``load_factor`` (just saved).
        steps: initial number of equal steps (the first step is 1/steps).
        min_fraction: smallest step allowed, as a fraction of the total load.
        easy_iterations: a step that converged in at most this many iterations lets the next
            step grow by ``growth`` (never beyond the initial step size).
        growth: factor by which an easy step's successor grows.
        on_step: called with each accepted :class:`LoadStep` (to write output as it goes).
        log: callable for one-line progress messages.

    Returns:
        list of accepted :class:`LoadStep`.

    Raises:
        SolveFailed: naming the step, the load factor, its residual history and the cut-backs.
    """
    from .step_control import EasyGrowth, StepControl, StepTooSmall

    nominal = 1.0 / steps
    control = StepControl(nominal, nominal, min_fraction, EasyGrowth(growth, easy_iterations))
    lam, history, tried = 0.0, [], []
    while lam < 1.0 - 1e-14:
        target = min(1.0, lam + control.size)
        state.save()
        if hasattr(state, "predict"):
            state.predict(lam, target)
        report = solve_at(target)
        if report.converged:
            item = LoadStep(
                len(history) + 1,
                target,
                report.iterations,
                report.residuals,
                len(tried),
                report.criterion or "residual",
                report.scale,
            )
            history.append(item)
            if log:
                at_floor = " (at the round-off floor)" if item.converged_by == "floor" else ""
                log(
                    f"step {item.step}: load factor {target:.6g}, {report.iterations} Newton "
                    f"iterations, |F| {report.residuals[-1] if report.residuals else 0:.3e}"
                    + at_floor
                )
            if on_step:
                on_step(item)
            lam, tried = target, []
            control.accepted(report.iterations)
            continue
        state.restore()
        tried.append((target, report))
        if log:
            log(
                f"step {len(history) + 1}: no convergence at load factor {target:.6g} "
                f"({report.reason}: {report.cause}); cutting the step back"
            )
        try:
            control.rejected()
        except StepTooSmall:
            raise _failure(history, lam, tried, 4 * steps) from None
    return history


def iteration_limit(last):
    """The remedy "more iterations" if ``[solver] snes_max_it`` stopped the ``last`` attempt
    (a SolveReport) below PETSc's default number of iterations, else None."""
    default = DEFAULT_OPTIONS["snes_max_it"]
    if last.reason == "DIVERGED_MAX_IT" and last.iterations < default:
        return (
            f"more iterations: [solver] snes_max_it = {last.iterations} stops Newton before "
            f"it converges (the default is {default})"
        )
    return None


def _remedy(last, sizes, steps):
    """The remedy of the ``last`` attempt of a step tried at the load increments ``sizes``:
    more iterations if ``[solver] snes_max_it`` stopped Newton below PETSc's default; not a
    smaller step if the cut-backs went down to a hundredth of the first try and failed the
    same way; else the cause's own (:func:`~beamfx.solvers.convergence.remedy`)."""
    limit = iteration_limit(last)
    if limit:
        return limit
    if last.cause in STEP_CAUSES and len(sizes) > 1 and min(sizes) <= 1e-2 * sizes[0]:
        return (
            f"not a smaller step: cut back to {min(sizes) / sizes[0]:.1e} of the first try, "
            f"Newton still failed ({last.cause}); check the supports, the loads and their "
            "units, the section constants and the [solver] options"
        )
    return remedy(last.cause, steps)


def _failure(history, lam, tried, steps):
    """The :class:`SolveFailed` of a load step that cannot be cut back further: the cause and
    remedy of the last attempt, every attempt's residuals."""
    last = tried[-1][1]
    fix = _remedy(last, [t - lam for t, _ in tried], steps)
    lines = "\n".join(
        f"  load factor {t:.6g}: {r.reason} ({r.cause}), |F| = "
        + ", ".join(f"{x:.3e}" for x in r.residuals)
        for t, r in tried
    )
    message = (
        f"Newton failed at step {len(history) + 1} after {len(tried)} attempts, the last "
        f"converged load factor is {lam:.6g}; cause: {last.cause} ({last.detail}); "
        f"PETSc: {describe(last.reason)}; remedy: {fix}\ntried:\n{lines}"
    )
    details = {
        "load_factor": lam,
        "attempts": [
            {"load_factor": t, "reason": r.reason, "cause": r.cause, "residuals": list(r.residuals)}
            for t, r in tried
        ],
    }
    return SolveFailed(message, history, last.cause, fix, details)
