"""Equilibrium paths past limit points: arc-length continuation of a :class:`BeamModel`.

The path is parametrised by the load factor λ of ``model.F = F_int(w) - λ F_ext(w)`` and the
displacement of one named point; the arc length measures the displacement dofs only (the
``W.sub(0)`` dofs), so that quaternion components do not weigh in, nor the mixed
formulation's section force (:mod:`beamfx.analyses.mixed`), whose negative pivots the
inertia count leaves out.
"""

import time
from dataclasses import replace
from typing import NamedTuple

import numpy as np

from ..geometry.mesh import mesh_size
from ..solvers.arclength import ArcLengthSettings, ArcLengthSolver
from ..solvers.forms import compile_seconds
from ..spec import DOF_NAMES
from .dofs import owned_size, point_displacement, point_displacement_dofs, subspace_dofs
from .mixed import owned_force_dofs
from .static import state_dependent_loads, state_sizes


class PathPoint(NamedTuple):
    """A point of the traced path: load factor, control-point displacement, arc length."""

    load_factor: float
    displacement: np.ndarray  # (3,) at the control point, global axes
    iterations: int  # corrector iterations of the step that reached it (0 at the start)
    arc_length: float  # s, the path length from the start (measured on the displacement dofs)
    negative_eigenvalues: int | None = None  # of the tangent (None: not counted)
    note: str = ""  # "bifurcation point" or "branch switch"


class LimitPoint(NamedTuple):
    """A maximum or minimum of the load factor along the path."""

    kind: str  # "maximum" or "minimum" of the load factor along the path
    load_factor: float
    displacement: np.ndarray  # (3,) at the control point
    arc_length: float


class ContinuationResult(NamedTuple):
    """The traced path, why the trace ended and the solver's steps and times."""

    path: tuple  # PathPoint, the first one the starting state
    control_point: str
    steps: tuple  # ArcLengthStep records of the solver
    reason: str  # why the trace ended: "target", "displacement_limit", "stop" (the caller's
    # stop callback) or "max_steps"
    seconds: dict  # wall time split: compile, assemble_F, assemble_J, solve, inertia, locate,
    # total
    critical_points: tuple = ()  # CriticalPoint records (beamfx.solvers.bifurcation)

    @property
    def load_factors(self):
        """Load factor of each path point, the start first."""
        return np.array([p.load_factor for p in self.path])

    @property
    def displacements(self):
        """(points, 3) displacements of the control point along the path (global axes)."""
        return np.array([p.displacement for p in self.path]).reshape(-1, 3)


def _check_model(model):
    for sup in model.spec.supports:
        if np.any(sup.displacement) or np.any(sup.rotation):
            raise ValueError(
                f"support at {sup.at!r} prescribes a displacement or rotation: "
                "arc-length continuation scales loads only (use solve_static)"
            )


