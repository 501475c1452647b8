"""The report of a time step that Newton could not take at any step size.

A failed transient says what a failed static solve says (:func:`beamfx.solvers.stepping`'s
failure): the cause and the PETSc reason of the last attempt, a remedy, and every attempt
with its step size and residual history (``failure`` in results.json), with the time and
the step it failed at. The first line of the message holds all but the residuals: it is
results.json's ``reason`` and the last line ``beamfx run`` prints.
"""

from ..solvers.convergence import describe, remedy
from ..solvers.snes import SolveFailed
from ..solvers.stepping import STEP_CAUSES, iteration_limit


class TransientFailed(SolveFailed):
    """A time step that Newton could not take even at the smallest step size."""


def time_step_remedy(last, sizes, dt_min):
    """The remedy of a time step whose ``last`` attempt (a SolveReport) failed after tries
    at the step sizes ``sizes``: more iterations if ``[solver] snes_max_it`` cut Newton
    short; smaller steps for a cause a smaller step cures (the inertia term, of order
    M/h², dominates the tangent of a short enough step, and the step's displacement shrinks
    as h²), with a ``dt_min`` to try; else the cause's own remedy."""
    limit = iteration_limit(last)
    if limit:
        return limit
    if last.cause in STEP_CAUSES:
        smallest = min(sizes)
        return (
            f"smaller time steps: the smallest tried, dt = {smallest:.3g}, still failed "
            f"({last.cause}); lower [analysis] dt_min (now {dt_min:.3g}, e.g. to "
            f"{smallest / 100:.3g}) and dt; a load or motion that sets in suddenly is eased by "
            "a history that ramps it up (e.g. (1 - cos) over a few periods of the structure)"
        )
    return remedy(last.cause)


def step_failure(t, step, dt_min, tried):
    """The :class:`TransientFailed` of the step from ``t`` (``step`` accepted before it)
    after the attempts ``tried``: (step size, SolveReport, why it was rejected) each, the
    last a Newton failure."""
    sizes = [h for h, _, _ in tried]
    last = tried[-1][1]
    fix = time_step_remedy(last, sizes, dt_min)
    lines = "\n".join(
        f"  dt = {h:.3g}: {why}, residuals " + ", ".join(f"{x:.3e}" for x in r.residuals)
        for h, r, why in tried
    )
    message = (
        f"time step {step + 1} from t = {t:.6g} failed at every step size from dt = "
        f"{sizes[0]:.3g} down to {min(sizes):.3g} (dt_min = {dt_min:.3g}), {len(tried)} "
        f"attempts; cause: {last.cause} ({last.detail}); PETSc: {describe(last.reason)}; "
        f"remedy: {fix}\ntried:\n{lines}"
    )
    details = {
        "time": t,
        "step": step + 1,
        "dt_min": dt_min,
        "smallest_dt_tried": min(sizes),
        "attempts": [
            {
                "dt": h,
                "reason": r.reason,
                "cause": r.cause if not r.converged else why,
                "iterations": r.iterations,
                "residuals": list(r.residuals),
            }
            for h, r, why in tried
        ],
    }
    return TransientFailed(message, (), last.cause, fix, details)
