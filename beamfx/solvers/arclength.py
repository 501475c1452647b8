r"""Arc-length continuation of :math:`R(w, λ) = F(w, λ) = F_{int}(w) - λ f(w) = 0`.

Crisfield's (1981) cylindrical/spherical arc length with a bordered Newton solve, or the
Riks (1979) normal-plane variant. Knows nothing of beams: it needs the compiled residual form
``F`` (load factor a ``fem.Constant``), its Jacobian ``J``, the unknowns ``w`` and the Dirichlet
conditions, whose values stay fixed along the path (the increments are homogeneous there).

The corrector step and its equations (Crisfield's quadratic constraint, Riks' normal plane, the
predictor): :mod:`.arclength_step`. The next arc length is :math:`Δl (I_d / I)^{1/2}`
(Crisfield 1981, eq. 25) for ``I`` iterations and a desired :math:`I_d`, bounded; a failed step is
retried with half the arc length. Stability, critical points, branch switching and the rules
against branch jumps: :mod:`.arclength_points`; the settings and results:
:mod:`.arclength_types`; the saddle-point helpers of the mixed formulation: :mod:`.saddle`.

References:
    M. A. Crisfield, "A fast incremental/iterative solution procedure that handles
    snap-through", Computers & Structures 13 (1981) 55–62.
    E. Riks, "An incremental approach to the solution of snapping and buckling problems",
    Int. J. Solids Struct. 15 (1979) 529–551.
"""

import math
import time

import numpy as np

from .arclength_points import INERTIA_JUMP, RELOCATIONS, SEPARATIONS, TRUST, _CriticalPoints
from .arclength_step import (
    TRIVIAL,
    WORKSPACE_ERRORS,
    WORKSPACE_RETRIES,
    _Corrector,
    _larger_workspace,
)
from .arclength_types import (
    ArcLengthResult,
    ArcLengthSettings,
    ArcLengthStep,
    _Path,
    _StepFailed,
)
from .bifurcation import CriticalPoint, classify
from .convergence import ScaledTest, remedy
from .forms import compile_form
from .inertia import InertiaCounter, counts_inertia
from .options import petsc_options
from .saddle import _deflate, _kinematic, inertia_offset
from .snes import SolveFailed, constrained_rows

__all__ = [
    "ARC_REMEDIES",
    "DEFAULT_OPTIONS",
    "INERTIA_JUMP",
    "RELOCATIONS",
    "SEPARATIONS",
    "TRIVIAL",
    "TRUST",
    "WORKSPACE_ERRORS",
    "WORKSPACE_RETRIES",
    "ArcLengthResult",
    "ArcLengthSettings",
    "ArcLengthSolver",
    "ArcLengthStep",
    "_deflate",
    "_kinematic",
    "_larger_workspace",
    "arc_remedy",
    "inertia_offset",
]

#: the bordered system is solved twice per factorisation: a direct solver is the natural fit
DEFAULT_OPTIONS = {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}


