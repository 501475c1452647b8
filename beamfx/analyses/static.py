"""Static analyses: nonlinear with adaptive load stepping, and linear (one solve)."""

import time
from typing import NamedTuple

import numpy as np

from ..solvers import NewtonSolver, step_load
from ..solvers.stepping import SavedState


class StaticResult(NamedTuple):
    """The accepted load steps, Newton iterations and wall times of a static solve."""

    steps: tuple  # accepted LoadStep records
    newton_iterations: int
    seconds: dict  # wall time of this call: compile, assemble_F, assemble_J, solve (factorise,
    # triangular_solve, python), total


class _State(SavedState):
    """Save/restore of the unknowns for cut-backs, and the secant predictor."""

    def __init__(self, w):
        super().__init__(w)
        self.last = self.previous = None  # (load factor, unknowns) of converged states

    def predict(self, lam, target):
        """Start Newton from the secant through the last two converged states,
        w = w_n + (λ − λ_n)/(λ_n − λ_{n−1}) (w_n − w_{n−1}), instead of from w_n."""
        if self.last is None or self.last[0] < lam:
            self.previous, self.last = self.last, (lam, self.saved.copy())
        if self.previous is None:
            return
        (lam_0, w_0), (lam_1, w_1) = self.previous, self.last
        self.w.x.array[:] = w_1 + (target - lam_1) / (lam_1 - lam_0) * (w_1 - w_0)
        self.w.x.scatter_forward()


def load_scale(model, F):
    """Norm of the load vector at the undeformed state (compiled residual ``F``), to set an
    absolute residual tolerance in the problem's units."""
    import dolfinx.fem.petsc as fp

    from ..solvers.assembly import assemble_load

    w0 = model.w.x.array.copy()
    model.reset()
    f = fp.create_vector(F)
    assemble_load(f, F, model.load_factor, model.bcs)
    norm = f.norm()
    f.destroy()
    model.w.x.array[:] = w0
    return norm


def solve_static(
    model, steps=10, options=None, prefix="beamfx_static_", on_step=None, log=None, solver=None
):
    """Nonlinear static equilibrium at load factor 1, reached by adaptive load stepping.

    The linear kinematics take a single step (the problem is linear). Newton's absolute
    tolerance is 1e-10 of the load vector's norm.
    """
    t0 = time.perf_counter()
    from ..solvers.forms import compile_seconds

    c0 = compile_seconds[0]
    solver = solver or NewtonSolver(
        model.F, model.J, model.w, model.bcs, prefix, options, coupling=model.coupling
    )
    scale = load_scale(model, solver.F)
    solver.set_atol(max(1e-10 * scale, 1e-14))
    compile_time = compile_seconds[0] - c0

    def solve_at(lam):
        model.set_load_factor(lam)
        report = solver.solve()
        if report.converged:
            model.check_state()  # e.g. the condensed model's range of rotations: raises
        return report

    n = 1 if not model.kin.finite else steps
    before = dict(solver.seconds)
    history = step_load(solve_at, _State(model.w), steps=n, on_step=on_step, log=log)
    spent = {k: v - before.get(k, 0.0) for k, v in solver.seconds.items()}
    seconds = {"compile": compile_time, **spent, "total": time.perf_counter() - t0}
    return StaticResult(tuple(history), int(np.sum([h.iterations for h in history])), seconds)
