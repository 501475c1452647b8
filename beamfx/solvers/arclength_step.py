r"""The step of arc-length continuation (:mod:`.arclength`): Crisfield's (1981)
cylindrical/spherical arc length with a bordered Newton solve, or the Riks (1979) normal-plane
variant, over :math:`R(w, λ) = F(w, λ) = F_{int}(w) - λ f(w) = 0`.

Each step :math:`n \to n+1` with arc length :math:`Δl` solves :math:`R(w_n + Δw, λ_n + Δλ) = 0`
together with the constraint

.. math::  a(Δw, Δλ) = Δw^T S Δw + ψ^2 Δλ^2 f^T f - Δl^2 = 0,

where ``S`` selects the dofs that measure the path (e.g. displacements, so that rotation or
quaternion components do not dominate) and ψ weighs the load (ψ = 0: cylindrical, ψ = 1:
spherical). Each iteration factorises the tangent :math:`K = ∂R/∂w` once and solves twice,

.. math::  K δw_R = -R, \qquad K δw_f = f, \qquad δw = δw_R + δλ\, δw_f,

and δλ is the root of the quadratic :math:`a_1 δλ^2 + a_2 δλ + a_3 = 0` (Crisfield 1981,
eqs. 16–19) with :math:`u = Δw + δw_R`:

.. math::
    a_1 = δw_f^T S δw_f + ψ^2 f^T f, \quad
    a_2 = 2 δw_f^T S u + 2 ψ^2 Δλ f^T f, \quad
    a_3 = u^T S u + ψ^2 Δλ^2 f^T f - Δl^2,

taking the root whose new increment makes the smaller angle with the previous one. The Riks
variant keeps the iterates on the plane normal to the predictor :math:`(Δw_0, Δλ_0)`:
:math:`δλ = -Δw_0^T S δw_R / (Δw_0^T S δw_f + ψ^2 Δλ_0 f^T f)`.

The predictor is :math:`Δw_0 = Δλ_0 δw_f` with :math:`Δλ_0 = ± Δl / \sqrt{δw_f^T S δw_f + ψ^2 f^T
f}`, its sign that of :math:`Δw_{prev}^T S δw_f + ψ^2 Δλ_{prev} f^T f` (keep moving forward
through limit points and snap-backs).

References:
    M. A. Crisfield, "A fast incremental/iterative solution procedure that handles
    snap-through", Computers & Structures 13 (1981) 55–62.
    E. Riks, "An incremental approach to the solution of snapping and buckling problems",
    Int. J. Solids Struct. 15 (1979) 529–551.
"""

import math
import time

import numpy as np

from .arclength_types import _StepFailed
from .assembly import assemble_load, assemble_residual, assemble_tangent
from .convergence import diagnose
from .inertia import prepare
from .saddle import _deflate

#: a path is trivial in the measured dofs where the load moves them (‖δw_f‖ per unit load
#: factor) by less than this fraction of the geometric arc length (:meth:`ArcLengthSolver._trivial`)
TRIVIAL = 1e-12
#: MUMPS's errors of a workspace too small for the factorisation (INFOG(1)): -8, -9 the
#: main integer and real arrays, -11, -14 ... -17, -20 other internal ones
WORKSPACE_ERRORS = (-8, -9, -11, -14, -15, -17, -20)
#: how often a factorisation is retried with a larger workspace (ICNTL(14) times 4 each)
WORKSPACE_RETRIES = 4


