r"""Steady states of a rotating frame: :func:`solve_steady` from rest, or along a list of
speeds by natural continuation in Ω² (re-exported by :mod:`~beamfx.analyses.rotating`).

A sweep of speeds (:func:`~beamfx.analyses.campbell.campbell`) solves each steady state from
the previous speed's one instead of from the undeformed state: the loads stay at their full
value (load factor 1) and the march parameter s ∈ [0, 1] of
:func:`~beamfx.solvers.stepping.step_load` moves the speed from Ω_a to Ω_b with

    Ω(s)² = Ω_a² + s (Ω_b² − Ω_a²),

the centrifugal load being linear in Ω². The whole interval is tried first; the step
controller (:mod:`~beamfx.solvers.step_control`, through ``step_load``) cuts it back when
Newton fails and grows it again after easy steps. Each step starts from the secant through the
last two converged states (those of the previous speeds, then of the sub-steps), extrapolated
in |Ω|: on the rotating Pai beam that takes 85 Newton iterations over six speeds, against 131
extrapolating in Ω² (which overshoots the stiffening: the first residual is 1e5 times larger)
and 108 without a predictor (the previous state).

At s = 1 the residual test is the same as for a steady state solved from the undeformed state
(the force scale is the load vector's norm at the target speed), so both reach the same steady
state to the convergence tolerance.
"""

import math
import time

from ..solvers.stepping import SavedState


class SpeedPath:
    """The last two converged steady states of a sweep: (|Ω|, unknowns), oldest first (the
    steady state depends on Ω² only)."""

    def __init__(self):
        self.states = []

    def add(self, speed, w):
        """Keep the converged state of the Function ``w`` at ``speed`` (rad/s)."""
        a = abs(float(speed))
        self.states = [s for s in self.states if s[0] != a][-1:] + [(a, w.x.array.copy())]


class _PathState(SavedState):
    """Save/restore for ``step_load``'s cut-backs, and the secant predictor in |Ω| through the
    last two converged states (the path's, then the sub-steps')."""

    def __init__(self, w, path, size):
        super().__init__(w)
        self.known = list(path.states)  # (|Ω|, unknowns), converged
        self.size = size  # s -> |Ω|

    def predict(self, s, target):
        """Start from w_n + (|Ω_t| − |Ω_n|)/(|Ω_n| − |Ω_{n−1}|) (w_n − w_{n−1})."""
        a = self.size(s)
        if self.known[-1][0] != a:  # a sub-step converged at s (its state just saved)
            self.known = self.known[-1:] + [(a, self.saved.copy())]
        if len(self.known) < 2:
            return
        (a_0, w_0), (a_1, w_1) = self.known[-2:]
        ratio = (self.size(target) - a_1) / (a_1 - a_0)
        self.w.x.array[:] = w_1 + ratio * (w_1 - w_0)
        self.w.x.scatter_forward()


def continue_steady(frame, path, speed, solver, log=None):
    """The steady state at ``speed`` from the path's last one (Ω² marched, loads at full).

    Returns (accepted load steps, seconds of the solver's parts). Raises
    :class:`~beamfx.solvers.snes.SolveFailed` as :func:`~beamfx.solvers.stepping.step_load`,
    with ``details["speed_rad_s"]``: the speed of the last converged state, which the model
    then holds (the frame is left at ``speed``).
    """
    from ..solvers import SolveFailed, step_load
    from .static import load_scale, state_sizes, tangent_condition

    model = frame.model
    q_a, q_b = path.states[-1][0] ** 2, float(speed) ** 2
    sign = -1.0 if speed < 0 else 1.0

    def square(s):
        return q_b if s >= 1.0 else q_a + s * (q_b - q_a)

    def speed_at(s):
        return float(speed) if s >= 1.0 else sign * math.sqrt(max(square(s), 0.0))

    def solve_at(s):
        frame.set_speed(speed_at(s))
        solver.set_scale(load_scale(model, solver.F))  # the load at this speed
        report = solver.solve()
        if report.converged:
            model.check_state()
        return report

    model.w.x.array[:] = path.states[-1][1]
    model.w.x.scatter_forward()
    model.set_load_factor(1.0)
    solver.set_sizes(state_sizes(model))
    before = dict(solver.seconds)
    state = _PathState(model.w, path, lambda s: abs(speed_at(s)))
    try:
        history = step_load(solve_at, state, steps=1, log=log)
    except SolveFailed as e:
        s_last = e.history[-1].load_factor if e.history else 0.0
        e.details["speed_rad_s"] = speed_at(s_last)
        e.details["condition_estimate"] = tangent_condition(solver)  # at that state
        frame.set_speed(speed)
        _explain(e, speed_at(0.0), float(speed))
        raise
    spent = {k: v - before.get(k, 0.0) for k, v in solver.seconds.items()}
    return history, spent


