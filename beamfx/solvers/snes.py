"""Newton's method through PETSc SNES on a residual form and its Jacobian."""

import math
import time
from typing import NamedTuple

import numpy as np

from .assembly import assemble_residual, assemble_tangent, prescribed, same_coefficients
from .blocked import use_node_blocks
from .convergence import ScaledTest, diagnose, reason_names
from .forms import compile_form
from .options import DENSE, describe, expand_linear, petsc_options, use_dense

#: defaults chosen for beams (notes §4): full Newton steps (the bt line search stalls on the
#: stiff axial term), no divergence stop, LU with MUMPS. The convergence test is beamfx's
#: (:mod:`~beamfx.solvers.convergence`): snes_atol and snes_rtol are read by it, snes_stol is
#: not used (a small step alone is not convergence)
DEFAULT_OPTIONS = {
    "snes_type": "newtonls",
    "snes_linesearch_type": "basic",
    "snes_max_it": 25,
    "snes_divergence_tolerance": -1,
    "ksp_type": "preonly",
    "pc_type": "lu",
    "pc_factor_mat_solver_type": "mumps",
}


#: PETSc log events that make up the linear solves: the preconditioner's set-up (the LU
#: factorisation: MUMPS's analysis and numeric factorisation, or the dense LU, whose
#: MatLUFactorNum PETSc does not log) and the triangular solves
LINEAR_EVENTS = {
    "factorise": ("PCSetUp",),
    "triangular_solve": ("MatSolve",),
}


_events = {}  # LINEAR_EVENTS' keys -> their PETSc log events, looked up once


def linear_solve_seconds():
    """Seconds spent so far in the :data:`LINEAR_EVENTS` (PETSc logging, started here)."""
    if not _events:
        from petsc4py import PETSc

        PETSc.Log.begin()  # the cost is a few counters per event
        for key, names in LINEAR_EVENTS.items():
            _events[key] = [PETSc.Log.Event(name) for name in names]
    return {key: sum(e.getPerfInfo()["time"] for e in events) for key, events in _events.items()}


class SolveReport(NamedTuple):
    """The outcome of a nonlinear solve: converged, why, the iterations and wall times."""

    converged: bool
    reason: str  # PETSc's name (convergence.REASONS says what it means)
    iterations: int
    residuals: tuple  # ‖F‖ at each iteration
    seconds: dict  # wall time: assemble_F, assemble_J, solve (= the rest: factorise,
    # triangular_solve, python = Python, SNES and vector work, test = the convergence test)
    criterion: str | None = None  # how it converged: 'residual', 'floor', 'relative'
    cause: str | None = None  # why it failed (convergence.REMEDIES' keys)
    detail: str | None = None  # the numbers behind the cause
    floor: float | None = None  # the round-off floor estimate at the last iterate, if known
    scale: float = 0.0  # the force scale S of the last iterate (load or reactions)


class SolveFailed(RuntimeError):
    """A numerical failure, with what was tried: ``history`` (accepted steps, or the eigen
    values found), ``cause`` and ``remedy`` (strings or None) and ``details`` (a dict for
    results.json)."""

    def __init__(self, message, history=(), cause=None, remedy=None, details=None):
        super().__init__(message)
        self.history, self.cause, self.remedy = history, cause, remedy
        self.details = details or {}