class _Corrector:
    """The linear algebra and the corrector step of :class:`~.arclength.ArcLengthSolver` (a
    mixin: the solver's constructor sets the attributes these methods read)."""

    # --- assembly and linear algebra -------------------------------------------------------

    def _residual(self, lam):
        """R(w, λ) with zero rows on the constrained dofs (w satisfies the bcs)."""
        t = time.perf_counter()
        self.lam.value = lam
        local, _ = assemble_residual(self.R, self.F, self.J, self.bcs, self.w.vector, self._rows)
        self.reactions = float(np.sqrt(self.comm.allreduce(local)))
        self.seconds["assemble_F"] += time.perf_counter() - t
        return self.R.norm()

    def _load(self):
        """Load vector f = F(w, 0) - F(w, 1) = -∂F/∂λ at the current w, zero on constrained dofs."""
        t = time.perf_counter()
        assemble_load(self.f, self.F, self.lam, self.bcs)
        self.ff = self.f.dot(self.f)
        self.seconds["assemble_F"] += time.perf_counter() - t

    def _factor(self, lam):
        """Assemble K = ∂R/∂w at (w, λ) and factorise it."""
        from petsc4py import PETSc

        t = time.perf_counter()
        self.lam.value = lam
        assemble_tangent(self.A, self.J, self.bcs)
        self.seconds["assemble_J"] += time.perf_counter() - t
        t = time.perf_counter()
        try:
            self.ksp.setOperators(self.A)
            if not self._prepared:
                prepare(self.ksp)
                self._prepared = True
            self.ksp.setUp()
            for _ in range(WORKSPACE_RETRIES):
                margin = _larger_workspace(self.ksp)
                if margin is None:
                    break
                # MUMPS skips the numeric phase after a failed one: analyse anew
                self.ksp.reset()
                self.ksp.setOperators(self.A)
                prepare(self.ksp)
                self.ksp.getPC().getFactorMatrix().setMumpsIcntl(14, margin)
                self.ksp.setUp()
        except PETSc.Error as e:
            raise _StepFailed(f"factorisation failed (PETSc error {e.ierr})") from None
        finally:
            self.seconds["solve"] += time.perf_counter() - t

    def _solve(self, rhs, out, scale=1.0):
        """Solve out = scale · K⁻¹ rhs with the current factorisation."""
        t = time.perf_counter()
        self.ksp.solve(rhs, out)
        if scale != 1.0:
            out.scale(scale)
        self.seconds["solve"] += time.perf_counter() - t
        if self.ksp.getConvergedReason() < 0 or not np.isfinite(out.norm()):
            raise _StepFailed(f"linear solve failed (KSP reason {self.ksp.getConvergedReason()})")

    def _dot(self, a, b):
        """a^T S b over the owned dofs of all ranks."""
        from mpi4py import MPI

        local = np.dot(
            a.getArray(readonly=True)[self.norm_dofs], b.getArray(readonly=True)[self.norm_dofs]
        )
        return self.comm.allreduce(float(local), op=MPI.SUM)

    def _add(self, vec, alpha=1.0):
        """Update w += alpha · vec (owned dofs), then refresh the ghosts."""
        self.w.vector.axpy(alpha, vec)
        self.w.x.scatter_forward()

    # --- one step --------------------------------------------------------------------------

    def _tangent(self, lam):
        """δw_f = K⁻¹ f at the current point (the one :meth:`_at_state` left, if any)."""
        if self._cached is not None:
            t, self._cached = self._cached, None
            return t
        self._factor(lam)
        if self.settings.follower:
            self._load()
        self._solve(self.f, self.dw_f)
        return self.dw_f.copy()

    def _forward(self, direction, t):
        """The predictor's load direction ±1 along δw_f = ``t``: forward from the previous
        increment ``direction = (Δw, Δλ)``, or the sign ``direction`` itself."""
        if not isinstance(direction, tuple):
            return direction
        dw, dlam = direction
        if self._trivial(t):  # Δwᵀδw_f is round-off: the load factor goes on
            return math.copysign(1.0, dlam)
        return math.copysign(1.0, self._dot(dw, t) + self.settings.psi**2 * dlam * self.ff)

    def _length(self, dw, dlam):
        """The arc length of the increment (Δw, Δλ): (Δwᵀ S Δw + ψ² Δλ² fᵀf)^½, at least
        |Δλ| times the trivial floor (a step on a trivial path measures its load factor:
        :meth:`_predict`, so that a step redone to a part of it goes to that part)."""
        measured = math.sqrt(self._dot(dw, dw) + self.settings.psi**2 * dlam**2 * self.ff)
        return max(measured, abs(dlam) * self._trivial_floor())

    def _trivial_floor(self):
        """The measure of δw_f = K⁻¹f below which the path is trivial in the measured dofs:
        :data:`TRIVIAL` times the geometric arc length (0: none)."""
        s = self.settings
        return 0.0 if s.psi else TRIVIAL * (s.geometric_arc_length or 0.0)

    def _trivial(self, t):
        """Whether the load moves the measured dofs along δw_f = ``t`` by round-off only: a
        trivial path (the mixed form's inextensible, shear-rigid circular arch under a
        radial load: u ≡ 0 up to its bifurcation), which the cylindrical constraint cannot
        measure (its δw_f, round-off amplified near the bifurcation, steers the
        predictor). Its steps are then taken at a load factor fixed by the predictor."""
        return math.sqrt(self._dot(t, t)) <= self._trivial_floor()

    def _predict(self, lam_n, dl, direction, land_at=None, inject=None):
        """The predictor (Δw_0, Δλ_0) of a step (see :meth:`_step`)."""
        s, ff = self.settings, self.ff
        if inject is not None:
            dw = inject.copy()
            dw.scale(dl / math.sqrt(self._dot(dw, dw)))
            return dw, 0.0
        if land_at is not None:
            dw, dlam = direction[0].copy(), direction[1]
            dw.scale((land_at - lam_n) / dlam)
            return dw, land_at - lam_n
        t = self._tangent(lam_n)
        a = math.sqrt(self._dot(t, t) + s.psi**2 * ff)
        self._fixed = self._trivial(t)  # Δλ = Δl / floor, at that load factor
        a = max(a, self._trivial_floor())
        if a == 0:
            raise _StepFailed("the load moves no measured dof (δw_f^T S δw_f = 0, ψ = 0)")
        dlam = self._forward(direction, t) * dl / a
        t.scale(dlam)
        return t, dlam

    def _step(self, lam_n, dl, direction, land_at=None, inject=None, deflate=None):
        """Corrector iterations of one step from the current (converged) state (w_n, λ_n).

        Args:
            lam_n: load factor λ_n of the converged state.
            dl: arc length Δl of the step (displacement units).
            direction: (Δw_prev, Δλ_prev) of the previous step, or the sign of the first one.
            land_at: solve at this fixed load factor instead (δλ = 0), from the predictor
                ``direction = (Δw, Δλ)`` scaled onto it.
            inject: predictor Δw = ξ·inject with Δλ = 0, scaled to the arc length ``dl``
                (mode injection onto a secondary branch).
            deflate: a unit vector φ (the null vector near a bifurcation): the corrections
                have their φ components removed, so the iterates stay on the primary path
                where K is nearly singular (its round-off would move them along φ by
                floor/μ).

        Returns:
            (Δw, Δλ, iterations, residuals); w and λ hold the new point, and ``turn`` the
            corrector's move from the predictor over Δl (0 at a fixed load factor).
        """
        s = self.settings
        self._fixed = False
        dw, dlam = self._predict(lam_n, dl, direction, land_at, inject)
        fixed = land_at is not None or self._fixed
        dw0, dlam0 = dw.copy(), dlam
        self._add(dw)
        self.test.reset()
        residuals, ddlam = [], 0.0
        for it in range(s.max_iterations + 1):
            residuals.append(self._residual(lam_n + dlam))
            if self._converged(it, residuals[-1], lam_n + dlam, ddlam):
                self.turn = 0.0 if fixed or not dl else self._moved(dw, dlam, dw0, dlam0) / dl
                dw0.destroy()
                return dw, dlam, it, tuple(residuals)
            if residuals[-1] > s.divergence * residuals[0]:
                raise self._failed("DIVERGED_DTOL", "diverged", residuals)
            if it == s.max_iterations:
                break
            try:
                self._factor(lam_n + dlam)
                self._solve(self.R, self.dw_R, scale=-1.0)
                _deflate(self.dw_R, deflate, self.kinematic)
                if not fixed:
                    if s.follower:
                        self._load()
                    self._solve(self.f, self.dw_f)
                    _deflate(self.dw_f, deflate, self.kinematic)
                    ddlam = self._constraint(dw, dlam, dw0, dlam0, dl)
            except _StepFailed as e:
                raise _StepFailed(e.args[0], tuple(residuals), "linear solve", e.args[0]) from None
            self.dw_R.axpy(ddlam, self.dw_f)
            dw.axpy(1.0, self.dw_R)
            dlam += ddlam
            self._add(self.dw_R)
        raise self._failed(
            "DIVERGED_MAX_IT", f"no convergence in {s.max_iterations} iterations", residuals
        )

    def _moved(self, dw, dlam, dw0, dlam0):
        """How far the corrector took the step (Δw, Δλ) from its predictor (Δw₀, Δλ₀), in
        the arc-length metric."""
        d = dw.copy()
        d.axpy(-1.0, dw0)
        moved = self._length(d, dlam - dlam0)
        d.destroy()
        return moved

    def _converged(self, it, fnorm, lam, ddlam):
        """Newton's convergence test (:class:`~beamfx.solvers.convergence.ScaledTest`) at
        iteration ``it`` of a step, whose last correction is (δw = ``dw_R``, δλ = ``ddlam``):
        the force scale is the load λ·‖f‖; the floor and relative criteria also need a small
        δλ. Raises _StepFailed on a non-finite residual."""
        t = time.perf_counter()
        self.force_scale = abs(lam) * self.f_norm
        x = self.w.vector
        norms = (x.norm(), self.dw_R.norm() if it else 0.0, fnorm)
        how = self.test.check(it, norms, self.R, self.dw_R if it else None, x)
        if how in ("floor", "relative") and it:  # δλ's share of the correction settled too
            record = self.test.records[-1]
            if abs(ddlam) * self.dw_f.norm() > self.test.allowed(record, x):
                how = self.test.how = None
        self.seconds["test"] += time.perf_counter() - t
        if how == "nan":
            raise self._failed("DIVERGED_FNORM_NAN", "the residual is not finite", [fnorm])
        return how is not None

    def _failed(self, reason, why, residuals):
        """_StepFailed of a corrector that stopped with the PETSc-named ``reason``: the cause
        and its numbers by :func:`~beamfx.solvers.convergence.diagnose`."""
        floor = self.test.absolute.floor(self.A, self.w.vector, self.sizes)
        cause, detail = diagnose(reason, self.test.records, floor)
        return _StepFailed(f"{why}: {cause}", tuple(residuals), cause, detail)

    def _constraint(self, dw, dlam, dw0, dlam0, dl):
        """δλ of the bordered system (Crisfield's quadratic or Riks' normal plane)."""
        s, ff, dR, df = self.settings, self.ff, self.dw_R, self.dw_f
        if s.method == "riks":
            den = self._dot(dw0, df) + s.psi**2 * dlam0 * ff
            return -self._dot(dw0, dR) / den
        u = dw.copy()
        u.axpy(1.0, dR)
        a1 = self._dot(df, df) + s.psi**2 * ff
        a2 = 2 * self._dot(df, u) + 2 * s.psi**2 * dlam * ff
        a3 = self._dot(u, u) + s.psi**2 * dlam**2 * ff - dl**2
        disc = a2**2 - 4 * a1 * a3
        if a1 <= 0 or disc < 0:
            u.destroy()
            raise _StepFailed("the constraint has no real root (arc length too large)")
        q = -0.5 * (a2 + math.copysign(math.sqrt(disc), a2))  # stable quadratic roots
        roots = (q / a1, a3 / q) if q != 0 else (0.0, 0.0)
        # smallest angle with the previous increment: largest (u + δλ δw_f)^T S Δw
        u_dw, df_dw = self._dot(u, dw), self._dot(df, dw)
        cos = [u_dw + r * df_dw + s.psi**2 * dlam * (dlam + r) * ff for r in roots]
        u.destroy()
        return roots[int(np.argmax(cos))]


def _larger_workspace(ksp):
    """After a MUMPS factorisation of ``ksp`` that ran out of workspace (MUMPS sizes it from
    the analysis; an indefinite tangent with a large stiffness ratio, EA, GA ≫ EI/L², delays
    pivots beyond that estimate): the margin ICNTL(14) (percent) to factorise again with,
    four times the last; None after any other outcome."""
    pc = ksp.getPC()
    if pc.getType() not in ("lu", "cholesky") or pc.getFactorSolverType() != "mumps":
        return None
    F = pc.getFactorMatrix()
    if F.getMumpsInfog(1) not in WORKSPACE_ERRORS:
        return None
    return 4 * max(F.getMumpsIcntl(14), 20)