def _explain(error, start, speed):
    """Say in ``error`` (a :class:`SolveFailed` of ``step_load``) that it is a continuation
    from ``start`` to ``speed``, and suggest intermediate speeds where its remedy suggests
    more load steps (``steps`` sets only the first steady state's)."""
    import re

    more = f"more speeds between {start:.6g} and {speed:.6g} rad/s in speeds_rad_s"
    message, fix = error.args[0], error.remedy
    if fix:
        new = re.sub(r"\[analysis\] steps = \S+?( \(or more\))?(?=;|$)", more, fix)
        message, error.remedy = message.replace(fix, new), new
    head = f"continuing the steady state from {start:.6g} to {speed:.6g} rad/s (load factor: "
    error.args = (f"{head}the share of the step in Ω²): {message}",)


def solve_steady(
    frame, speed, steps=10, options=None, prefix="beamfx_rotating_static_", log=None, path=None
):
    """The relative equilibrium at ``speed`` (rad/s). Leaves the model at load factor 1.

    Without ``path`` (or with an empty one) it is reached from the undeformed state by load
    steps in Ω² (``steps``, adaptive, as :func:`~beamfx.analyses.static.solve_static`). With a
    :class:`~beamfx.analyses.rotating_path.SpeedPath` holding a previous speed's steady state,
    from that state (:func:`~beamfx.analyses.rotating_path.continue_steady`); the state reached
    is added to ``path``.

    Raises:
        NoSteadyState: past a divergence speed, where no steady state is left: the state
            reached has a folded centre line (axial stretch ≤ 0 somewhere), or Newton failed
            and the tangent loses definiteness by this speed
            (:func:`~beamfx.analyses.rotating_checks.steady_state_lost`). For a linear-elastic
            radial rod the centrifugal stretch grows without bound as Ω → (π/2) sqrt(E/ρ)/L,
            and past it the load steps can jump to a folded, unstable solution.
        SolveFailed: Newton failed with the tangent positive definite (numerical).
    """
    from ..solvers.snes import SolveFailed
    from .rotating_checks import NoSteadyState, classify_failure

    model = frame.model
    solver = frame.newton(prefix, options)
    try:
        if path is not None and path.states:
            result = _continued(frame, path, speed, solver, log)
        else:
            result = _from_rest(frame, speed, steps, solver, log)
    except SolveFailed as e:
        raise classify_failure(frame, e) from None
    stretch = frame.min_stretch()
    if stretch <= 0:
        raise NoSteadyState(
            f"no steady state at {speed:.6g} rad/s: the equilibrium found has a folded centre "
            f"line (smallest axial stretch {stretch:.3g}); the speed is past a divergence",
            result.steps,
            "no steady state",
        )
    if path is not None:
        path.add(speed, model.w)
    return result


def _from_rest(frame, speed, steps, solver, log):
    """Load steps in Ω² (and the scene's loads) from the undeformed state."""
    from .static import StaticResult, load_scale, solve_static

    model = frame.model
    frame.set_speed(speed)
    model.reset()
    model.set_load_factor(0.0)
    if load_scale(model, solver.F) == 0.0:  # at rest and unloaded: the reference state (Newton
        model.set_load_factor(1.0)  # could not reach an absolute tolerance of 0)
        return StaticResult((), 0, {"total": 0.0})
    return solve_static(model, steps=steps, solver=solver, log=log)


def _continued(frame, path, speed, solver, log):
    """From the path's last steady state, loads at full (a StaticResult)."""
    from .static import StaticResult

    t0 = time.perf_counter()
    history, seconds = continue_steady(frame, path, speed, solver, log)
    seconds["total"] = time.perf_counter() - t0
    its = int(sum(h.iterations for h in history))
    return StaticResult(tuple(history), its, seconds)


__all__ = ["SpeedPath", "continue_steady", "solve_steady"]