def trace_path(
    model,
    control_point=None,
    max_steps=100,
    target_load_factor=None,
    arc_length=None,
    first_load_increment=0.05,
    displacement_limit=None,
    stop=None,
    settings=None,
    options=None,
    prefix="beamfx_arclength_",
    on_step=None,
    log=None,
):
    """Follow the equilibrium path of ``model`` from its current state by arc length.

    Crisfield's cylindrical arc length on the displacement dofs (ψ = 0 by default) with a
    bordered Newton corrector; see :mod:`beamfx.solvers.arclength` for the equations.

    Args:
        model: :class:`~beamfx.analyses.model.BeamModel` in a converged state (e.g. just reset).
        control_point: named point whose displacement is recorded; default the first point
            load's point.
        max_steps: accepted arc-length steps before stopping.
        target_load_factor: stop on reaching this load factor (landing exactly on it).
        arc_length: first arc length (displacement units); None: that of a first load
            increment ``first_load_increment`` on the linear tangent.
        first_load_increment: see ``arc_length``.
        displacement_limit: ``(component, value)`` with component in "ux", "uy", "uz": stop
            once that displacement of the control point reaches ``|value|`` in magnitude (at
            the first accepted point at or past it: the trace does not land on the limit);
            the reason is then "displacement_limit".
        stop: ``stop(path) -> bool`` called with the list of :class:`PathPoint` after each
            step; True ends the trace (e.g. once the load has dropped past a limit point),
            the reason "stop".
        settings: :class:`~beamfx.solvers.arclength.ArcLengthSettings` (follower loads are
            detected from the model).
        options: PETSc options of the linear solver (without the prefix).
        prefix: mandatory PETSc options prefix of the linear solver.
        on_step: called with each new :class:`PathPoint`.
        log: callable for one-line progress messages.

    Returns:
        :class:`ContinuationResult`.

    Raises:
        SolveFailed: when the arc length has to shrink below its minimum.
        ValueError: for prescribed support motions or unknown names.
    """
    t0 = time.perf_counter()
    _check_model(model)
    control_point, comp, limit = _control(model.spec, control_point, displacement_limit)
    dofs = point_displacement_dofs(model, control_point)
    u_dofs = subspace_dofs(model.W, 0)
    settings = _model_settings(model, settings or ArcLengthSettings(), u_dofs)
    c0 = compile_seconds[0]
    solver = ArcLengthSolver(
        *(model.F, model.J, model.w, model.load_factor, model.bcs, prefix, options, settings),
        norm_dofs=u_dofs,
        sizes=state_sizes(model),
        force_dofs=owned_force_dofs(model),
    )
    compile_time = compile_seconds[0] - c0
    path, record = _recorder(model, dofs, on_step)

    stop_here, stopped = _stopper(path, comp, limit, stop)
    try:
        result = solver.trace(
            arc_length, first_load_increment, max_steps, target_load_factor, stop_here, record, log
        )
    finally:
        solver.destroy()
    model.set_load_factor(float(model.load_factor.value))  # the support values follow λ
    seconds = {"compile": compile_time, **result.seconds, "total": time.perf_counter() - t0}
    path[0] = path[0]._replace(negative_eigenvalues=result.negative_eigenvalues)
    reason = stopped[-1] if result.reason == "stop" else result.reason
    return ContinuationResult(
        tuple(path), control_point, result.steps, reason, seconds, result.critical_points
    )


def _stopper(path, comp, limit, stop):
    """(``stop_here(step)`` for the solver: the displacement limit of component ``comp``
    (None: none) reached at the last point of ``path``, or the caller's ``stop(path)``; the
    list whose last item says which ended the trace: "displacement_limit" or "stop")."""
    stopped = []

    def stop_here(step):
        if comp is not None and abs(path[-1].displacement[comp]) >= abs(limit):
            stopped.append("displacement_limit")
            return True
        if stop is not None and stop(path):
            stopped.append("stop")
            return True
        return False

    return stop_here, stopped


def _control(spec, control_point, displacement_limit):
    """(control point, index of the limited component or None, the limit): the first point
    load's point by default."""
    if control_point is None:
        if not spec.point_loads:
            raise ValueError("no point load: name a control_point")
        control_point = spec.point_loads[0].at
    if displacement_limit is None:
        return control_point, None, None
    comp, limit = displacement_limit
    if comp not in DOF_NAMES[:3]:
        raise ValueError(
            f"displacement_limit component must be one of {DOF_NAMES[:3]}, got {comp!r}"
        )
    return control_point, DOF_NAMES.index(comp), limit


def _recorder(model, dofs, on_step):
    """(the path so far, starting at the current state; ``record(step)`` appending a step's
    :class:`PathPoint` and calling ``on_step`` with it)."""
    path = [PathPoint(float(model.load_factor.value), point_displacement(model, dofs), 0, 0.0)]

    def record(step):
        s = path[-1].arc_length + step.arc_length
        u = point_displacement(model, dofs)
        path.append(
            PathPoint(step.load_factor, u, step.iterations, s, step.negative_eigenvalues, step.note)
        )
        if on_step:
            on_step(path[-1])

    return path, record


def _model_settings(model, settings, u_dofs):
    """``settings`` with what the model decides: follower loads, and the defaults of the
    switch amplitude and of the geometric bound of a step (collective)."""
    settings = replace(settings, follower=settings.follower or state_dependent_loads(model))
    if settings.switch_amplitude is None:  # far enough from the bifurcation for its inertia
        settings = replace(settings, switch_amplitude=SWITCH_AMPLITUDE * model_size(model))
    if settings.geometric_arc_length is None:
        settings = replace(settings, geometric_arc_length=geometric_arc_length(model, u_dofs))
    return settings