class NewtonSolver:
    """SNES over ``F(w) = 0`` with Jacobian ``J``; the state lives in the Function ``w``.

    Converged means :class:`~beamfx.solvers.convergence.ScaledTest` holds: set the force scale
    (:meth:`set_scale`) and the sizes added to the state in the floor estimate
    (:meth:`set_sizes`); the reactions are measured at every residual.

    Args:
        F, J: UFL residual and Jacobian forms.
        w: dolfinx Function of the unknowns.
        bcs: Dirichlet conditions; their values are the targets for ``w`` (not increments).
        prefix: PETSc options prefix (mandatory, e.g. "beamfx_static_").
        options: PETSc options without the prefix; merged over :data:`DEFAULT_OPTIONS`.
        coupling: optional non-local term that forms cannot hold (e.g. a follower force on
            the Kirchhoff rod, :class:`~beamfx.analyses.kirchhoff.KirchhoffModel`): its
            ``update()`` runs before each residual assembly (``w`` current) and its
            ``add_to_tangent(A)`` after each tangent assembly.
    """

    def __init__(self, F, J, w, bcs, prefix, options=None, coupling=None):
        import dolfinx.fem.petsc as fp
        from petsc4py import PETSc

        self.w, self.bcs, self.coupling = w, bcs, coupling
        self.F, self.J = compile_form(F), compile_form(J)
        self.b = fp.create_vector(self.F)
        self.A = fp.create_matrix(self.J)
        self.x = w.vector.copy()
        self.comm = w.function_space.mesh.comm
        self.seconds = {"assemble_F": 0.0, "assemble_J": 0.0, "solve": 0.0, "test": 0.0}
        linear_solve_seconds()  # start PETSc's event log before the first solve
        self._residuals = []
        self.options = {**DEFAULT_OPTIONS, **expand_linear(options)}
        # a small serial tangent: factored dense (LAPACK) from a copy kept beside the sparse A
        given = [k.removeprefix(prefix) for k in PETSc.Options().getAll() if k.startswith(prefix)]
        self.P = None
        if use_dense(options, self.A.getSize()[0], self.comm.size, given):
            self.options.update(DENSE)
            self.P = PETSc.Mat().createDense(self.A.getSizes(), comm=self.comm)
            self.P.setUp()
        self.atol = float(self.options.get("snes_atol", 0.0))
        self.rtol = float(self.options.get("snes_rtol", 0.0))
        self.force_scale, self.reactions, self.sizes = 0.0, 0.0, None
        self._rows = constrained_rows(bcs, self.b.getLocalSize())
        self._kept = None  # (x, F before the conditions, lifted) of the last residual
        self._targets = None  # the prescribed values on the constrained rows, per solve
        self._constants = (None, None)  # F's and J's constants packed, per solve
        # F's coefficients packed at the last residual's state (the state the tangent is
        # then asked at): J's too when J takes the same coefficients (checked once: None)
        self._packed, self._share = None, None

        snes = PETSc.SNES().create(w.function_space.mesh.comm)
        snes.setOptionsPrefix(prefix)
        snes.setFunction(self._residual, self.b)
        snes.setJacobian(self._jacobian, self.A, self.A if self.P is None else self.P)
        snes.setMonitor(lambda s, it, norm: self._residuals.append(norm))
        with petsc_options(prefix, self.options):
            snes.setFromOptions()
            snes.getKSP().setFromOptions()
            self.blocks = use_node_blocks(snes.getKSP(), w)  # AMG on whole beam nodes
        self.linear_solver = describe(snes.getKSP(), self.P is not None)  # recorded
        self.test = ScaledTest(self)
        snes.setConvergenceTest(self._test)
        self.snes = snes

    def _residual(self, snes, x, b):
        from petsc4py import PETSc

        t = time.perf_counter()
        serial = self.comm.size == 1  # no ghosts to update
        if not serial:
            x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        x.copy(self.w.vector)
        if not serial:
            self.w.x.scatter_forward()
        if self.coupling:
            self.coupling.update()
        kept = self._kept
        keep = kept[1] if kept else None
        self._packed = packed = _pack_coefficients(self.F)
        local, lifted = assemble_residual(
            b, self.F, self.J, self.bcs, x, self._rows, keep, self._targets, self._constants[0],
            packed,
        )  # fmt: skip
        if kept:
            kept[0][:] = x.getArray(readonly=True)
            kept[2] = lifted
        comm = self.comm
        self.reactions = math.sqrt(comm.allreduce(local) if comm.size > 1 else local)
        self.seconds["assemble_F"] += time.perf_counter() - t

    def _jacobian(self, snes, x, A, P):
        t = time.perf_counter()
        assemble_tangent(A, self.J, self.bcs, self._constants[1], self._tangent_coefficients())
        if self.coupling:
            self.coupling.add_to_tangent(A)
        if self.P is not None:  # the factored copy (its entries replaced, its storage kept)
            A.convert("dense", self.P)
        self.seconds["assemble_J"] += time.perf_counter() - t

    def _tangent_coefficients(self):
        """J's coefficients packed at the state of the last residual (SNES asks the tangent
        where it evaluated the residual last, and only the residual moves ``w``): the
        residual's packing when J takes the same coefficients (no coupling, whose
        ``update()`` may change them), else None (packed by the assembly)."""
        if self._share is None:
            self._share = self.coupling is None and same_coefficients(self.F, self.J)
        return self._packed if self._share else None

    def _test(self, snes, it, norms):
        t = time.perf_counter()
        reason = self.test(snes, it, norms)
        self.seconds["test"] += time.perf_counter() - t
        return reason

    def constrained_rows(self):
        """Owned local rows of the constrained dofs (:func:`constrained_rows` of its bcs)."""
        return self._rows

    def set_atol(self, atol):
        """Absolute residual tolerance, in the units of the residual (force, moment)."""
        self.atol = float(atol)

    def set_scale(self, force):
        """The force scale of the residual criterion (e.g. the load vector's norm); the
        reactions at the iterate count when larger."""
        self.force_scale = float(force)

    def set_sizes(self, sizes):
        """Per owned unknown, a size added to |x| in the round-off floor estimate (the terms of
        the reference state: e.g. the element length for a displacement, 1 for a rotation)."""
        self.sizes = None if sizes is None else np.asarray(sizes, float)

    def keep_residual(self):
        """Keep a copy of F (before the conditions replace its constrained rows) at every
        residual evaluation, for :meth:`residual_at_solution`."""
        n = self.b.getLocalSize()
        self._kept = [np.empty(n), np.empty(n), True]

    def residual_at_solution(self):
        """F at the last solution (owned entries, the constrained rows as assembled: the
        reactions), bitwise as an assembly of F there would give; None if it was not kept
        (:meth:`keep_residual`), was evaluated elsewhere or included a lifting."""
        kept = self._kept
        ok = kept is not None and not kept[2] and (kept[0] == self.x.getArray(readonly=True)).all()
        if self.comm.size > 1:  # the same answer on every rank: a None makes them assemble
            from mpi4py import MPI

            ok = self.comm.allreduce(bool(ok), op=MPI.LAND)
        return kept[1] if ok else None

    def solve(self):
        """Run Newton from the current ``w``; ``w`` holds the last iterate. Returns a report."""
        from petsc4py import PETSc

        self._residuals = []
        self._packed = None  # (a tangent before any residual packs its own)
        self.test.reset()
        # the prescribed values, fixed during the solve (whether a residual needs a lifting)
        self._targets = prescribed(self.bcs, self._rows, self.b.getLocalSize()).tolist()
        # the forms' constants (load factor, time, step) are those of this solve; a coupling
        # may change them at each residual: packed at every assembly then
        self._constants = (None, None) if self.coupling else packed_constants(self.F, self.J)
        before = dict(self.seconds)
        linear_before = linear_solve_seconds()
        t = time.perf_counter()
        self.w.vector.copy(self.x)
        code = self._run_snes()
        if code == PETSc.SNES.ConvergedReason.DIVERGED_LINEAR_SOLVE:
            # the failed factorisation is not used again: MUMPS would stop the next solve
            # (a step's retry) with INFOG(1) = -3; the reason is the same on every rank
            self.snes.getKSP().getPC().reset()
        self.x.copy(self.w.vector)
        self.w.x.scatter_forward()
        if code == PETSc.SNES.ConvergedReason.CONVERGED_ITS and self._residuals:
            # ksponly (one linear solve) stops without asking the test: ask it here
            self.test.linear(self.x, self._residuals[-1])
        seconds = self._split(before, linear_before, time.perf_counter() - t)
        reason = _reason_name(code)
        done = (reason, self.snes.getIterationNumber(), tuple(self._residuals), seconds)
        if code > 0 and self.test.how is not None:
            scale = self.test.records[-1]["scale"]
            return SolveReport(True, *done, criterion=self.test.how, scale=scale)
        floor = self.test.absolute.floor(self.A, self.x, self.sizes)
        cause, detail = diagnose(reason, self.test.records, floor)
        return SolveReport(False, *done, cause=cause, detail=detail, floor=floor)

    def _run_snes(self):
        """SNES from ``self.x``; its reason code. The dense LU (LAPACK getrf, :func:`use_dense`)
        stops with PETSc's error on an exactly zero pivot, where MUMPS reports a failed
        factorisation: a failed linear solve then too (``self.x`` the last iterate, the update
        not made), so that the run reports it. PETSc's events left open by the error then log
        no more time (the factorisation's seconds count as ``python``)."""
        from petsc4py import PETSc

        try:
            self.snes.solve(None, self.x)
        except PETSc.Error as e:
            if self.P is None or e.ierr != ZERO_PIVOT:
                raise
            return PETSc.SNES.ConvergedReason.DIVERGED_LINEAR_SOLVE
        return self.snes.getConvergedReason()

    def _split(self, before, linear_before, total):
        """This solve's wall-time split (and the running totals in ``self.seconds``)."""
        seconds = {k: self.seconds[k] - before[k] for k in self.seconds}
        seconds["solve"] = total - seconds["assemble_F"] - seconds["assemble_J"]
        self.seconds["solve"] += seconds["solve"]
        linear = linear_solve_seconds()
        for key in LINEAR_EVENTS:
            seconds[key] = linear[key] - linear_before[key]
        seconds["python"] = (
            seconds["solve"] - seconds["factorise"] - seconds["triangular_solve"] - seconds["test"]
        )
        for key in (*LINEAR_EVENTS, "python"):
            self.seconds[key] = self.seconds.get(key, 0.0) + seconds[key]
        return seconds

    def destroy(self):
        """Free the SNES and its matrix and vectors."""
        self.snes.destroy()
        self.test.destroy()
        if self.blocks is not None:
            self.blocks.destroy()
        if self.P is not None:
            self.P.destroy()
        self.A.destroy()
        self.b.destroy()
        self.x.destroy()


_reasons = {}
#: PETSc's error code of a zero pivot in an LU factorisation (PETSC_ERR_MAT_LU_ZRPVT)
ZERO_PIVOT = 71


def _pack_coefficients(form):
    """``dolfinx.cpp.fem.pack_coefficients(form)`` (the same call), its import made once."""
    from dolfinx.cpp.fem import pack_coefficients

    global _pack_coefficients
    _pack_coefficients = pack_coefficients
    return pack_coefficients(form)


def _reason_name(code):
    """PETSc's name of a SNES reason ``code`` (the table built once)."""
    if not _reasons:
        _reasons.update(reason_names())
    return _reasons.get(code, str(code))


def packed_constants(*forms):
    """The constants of each form as DOLFINx's assemblers take them, packed."""
    from dolfinx.cpp.fem import pack_constants

    return tuple(pack_constants(form) for form in forms)


def constrained_rows(bcs, n_owned):
    """Owned local rows of the dofs constrained by ``bcs`` (where the reactions are)."""
    if not bcs:
        return np.empty(0, np.int32)
    rows = np.unique(np.concatenate([bc.dof_indices()[0] for bc in bcs]))
    return rows[rows < n_owned]
