"""Newton's method through PETSc SNES on a residual form and its Jacobian."""

import time
from typing import NamedTuple

import numpy as np

from .assembly import assemble_residual, assemble_tangent
from .forms import compile_form
from .options import petsc_options

#: defaults chosen for beams (notes §4): full Newton steps (the bt line search stalls on the
#: stiff axial term), no divergence or step-size stop, LU with MUMPS
DEFAULT_OPTIONS = {
    "snes_type": "newtonls",
    "snes_linesearch_type": "basic",
    "snes_rtol": 1e-10,
    "snes_stol": 1e-13,
    "snes_max_it": 25,
    "snes_divergence_tolerance": -1,
    "ksp_type": "preonly",
    "pc_type": "lu",
    "pc_factor_mat_solver_type": "mumps",
}


#: PETSc log events that make up the linear solves: (sparse) LU factorisation and the
#: triangular solves (MUMPS is called through them)
LINEAR_EVENTS = {
    "factorise": ("MatLUFactorSym", "MatLUFactorNum"),
    "triangular_solve": ("MatSolve",),
}


def linear_solve_seconds():
    """Seconds spent so far in the :data:`LINEAR_EVENTS` (PETSc logging, started here)."""
    from petsc4py import PETSc

    PETSc.Log.begin()  # idempotent; the cost is a few counters per event
    return {
        key: sum(PETSc.Log.Event(name).getPerfInfo()["time"] for name in names)
        for key, names in LINEAR_EVENTS.items()
    }


class SolveReport(NamedTuple):
    """The outcome of a nonlinear solve: converged, why, the iterations and wall times."""

    converged: bool
    reason: str
    iterations: int
    residuals: tuple  # ‖F‖ at each iteration
    seconds: dict  # wall time: assemble_F, assemble_J, solve (= the rest: factorise,
    # triangular_solve, python = Python, SNES and vector work)


class SolveFailed(RuntimeError):
    """A nonlinear solve that did not converge, with what was tried."""

    def __init__(self, message, history=()):
        super().__init__(message)
        self.history = history


def _reason_names():
    from petsc4py import PETSc

    return {v: k for k, v in vars(PETSc.SNES.ConvergedReason).items() if not k.startswith("_")}


class NewtonSolver:
    """SNES over ``F(w) = 0`` with Jacobian ``J``; the state lives in the Function ``w``.

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
        self.seconds = {"assemble_F": 0.0, "assemble_J": 0.0, "solve": 0.0}
        linear_solve_seconds()  # start PETSc's event log before the first solve
        self._residuals = []

        snes = PETSc.SNES().create(w.function_space.mesh.comm)
        snes.setOptionsPrefix(prefix)
        snes.setFunction(self._residual, self.b)
        snes.setJacobian(self._jacobian, self.A)
        snes.setMonitor(lambda s, it, norm: self._residuals.append(norm))
        self.options = {**DEFAULT_OPTIONS, **(options or {})}
        with petsc_options(prefix, self.options):
            snes.setFromOptions()
            snes.getKSP().setFromOptions()
        self.snes = snes

    def _residual(self, snes, x, b):
        from petsc4py import PETSc

        t = time.perf_counter()
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        x.copy(self.w.vector)
        self.w.x.scatter_forward()
        if self.coupling:
            self.coupling.update()
        assemble_residual(b, self.F, self.J, self.bcs, x)
        self.seconds["assemble_F"] += time.perf_counter() - t

    def _jacobian(self, snes, x, A, P):
        t = time.perf_counter()
        assemble_tangent(A, self.J, self.bcs)
        if self.coupling:
            self.coupling.add_to_tangent(A)
        self.seconds["assemble_J"] += time.perf_counter() - t

    def set_atol(self, atol):
        """Absolute residual tolerance, in the units of the residual (force, moment)."""
        rtol, _, stol, max_it = self.snes.getTolerances()
        self.snes.setTolerances(rtol=rtol, atol=atol, stol=stol, max_it=max_it)

    def solve(self):
        """Run Newton from the current ``w``; ``w`` holds the last iterate. Returns a report."""
        self._residuals = []
        before = dict(self.seconds)
        linear_before = linear_solve_seconds()
        t = time.perf_counter()
        self.w.vector.copy(self.x)
        self.snes.solve(None, self.x)
        self.x.copy(self.w.vector)
        self.w.x.scatter_forward()
        code = self.snes.getConvergedReason()
        total = time.perf_counter() - t
        seconds = {k: self.seconds[k] - before[k] for k in self.seconds}
        seconds["solve"] = total - seconds["assemble_F"] - seconds["assemble_J"]
        self.seconds["solve"] += seconds["solve"]
        linear = linear_solve_seconds()
        for key in LINEAR_EVENTS:
            seconds[key] = linear[key] - linear_before[key]
        seconds["python"] = seconds["solve"] - seconds["factorise"] - seconds["triangular_solve"]
        for key in (*LINEAR_EVENTS, "python"):
            self.seconds[key] = self.seconds.get(key, 0.0) + seconds[key]
        residuals = tuple(self._residuals)
        # a step-size (stol) stop is only convergence if the residual did not grow
        converged = (
            code > 0
            and np.all(np.isfinite(residuals))
            and (len(residuals) < 2 or residuals[-1] <= residuals[0])
        )
        return SolveReport(
            bool(converged),
            _reason_names().get(code, str(code)),
            self.snes.getIterationNumber(),
            residuals,
            seconds,
        )

    def destroy(self):
        """Free the SNES and its matrix and vectors."""
        self.snes.destroy()
        self.A.destroy()
        self.b.destroy()
        self.x.destroy()