class ArcLengthSolver(_Corrector, _CriticalPoints):
    """Arc-length continuation over a residual form linear in the load factor.

    Args:
        F: UFL or compiled residual form F(w, λ) = F_int(w) - λ f(w).
        J: UFL or compiled Jacobian ∂F/∂w.
        w: dolfinx Function of the unknowns; holds the current point of the path.
        load_factor: the ``fem.Constant`` λ in ``F``; holds the current load factor.
        bcs: Dirichlet conditions; their values must not change along the path.
        prefix: PETSc options prefix of the linear solver (mandatory, e.g. "beamfx_arc_").
        options: PETSc options without the prefix, merged over :data:`DEFAULT_OPTIONS`.
        settings: :class:`ArcLengthSettings`.
        norm_dofs: local indices (of ``w.x.array``) of the dofs measured by the arc length
            (the matrix S); None measures all dofs.
        sizes: per owned unknown, the size added to |x| in the round-off floor estimate
            (:meth:`~beamfx.solvers.snes.NewtonSolver.set_sizes`); None: none.
        force_dofs: local indices of the force unknowns of a saddle-point tangent (the mixed
            formulation's section force; :func:`inertia_offset`); None: none.
    """

    def __init__(
        self,
        F,
        J,
        w,
        load_factor,
        bcs,
        prefix,
        options=None,
        settings=None,
        norm_dofs=None,
        sizes=None,
        force_dofs=None,
    ):
        import dolfinx.fem.petsc as fp
        from petsc4py import PETSc

        self.settings = settings or ArcLengthSettings()
        if self.settings.method not in ("crisfield", "riks"):
            raise ValueError(f"method must be 'crisfield' or 'riks', got {self.settings.method!r}")
        if self.settings.branch not in ("primary", "secondary"):
            raise ValueError(
                f"branch must be 'primary' or 'secondary', got {self.settings.branch!r}"
            )
        self.w, self.lam, self.bcs = w, load_factor, bcs
        self.F = F if hasattr(F, "ufcx_form") else compile_form(F)
        self.J = J if hasattr(J, "ufcx_form") else compile_form(J)
        self.comm = w.function_space.mesh.comm
        self.A = fp.create_matrix(self.J)
        self.R, self.f = fp.create_vector(self.F), fp.create_vector(self.F)
        self.dw_R, self.dw_f = self.R.duplicate(), self.R.duplicate()
        self.seconds = {"assemble_F": 0.0, "assemble_J": 0.0, "solve": 0.0}
        self.seconds.update(inertia=0.0, locate=0.0, test=0.0)
        # what Newton's convergence test reads (ScaledTest): the tangent, tolerances, the
        # force scale λ·‖f‖ and the reactions of the iterate, the sizes of the floor estimate
        self.b, self.atol, self.rtol = self.R, self.settings.atol, self.settings.rtol
        self.force_scale, self.reactions = 0.0, 0.0
        self.sizes = None if sizes is None else np.asarray(sizes, float)
        self._rows = constrained_rows(bcs, self.R.getLocalSize())
        self.test = ScaledTest(self)
        self.counting = self.settings.inertia and not self.settings.follower
        self._fixed = False  # the step's corrector at a fixed load factor (a trivial path)
        self.turn = 0.0  # of the last converged step: its corrector's move / Δl (_step)
        self._cached, self._prepared = None, False

        n_owned = (
            w.function_space.dofmap.index_map.size_local * w.function_space.dofmap.index_map_bs
        )
        if norm_dofs is None:
            self.norm_dofs = slice(None)
        else:
            d = np.asarray(norm_dofs)
            self.norm_dofs = d[d < n_owned]
        self.kinematic, self.offset = _kinematic(self.comm, n_owned, force_dofs)

        ksp = PETSc.KSP().create(self.comm)
        ksp.setOptionsPrefix(prefix)
        # a symmetric tangent: LDLᵀ, half the work of LU, and its pivots give the inertia
        base = {**DEFAULT_OPTIONS, **({"pc_type": "cholesky"} if self.counting else {})}
        self.options = {**base, **(options or {})}
        with petsc_options(prefix, self.options):
            ksp.setFromOptions()
        self.ksp = ksp
        self._counter = None
        if self.counting and not counts_inertia(ksp):
            self._counter = InertiaCounter(self.comm, prefix + "inertia_")

    # --- the path --------------------------------------------------------------------------

    def trace(
        self,
        arc_length=None,
        first_load_increment=0.05,
        max_steps=100,
        target_load_factor=None,
        stop=None,
        on_step=None,
        log=None,
    ):
        """Follow the equilibrium path from the current (w, λ), which must be converged.

        Args:
            arc_length: first Δl, in the units of the measured dofs; None: the Δl of a first
                load increment ``first_load_increment`` along the linear tangent.
            first_load_increment: see ``arc_length``; its sign picks the first direction.
            max_steps: accepted steps before stopping.
            target_load_factor: stop at the first crossing of this λ, landing on it with a
                load-controlled Newton solve (or, if that fails, just past it). The first
                step heads towards it; if it is the current λ, the trace runs until the path
                comes back to it (e.g. past a limit point).
            stop: ``stop(step) -> bool`` called after each accepted :class:`ArcLengthStep`
                (collectively, with ``w`` at the new point); True ends the trace.
            on_step: called with each accepted :class:`ArcLengthStep`.
            log: callable for one-line progress messages.

        Returns:
            :class:`ArcLengthResult`.

        Raises:
            SolveFailed: when Δl falls below its smallest value; names the step, the last
                converged λ and the residual history of every attempt.
        """
        t_start = time.perf_counter()
        lam = float(self.lam.value)
        self._load()
        self.f_norm = math.sqrt(self.ff)
        if self.f_norm == 0:
            raise ValueError("the load vector is zero: F does not depend on the load factor")
        sign = math.copysign(1.0, first_load_increment)
        if target_load_factor is not None and target_load_factor != lam:
            sign = math.copysign(1.0, target_load_factor - lam)
        count, forward = self._at_state(lam, sign)
        if arc_length is None:
            arc_length = self._first_arc_length(first_load_increment)
        path = _Path(lam, sign, count, forward, self._control(arc_length), [], [], [])
        saved = self.w.vector.copy()
        reason = "max_steps"
        while len(path.steps) < max_steps:
            self.w.vector.copy(saved)
            taken = self._attempt(path, saved, log)
            if taken is None:
                continue
            dw, dlam, its, res = taken
            path.turn = self.turn  # before a landing or the location's probes change it
            reached = _crosses(path.lam, dlam, target_load_factor)
            if reached and path.lam + dlam != target_load_factor:
                landed = self._land(saved, path.lam, dw, dlam, target_load_factor)
                if landed:
                    dw, dlam, its, res = landed
            state = self._at_state(path.lam + dlam, (dw, dlam))
            if self._jumped(path, saved, state, log):
                dw.destroy()
                continue
            outcome = self._accept(path, saved, (dw, dlam, its, res), state, on_step, log)
            if outcome == "redo":
                continue
            reached = reached and outcome != "switched"  # a switch ends before the step's end
            if reached:
                reason = "target"
                break
            if stop is not None and stop(path.steps[-1]):
                reason = "stop"
                break
            path.control.accepted(its)
        saved.destroy()
        self.lam.value = path.lam
        seconds = {**self.seconds, "total": time.perf_counter() - t_start}
        return ArcLengthResult(tuple(path.steps), reason, seconds, tuple(path.critical), count)

    def _first_arc_length(self, load_increment):
        """The Δl of a load increment ``load_increment`` along the linear tangent (cached at
        the start state by :meth:`_at_state`)."""
        t = self._cached
        return abs(load_increment) * math.sqrt(self._dot(t, t) + self.settings.psi**2 * self.ff)

    def _control(self, dl0):
        """The step controller of Δl from the first arc length ``dl0``."""
        from .step_control import IterationRatio, StepControl

        s = self.settings
        smallest, largest = s.bounds
        smallest = s.min_arc_length * dl0 if smallest is None else smallest
        if largest is None:
            largest = max(s.max_arc_length * dl0, s.geometric_arc_length or 0.0)
        growth = IterationRatio(s.desired_iterations, 0.5, s.max_growth)
        return StepControl(min(max(dl0, smallest), largest), largest, smallest, growth)

    def _attempt(self, path, saved, log):
        """One try of the next step: (Δw, Δλ, iterations, residuals), or None after a failure
        (state restored, Δl halved). Raises SolveFailed when Δl gets too small."""
        dl = path.control.size
        try:
            return self._step(path.lam, dl, path.direction)
        except _StepFailed as e:
            self._restore(saved, path.lam)
            why, residuals, cause, detail = (*e.args, (), None, None)[:4]
            self._reject(path, (dl, why, residuals, detail), cause, log)
            return None

    def _reject(self, path, tried, cause, log):
        """Note the failed attempt ``tried`` = (Δl, why, residuals, detail) and halve Δl;
        SolveFailed (by ``cause``) when it gets too small."""
        from .step_control import StepTooSmall

        dl, why, _, detail = tried
        path.tried.append(tried)
        if log:
            log(f"step {len(path.steps) + 1}: arc length {dl:.4g} failed ({why}); halving it")
        try:
            path.control.rejected()
        except StepTooSmall:
            failure = self._failure(len(path.steps) + 1, path.lam, path.tried)
            details = {"cause": cause, "detail": detail, "load_factor": path.lam}
            raise SolveFailed(
                failure, path.steps, cause, arc_remedy(cause), details=details
            ) from None

    def _accept(self, path, saved, taken, state, on_step, log):
        """Record the converged step ``taken`` from the state ``saved``, with ``state`` =
        (inertia, forward) at its end; the critical point it passed (located, and the branch
        switched, for a bifurcation). Returns "switched" when the path switched branch (it no
        longer ends where the step did), "redo" when the step is to be redone shorter (its
        critical point could not be located on it: state put back, Δl halved), else None."""
        dw, dlam, its, res = taken
        lam = path.lam + dlam
        count, forward = state
        kind = classify(path.count, count, path.forward, forward)
        if kind is not None:
            point = CriticalPoint(kind, len(path.steps) + 1, (path.lam, lam), path.count, count)
            if log:
                log(
                    f"step {point.step}: {kind} point passed between load factors "
                    f"{path.lam:.6g} and {lam:.6g} (negative eigenvalues {path.count} -> {count})"
                )
            # located (a limit point too: its load factor to the location's precision, not
            # to the path's parabola, whose error grows as Δs³ with the steps); a limit
            # point whose step changed the inertia by more than one passed another point
            # too, which the location would find instead: left to the parabola
            switch = kind == "bifurcation" and self.settings.branch == "secondary"
            if kind == "limit" and abs(count - path.count) != 1:
                path.critical.append(point)
            else:
                outcome = self._bifurcation(
                    path, saved, taken, point, switch and not path.switched, on_step, log
                )
                if outcome:
                    return outcome
        length = self._length(dw, dlam)
        self._record(path, (dw, dlam, its, res), length, count, forward, on_step, log)
        return None

    def _record(self, path, taken, length, count, forward, on_step, log, note=""):
        """Append the step ``taken`` (its end is the current state) and move the path on."""
        dw, dlam, its, res = taken
        steps = path.steps
        step = ArcLengthStep(
            len(steps) + 1, path.lam + dlam, length, its, res, len(path.tried), count, note
        )
        steps.append(step)
        if log:
            inertia = "" if count is None else f", {count} negative eigenvalues"
            log(
                f"step {step.step}: load factor {step.load_factor:.6g}, arc length "
                f"{length:.4g}, {its} iterations, |R| {res[-1] if res else 0:.3e}{inertia}"
                + (f" ({note})" if note else "")
            )
        if on_step:
            on_step(step)
        if isinstance(path.direction, tuple):
            path.direction[0].destroy()
        path.lam, path.direction, path.tried = step.load_factor, (dw, dlam), []
        if count is not None:
            path.count, path.forward = count, forward

    # --- landing and failures --------------------------------------------------------------

    def _land(self, saved, lam, dw, dlam, target):
        """Redo the step that crossed ``target`` at fixed λ = target; None if that fails."""
        crossed = self.w.vector.copy()
        self._restore(saved, lam)
        try:
            dw_t, dlam_t, its, res = self._step(lam, 0.0, (dw, dlam), land_at=target)
        except _StepFailed:
            crossed.copy(self.w.vector)
            self.w.x.scatter_forward()
            self.lam.value = lam + dlam
            return None
        finally:
            crossed.destroy()
        dw.destroy()
        return dw_t, dlam_t, its, res

    def _restore(self, saved, lam):
        saved.copy(self.w.vector)
        self.w.x.scatter_forward()
        self.lam.value = lam

    @staticmethod
    def _failure(step, lam, tried):
        lines = "\n".join(
            f"  arc length {dl:.4g}: {why}, |R| = "
            + ", ".join(f"{r:.3e}" for r in res)
            + (f" ({detail})" if detail else "")
            for dl, why, res, detail in tried
        )
        return (
            f"arc-length continuation failed at step {step} after {len(tried)} attempts, the "
            f"last converged load factor is {lam:.6g}; tried:\n{lines}"
        )

    def destroy(self):
        """Free the solver's PETSc objects."""
        self.test.destroy()
        for obj in (self.ksp, self.A, self.R, self.f, self.dw_R, self.dw_f):
            obj.destroy()
        if self._counter is not None:
            self._counter.destroy()
        if self._cached is not None:
            self._cached.destroy()


def _crosses(lam, dlam, target):
    """Whether the step from ``lam`` by ``dlam`` reaches or crosses ``target`` (None: no)."""
    if target is None:
        return False
    return (lam - target) * (lam + dlam - target) < 0 or lam + dlam == target


#: remedies of a failed arc-length step by cause, where they differ from a load step's
ARC_REMEDIES = {
    "divergence": "a smaller first arc length ([analysis] arc_length) or max_arc_length",
    "stagnation above the floor": "a smaller max_arc_length; if it persists, a smaller "
    "min_arc_length",
    "max iterations": "a smaller max_arc_length ([analysis]), or more iterations",
    "nan": "a smaller max_arc_length; a NaN also comes from a state outside the model's range "
    "(a folded element)",
    "branch jump": "a smaller first arc length ([analysis] arc_length)",
}


def arc_remedy(cause):
    """The remedy of a failed arc-length trace whose last attempt failed by ``cause``."""
    return ARC_REMEDIES.get(cause) or remedy(cause)