#: default arc length of the first step onto a secondary branch, as a fraction of the model's
#: size: at 1e-2 the eigenvalue of the tangent that passed zero has grown to about 1e-4 of
#: its scale on an Euler column's branch (far above round-off, so the inertia is certain)
SWITCH_AMPLITUDE = 1e-2


#: the geometric bound of a step: every measured dof moving by this fraction of the model's size
#: (root mean square); below the steps of the shallow arch at its physical stiffness (0.5 %),
#: so that the relative bound (10 first arc lengths) keeps deciding where it is the larger
GEOMETRIC_FRACTION = 4e-3


def geometric_arc_length(model, u_dofs):
    """The arc length of a step that moves each measured dof (``u_dofs``, local indices) by
    :data:`GEOMETRIC_FRACTION` of the model's size: the largest arc length a trace may always
    reach, whatever the stiffness of its initial tangent (collective)."""
    from mpi4py import MPI

    owned = owned_size(model.W)
    count = model.comm.allreduce(int(np.count_nonzero(np.asarray(u_dofs) < owned)), op=MPI.SUM)
    return GEOMETRIC_FRACTION * model_size(model) * float(np.sqrt(count))


def model_size(model):
    """The largest extent of the model's mesh along x, y or z, over all ranks (collective)."""
    return mesh_size(model.mesh.mesh)


def limit_in_step(path, step, load_factor):
    """The :class:`LimitPoint` of a limit point located (by the inertia) at ``load_factor``
    inside ``step`` (between path points ``step`` − 1 and ``step``) where the path has no
    discrete extremum there, e.g. when the path ends within a step of the limit: its place
    s and displacement from the parabola λ(s) through the step's points and the one before,
    its vertex kept within the step."""
    i = min(max(step, 2), len(path) - 1)
    lam = np.array([p.load_factor for p in path[i - 2 : i + 1]])
    s = np.array([p.arc_length for p in path[i - 2 : i + 1]])
    u = np.array([p.displacement for p in path[i - 2 : i + 1]]).reshape(-1, 3)
    c = np.polyfit(s - s[1], lam, 2)
    ds = -c[1] / (2 * c[0]) if c[0] != 0 else s[2] - s[1]
    ds = float(np.clip(ds, 0.0, s[2] - s[1]))
    du = [np.polyval(np.polyfit(s - s[1], u[:, k], 2), ds) for k in range(3)]
    kind = "maximum" if load_factor >= max(lam[1], lam[2]) else "minimum"
    return LimitPoint(kind, float(load_factor), np.array(du), float(s[1] + ds))


def limit_points(path):
    """Local extrema of the load factor along a path, located by a parabola in s.

    The parabola through the three path points around a discrete extremum, λ(s) and u(s)
    quadratic in the arc length s, places the limit point with an error O(Δs³). Points where
    the path switches branch (a ``note``) are no extrema of a smooth path and are skipped.

    Args:
        path: sequence of :class:`PathPoint` (``ContinuationResult.path``).

    Returns:
        list of :class:`LimitPoint` in path order.
    """
    lam = np.array([p.load_factor for p in path])
    s = np.array([p.arc_length for p in path])
    u = np.array([p.displacement for p in path]).reshape(-1, 3)
    out = []
    for i in range(1, len(path) - 1):
        rise, fall = lam[i] - lam[i - 1], lam[i + 1] - lam[i]
        if rise * fall >= 0 or any(getattr(p, "note", "") for p in path[i - 1 : i + 2]):
            continue  # no extremum, or the path changes branch there (not smooth)
        x = s[i - 1 : i + 2]
        c = np.polyfit(x - x[1], lam[i - 1 : i + 2], 2)
        ds = -c[1] / (2 * c[0])
        du = [np.polyval(np.polyfit(x - x[1], u[i - 1 : i + 2, k], 2), ds) for k in range(3)]
        out.append(
            LimitPoint(
                "maximum" if rise > 0 else "minimum",
                float(np.polyval(c, ds)),
                np.array(du),
                float(x[1] + ds),
            )
        )
    return out
