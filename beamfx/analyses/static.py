"""Static analyses: nonlinear with adaptive load stepping, and linear (one solve)."""

import time
from typing import NamedTuple

import numpy as np

from ..solvers import NewtonSolver, SolveFailed, step_load
from ..solvers.options import is_iterative
from ..solvers.stepping import SavedState
from .mixed import force_unknowns


class StaticResult(NamedTuple):
    """The accepted load steps, Newton iterations and wall times of a static solve."""

    steps: tuple  # accepted LoadStep records
    newton_iterations: int
    seconds: dict  # wall time of this call: compile, assemble_F, assemble_J, solve (factorise,
    # triangular_solve, python), total
    negative_eigenvalues: tuple = ()  # of the tangent after each accepted step (or empty)
    condition_estimate: dict | None = None  # of the tangent at the last state (small models)


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


def load_scale(model, F, vector=None):
    """Norm of the load vector at the undeformed state (compiled residual ``F``), to set an
    absolute residual tolerance in the problem's units. ``vector``: a vector of ``F``'s space
    to assemble into (e.g. the solver's residual vector before its solve), else a new one."""
    import dolfinx.fem.petsc as fp

    from ..solvers.assembly import assemble_load

    w0 = model.w.x.array.copy()
    model.reset()
    f = fp.create_vector(F) if vector is None else vector
    assemble_load(f, F, model.load_factor, model.bcs)
    norm = f.norm()
    if vector is None:
        f.destroy()
    model.w.x.array[:] = w0
    return norm


def state_sizes(model):
    """Per owned unknown of ``model.w``, the size added to |x| in Newton's round-off floor
    (:meth:`~beamfx.solvers.snes.NewtonSolver.set_sizes`): the node spacing (cell length over
    the degree) for a displacement, whose derivative adds to the unit reference tangent, and 1
    for a rotation unknown. None for a model without a beam discretisation."""
    from .dofs import owned_size, subspace_dofs

    d = getattr(model, "discretisation", None)
    if d is None or not hasattr(model, "W"):
        return None
    W = model.W
    if type(W.ufl_element()).__name__ != "MixedElement":  # rotations only (condensed model)
        return np.ones(owned_size(W))
    cells = np.diff(d.mesh.cell_span, axis=1).ravel() / model.degree
    dofs = W.dofmap.list.array.reshape(len(cells), -1)
    spacing = np.zeros(len(model.w.x.array))
    # the largest spacing at each dof: (dof, spacing) pairs sorted, the last of each dof kept
    # (np.maximum.at is unbuffered, five times slower in NumPy 1.24: a third of what else was
    # left of "other" at 2·10⁵ unknowns)
    flat, size = dofs.ravel(), np.repeat(cells, dofs.shape[1])
    order = np.lexsort((size, flat))
    flat, size = flat[order], size[order]
    last = np.r_[flat[1:] != flat[:-1], True]
    spacing[flat[last]] = size[last]
    sizes = np.ones_like(spacing)
    disp = subspace_dofs(W, 0)
    sizes[disp] = spacing[disp]
    return sizes[: owned_size(W)]


def solve_static(
    model,
    steps=10,
    options=None,
    prefix="beamfx_static_",
    on_step=None,
    log=None,
    solver=None,
    inertia=False,
):
    """Nonlinear static equilibrium at load factor 1, reached by adaptive load stepping.

    The linear kinematics take a single step (the problem is linear). Newton's test
    (:mod:`~beamfx.solvers.convergence`) scales the residual by the load vector's norm (or
    the reactions) and knows the round-off floor of the model's stiffness and state.
    ``inertia``: count the negative eigenvalues of the tangent after every accepted step
    (one LDLᵀ factorisation more per step; symmetric tangents of finite kinematics only).
    """
    t0 = time.perf_counter()
    from ..solvers.forms import compile_seconds

    c0 = compile_seconds[0]
    solver = solver or NewtonSolver(
        model.F, model.J, model.w, model.bcs, prefix, options, coupling=model.coupling
    )
    full_load = load_scale(model, solver.F, solver.b)  # b: overwritten by every residual
    solver.set_sizes(state_sizes(model))
    compile_time = compile_seconds[0] - c0

    def solve_at(lam):
        model.set_load_factor(lam)
        solver.set_scale(lam * full_load)  # the load at this step (the reactions count too)
        report = solver.solve()
        if report.converged:
            model.check_state()  # e.g. the condensed model's range of rotations: raises
        return report

    n = 1 if not model.kin.finite else steps
    before = dict(solver.seconds)
    # an LDLᵀ factorisation per step is what the iterative solver avoids
    counts, counted = [], _inertia_counter(model, inertia and not is_iterative(solver.options))

    def accepted(step):
        if counted is not None:  # the tangent at the converged state, assembled once more
            count = counted.count(solver.J, solver.bcs, solver.coupling)
            counts.append(count - force_unknowns(model))  # the mixed form's saddle point
        if on_step:
            on_step(step)

    try:
        history = step_load(solve_at, _State(model.w), steps=n, on_step=accepted, log=log)
    except SolveFailed as e:  # the tangent at the last converged state (restored): κ·eps ≥ 1
        e.details["condition_estimate"] = tangent_condition(solver, _saddle(model))  # says why
        raise
    finally:
        if counted is not None:
            counted.destroy()
    spent = {k: v - before.get(k, 0.0) for k, v in solver.seconds.items()}
    if counted is not None:
        spent["inertia"] = counted.seconds
    t1 = time.perf_counter()
    kappa = tangent_condition(solver, _saddle(model))
    spent["condition"] = time.perf_counter() - t1
    seconds = {"compile": compile_time, **spent, "total": time.perf_counter() - t0}
    its = int(np.sum([h.iterations for h in history]))
    return StaticResult(tuple(history), its, seconds, tuple(counts), kappa)


def tangent_condition(solver, saddle=False):
    """The condition estimate (:mod:`~beamfx.solvers.conditioning`) of the tangent at the
    solver's current state (assembled once more, into the solver's own matrix: Newton
    assembles it again before any use), or None for a large model; ``saddle``: the mixed
    formulation's saddle-point tangent. Collective."""
    from ..solvers.assembly import assemble_tangent
    from ..solvers.conditioning import LIMIT, condition_estimate

    A = solver.A
    if A.getSize()[0] > LIMIT:
        return None
    assemble_tangent(A, solver.J, solver.bcs)
    if solver.coupling:
        solver.coupling.add_to_tangent(A)
    return condition_estimate(A, solver.constrained_rows(), saddle=saddle)


def _saddle(model):
    """Whether the model's tangent is a saddle point (the mixed formulation)."""
    return bool(getattr(model, "mixed", False))


def _inertia_counter(model, inertia):
    """An LDLᵀ inertia counter where asked and meaningful: finite kinematics (a linear solve
    has nothing to pass) and a symmetric tangent (no state-dependent load)."""
    if not inertia or not model.kin.finite or state_dependent_loads(model):
        return None
    from ..solvers.inertia import TangentInertia

    return TangentInertia(model.comm, "beamfx_static_inertia_")


def state_dependent_loads(model):
    """Whether the load vector depends on the state (then the tangent is unsymmetric): for
    follower and semitangential loads, and for fixed moments under finite rotations (their
    work is M·δθ with δθ a function of q)."""
    loads = (*model.spec.point_loads, *model.spec.distributed_loads)
    return any(ld.kind != "dead" or (model.kin.finite and any(ld.moment)) for ld in loads)
