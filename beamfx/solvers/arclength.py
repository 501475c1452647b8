r"""Arc-length continuation of :math:`R(w, λ) = F(w, λ) = F_{int}(w) - λ f(w) = 0`.

Crisfield's (1981) cylindrical/spherical arc length with a bordered Newton solve, or the
Riks (1979) normal-plane variant. Knows nothing of beams: it needs the compiled residual form
``F`` (load factor a ``fem.Constant``), its Jacobian ``J``, the unknowns ``w`` and the Dirichlet
conditions, whose values stay fixed along the path (the increments are homogeneous there).

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
through limit points and snap-backs). The next arc length is :math:`Δl (I_d / I)^{1/2}`
(Crisfield 1981, eq. 25) for ``I`` iterations and a desired :math:`I_d`, bounded; a failed step is
retried with half the arc length.

Stability: with a symmetric tangent (no follower load) the linear solver is MUMPS's LDLᵀ,
whose negative pivots count the negative eigenvalues of K (:mod:`beamfx.solvers.inertia`).
Each converged state is factorised once more (that factorisation also gives the next
predictor, so it replaces one the next step would make) and a change of the count flags a
limit or bifurcation point (:mod:`beamfx.solvers.bifurcation`): bifurcations are located, and
with ``branch = "secondary"`` the trace leaves the primary path at the first one.

Branch jumps: a converged step is redone with half the arc length when its inertia changed
by more than :data:`INERTIA_JUMP`, or when it changed at all but the critical point cannot be
located on the step while its corrector moved it more than :data:`TRUST` Δl from the
predictor (the zero of the eigenvalue lies on a smooth path between the step's ends, which
the location's shorter probes from the start follow: an end they cannot reach after a far
corrector move is on another branch, one the inertia differs from by one).

References:
    M. A. Crisfield, "A fast incremental/iterative solution procedure that handles
    snap-through", Computers & Structures 13 (1981) 55–62.
    E. Riks, "An incremental approach to the solution of snapping and buckling problems",
    Int. J. Solids Struct. 15 (1979) 529–551.
"""

import math
import time
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from .assembly import assemble_load, assemble_residual, assemble_tangent
from .bifurcation import CriticalPoint, classify, locate, smallest_eigenpair
from .convergence import ScaledTest, diagnose, remedy
from .forms import compile_form
from .inertia import InertiaCounter, counts_inertia, negative_pivots, prepare
from .options import petsc_options
from .snes import SolveFailed, constrained_rows

#: the largest change of the inertia in one accepted step: a double critical point (a
#: symmetric structure's pair of modes) and a limit point; more says that the corrector
#: converged onto another branch (:meth:`ArcLengthSolver._jumped`)
INERTIA_JUMP = 3
#: how often a step that passed a limit point with another critical point is halved to
#: separate them
SEPARATIONS = 4
#: how often a step whose inertia changed, whose corrector moved by more than
#: :data:`TRUST` Δl from its predictor and whose critical point could not be located on it
#: is redone with half the arc length (:meth:`ArcLengthSolver._unlocated`): the
#: eigenvalue's zero lies on a smooth path between the step's ends, so a location that
#: fails after a far move says the corrector converged onto another branch (one the
#: inertia changes by one to, e.g. the rising continuation of a nearly perfect bifurcation
#: that is a sharp limit point on the path: the shallow arch with EA × 1e6)
RELOCATIONS = 6
#: a corrector that moved the step less than this fraction of Δl from its (tangent)
#: predictor stayed on the path (a turn below ~14°): a location failing there is the
#: probes' trouble near a singular tangent, not another branch. The shallow arch's branch
#: jump moved 0.57 Δl (33°); steps across its critical points at ×1 move < 0.02 Δl
TRUST = 0.25
#: a path is trivial in the measured dofs where the load moves them (‖δw_f‖ per unit load
#: factor) by less than this fraction of the geometric arc length (:meth:`ArcLengthSolver._trivial`)
TRIVIAL = 1e-12
#: the bordered system is solved twice per factorisation: a direct solver is the natural fit
DEFAULT_OPTIONS = {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}


@dataclass(frozen=True)
class ArcLengthSettings:
    """Controls of :class:`ArcLengthSolver`.

    Attributes:
        method: "crisfield" (quadratic constraint) or "riks" (normal plane to the predictor).
        psi: weight ψ of the load term in the constraint (0: cylindrical, 1: spherical).
        follower: the load vector f depends on w (follower loads): re-assemble it every
            iteration as f = F(w, 0) - F(w, 1); otherwise it is assembled once.
        atol: absolute residual tolerance, in the units of the residual; the corrector's
            convergence test is Newton's (:mod:`beamfx.solvers.convergence`): the residual
            against the force scale (the load λ·‖f‖ or the reactions), or the round-off
            floor with small increments (also of λ).
        rtol: the test's relative criterion (‖R‖ ≤ rtol·‖R₀‖ with small increments); 0: off.
        max_iterations: corrector iterations per step before the step counts as failed.
        divergence: a step fails when ‖R‖ exceeds this multiple of its first residual.
        desired_iterations: I_d of the step-size rule Δl_new = Δl (I_d / I)^½.
        max_growth: bound on Δl_new / Δl after a converged step.
        min_arc_length, max_arc_length: bounds on Δl, as multiples of the first arc length.
            The smallest is far below it: a stiff structure (EA, GA ≫ EI/L²) reaches its
            first critical point over a displacement ∝ 1/EA (the star dome with EA × 1e6:
            6e-5 of its scene's first arc length), and the steps before it are halved
            down to that (their inertia jumps, :data:`INERTIA_JUMP`).
        geometric_arc_length: a Δl the steps may always grow to (units of the measured dofs):
            the default largest Δl is the larger of ``max_arc_length`` first arc lengths and
            this. The first arc length comes from the initial tangent, which a stiff axial or
            shear term (EA, GA ≫ EI/L²: a shallow arch's membrane state) makes tiny; without
            a geometric bound the whole path would be traced in steps of that size. None: the
            relative bound alone.
        bounds: (smallest, largest) Δl in the units of the measured dofs; an entry given
            replaces the relative bound.
        inertia: count the negative eigenvalues of the tangent at every converged state
            (symmetric tangents only: ignored for follower loads).
        branch: "primary" (locate bifurcations, go on along the path) or "secondary" (switch
            onto the secondary branch at the first bifurcation).
        switch_amplitude: arc length of the first step onto the secondary branch (None: the
            arc length of the step that passed the bifurcation).
        locate_tol: bifurcations are located to this fraction of the step's arc length.
    """

    method: str = "crisfield"
    psi: float = 0.0
    follower: bool = False
    atol: float = 0.0
    rtol: float = 0.0
    max_iterations: int = 12
    divergence: float = 1e6
    desired_iterations: int = 5
    max_growth: float = 2.0
    min_arc_length: float = 1e-8
    max_arc_length: float = 10.0
    bounds: tuple = (None, None)
    geometric_arc_length: float | None = None
    inertia: bool = True
    branch: str = "primary"
    switch_amplitude: float | None = None
    locate_tol: float = 1e-7


class ArcLengthStep(NamedTuple):
    """An accepted arc-length step: load factor, length, corrector iterations and cut-backs."""

    step: int
    load_factor: float
    arc_length: float  # length of the step, (Δw^T S Δw + ψ² Δλ² f^T f)^½ (= Δl for Crisfield)
    iterations: int  # corrector iterations (one factorisation each)
    residuals: tuple  # ‖R‖ before each corrector iteration and at convergence
    cutbacks: int  # failed attempts before this step converged
    negative_eigenvalues: int | None = None  # of the tangent at the new point (None: not counted)
    note: str = ""  # "bifurcation point" (located), "branch switch" (first secondary step)


class ArcLengthResult(NamedTuple):
    """The accepted steps of an arc-length trace, why it ended and its wall times."""

    steps: tuple  # accepted ArcLengthStep records
    reason: str  # "target", "stop", "max_steps"
    seconds: dict  # wall time split: assemble_F, assemble_J, solve, inertia, locate, total
    critical_points: tuple = ()  # CriticalPoint records, in path order
    negative_eigenvalues: int | None = None  # at the starting state


class _StepFailed(Exception):
    """A failed step: args (why, residuals, cause, detail); the cause is a key of
    :data:`~beamfx.solvers.convergence.REMEDIES`."""


@dataclass
class _Path:
    """Where a trace is: the last accepted state and what the next step needs."""

    lam: float
    direction: object  # (Δw, Δλ) of the last step, or the sign of the first one
    count: int | None  # negative eigenvalues of K at the last state
    forward: float  # the predictor's load direction ±1 there
    control: object  # StepControl of Δl
    steps: list
    critical: list
    tried: list  # (Δl, why, residuals, detail) of the failed attempts at the next step
    switched: bool = False
    turn: float = 0.0  # the corrector's move from the predictor / Δl in the step being taken


class ArcLengthSolver:
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

    def _jumped(self, path, saved, state, log):
        """Whether the converged step is to be redone shorter, from its end's ``state`` =
        (inertia, forward): its inertia changed by more than :data:`INERTIA_JUMP` (the
        corrector left the path for another branch: a linear predictor far beyond the
        path's curvature, a stiff initial tangent, whose load increment per arc length is
        large, and a corrector that converges from far, as the mixed formulation's does),
        or it passed a limit point and another critical point at once (the limit point is
        located alone: :meth:`_accept`), up to :data:`SEPARATIONS` times. The state is then
        put back and the arc length halved. Raises SolveFailed when Δl gets too small."""
        count, forward = state
        if count is None or path.count is None or count == path.count:
            return False
        change = abs(count - path.count)
        separate = forward != path.forward and change > 1
        tries = sum(1 for t in path.tried if t[1].startswith("a limit point"))
        if change <= INERTIA_JUMP and not (separate and tries < SEPARATIONS):
            return False
        self._restore(saved, path.lam)
        self._cached.destroy()  # δw_f at the rejected state
        self._cached = None
        if change > INERTIA_JUMP:
            why, cause = (
                f"the inertia jumped from {path.count} to {count}: another branch",
                "branch jump",
            )
        else:
            why = f"a limit point and another critical point (inertia {path.count} -> {count})"
            cause = "branch jump"
        self._reject(path, (path.control.size, why, (), None), cause, log)
        return True

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

    # --- stability -------------------------------------------------------------------------

    def _at_state(self, lam, direction):
        """Factorise K at the converged state and keep δw_f = K⁻¹f for the next predictor.

        Returns:
            (negative eigenvalues of K or None, the predictor's load direction ±1 there).
        """
        self._factor(lam)
        if self.settings.follower:
            self._load()
        self._solve(self.f, self.dw_f)
        if self._cached is not None:
            self._cached.destroy()
        self._cached = self.dw_f.copy()
        return self._count(), self._forward(direction, self._cached)

    def _count(self):
        """Negative eigenvalues of the factorised K (None when not counted)."""
        if not self.counting:
            return None
        t = time.perf_counter()
        n = negative_pivots(self.ksp) if self._counter is None else self._counter.count(self.A)
        self.seconds["inertia"] += time.perf_counter() - t
        return n - self.offset  # the force block's own (saddle point: inertia_offset)

    def _bifurcation(self, path, saved, taken, point, switch, on_step, log):
        """Locate the critical point (bifurcation or limit) the step ``taken`` passed; with
        ``switch``, record the located point and a first step along the secondary branch and
        return "switched"; else note the point, put the state back at the step's end and
        return None. A point that cannot be located: "redo" (:meth:`_unlocated`), or noted
        after :data:`RELOCATIONS` halvings."""
        dw, dlam = taken[:2]
        t = time.perf_counter()
        end, lam_end, cached = self.w.vector.copy(), path.lam + dlam, self._cached
        self._cached = None
        dl = self._length(dw, dlam)
        try:
            x, lam_c, mu, n, phi = self._locate(path, saved, (end, lam_end, dl), point)
        except _StepFailed as e:
            x = None
            if log:
                log(f"  the {point.kind} point could not be located ({e.args[0]})")
        self.seconds["locate"] += time.perf_counter() - t
        if x is not None:
            point = point._replace(load_factor=lam_c, eigenvalue=mu, probes=n)
            point = point._replace(bracket=self._bracket)
            if log:
                lo, hi = self._bracket
                log(
                    f"  {point.kind} point located at load factor {lam_c:.8g} ({n} solves; "
                    f"the inertia changes between {lo:.10g} and {hi:.10g})"
                )
        if x is None and self._unlocated(path, saved, point, log):
            cached.destroy()
            end.destroy()
            dw.destroy()
            return "redo"
        if x is None or not switch:
            path.critical.append(point)
            if x is not None:
                phi.destroy()
            self._restore(end, lam_end)
            self._cached = cached
            end.destroy()
            return None
        cached.destroy()
        end.destroy()
        path.critical.append(point._replace(switched=True))
        path.switched = True
        dw.destroy()
        dw_c = self.w.vector.copy()  # the located point, from the step's start
        dw_c.axpy(-1.0, saved)
        located = (dw_c, lam_c - path.lam, 0, ())
        self._record(path, located, x, None, path.forward, on_step, log, "bifurcation point")
        self._switch(path, phi, dl, on_step, log)
        return "switched"

    def _unlocated(self, path, saved, point, log):
        """After a failed location of ``point``: whether the step is to be redone with half
        the arc length (at most :data:`RELOCATIONS` times in a row; the state is then put
        back at its start). The eigenvalue that changed sign has its zero on a smooth path
        between the step's ends, which the probes (steps from the start, shorter) reach;
        when they do not and the corrector moved the step far from its predictor (more than
        :data:`TRUST` Δl), the end is on another branch. Raises SolveFailed when Δl gets
        too small."""
        why = f"the {point.kind} point could not be located on the step: another branch"
        if path.turn <= TRUST or sum(1 for t in path.tried if t[1] == why) >= RELOCATIONS:
            return False
        self._restore(saved, path.lam)
        self._reject(path, (path.control.size, why, (), None), "branch jump", log)
        return True

    def _locate(self, path, saved, end, point):
        """Find the critical point within the last step (module :mod:`.bifurcation`):
        returns (arc length from the step's start, λ, eigenvalue, solves, null vector); w
        and λ are left at the located point. The probes of a bifurcation deflate the null
        vector from their corrections; those of a limit point do not (the path's own
        tangent is the null vector there)."""
        from mpi4py import MPI

        end_vec, lam_end, dl = end
        phi = self.R.duplicate()
        rng = np.random.default_rng(self.comm.rank)
        start = rng.standard_normal(phi.getLocalSize())
        start[self._rows] = 0.0  # the constrained dofs' unit eigenvalues are not the structure's
        if self.kinematic is not None:
            start *= self.kinematic  # the pencil's metric: kinematic unknowns only
        phi.setArray(start)
        last = {}

        def probe(x):
            if x == dl:
                self._restore(end_vec, lam_end)
                lam = lam_end
            else:
                self._restore(saved, path.lam)
                lam = path.lam
                if x:
                    deflate = phi if point.kind == "bifurcation" else None
                    lam += self._step(path.lam, x, path.direction, deflate=deflate)[1]
            self._factor(lam)
            count = self._count()
            mu, _ = smallest_eigenpair(self.A, self._solve, phi, metric=self.kinematic)
            last.update(lam=lam, mu=mu)
            # the nearest probes on either side: the inertia brackets the point between them
            last["below" if count == point.negative_before else "above"] = lam
            return count, mu

        x, n = locate(probe, dl, point.negative_before, self.settings.locate_tol)
        self._bracket = (last["below"], last["above"])
        # the sign of the mode: its largest measured component positive (same on any ranks)
        a = phi.getArray(readonly=True)[self.norm_dofs]
        top = self.comm.allreduce(float(a.max(initial=-np.inf)), op=MPI.MAX)
        bottom = self.comm.allreduce(float(a.min(initial=np.inf)), op=MPI.MIN)
        if -bottom > top:
            phi.scale(-1.0)
        return x, last["lam"], last["mu"], n, phi

    def _switch(self, path, phi, dl, on_step, log):
        """Mode injection from the located point: the first step along φ, Δλ = 0 predicted,
        of arc length ``switch_amplitude`` (default ``dl``), halved up to 4 times."""
        amplitude = self.settings.switch_amplitude or dl
        start, lam_c = self.w.vector.copy(), path.lam
        for _ in range(5):
            try:
                taken = self._step(lam_c, amplitude, None, inject=phi)
                break
            except _StepFailed as e:
                self._restore(start, lam_c)
                if log:
                    log(f"  branch switch with amplitude {amplitude:.4g} failed ({e.args[0]})")
                amplitude /= 2
        else:
            raise SolveFailed(
                f"branch switching at load factor {lam_c:.6g} failed: the step along the "
                "null vector did not converge (try another switch_amplitude)",
                path.steps,
            )
        start.destroy()
        phi.destroy()
        dw, dlam = taken[:2]
        count, forward = self._at_state(lam_c + dlam, (dw, dlam))
        length = self._length(dw, dlam)
        self._record(path, taken, length, count, forward, on_step, log, note="branch switch")
        # the secondary branch has its own scale: the step sizes start again from this step's
        path.control = self._control(length)

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


#: MUMPS's errors of a workspace too small for the factorisation (INFOG(1)): -8, -9 the
#: main integer and real arrays, -11, -14 ... -17, -20 other internal ones
WORKSPACE_ERRORS = (-8, -9, -11, -14, -15, -17, -20)
#: how often a factorisation is retried with a larger workspace (ICNTL(14) times 4 each)
WORKSPACE_RETRIES = 4


def _crosses(lam, dlam, target):
    """Whether the step from ``lam`` by ``dlam`` reaches or crosses ``target`` (None: no)."""
    if target is None:
        return False
    return (lam - target) * (lam + dlam - target) < 0 or lam + dlam == target


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


def _deflate(v, phi, metric=None):
    """Remove the φ component of v: v ← v − (φᵀMv) φ, φ a unit vector in the metric M
    (the weights ``metric``, None: M = I; :func:`~.bifurcation.smallest_eigenpair`);
    nothing for φ None."""
    if phi is None:
        return
    if metric is None:
        v.axpy(-v.dot(phi), phi)
        return
    from mpi4py import MPI

    a = v.getArray(readonly=True) * metric
    local = float(np.dot(a, phi.getArray(readonly=True)))
    v.axpy(-v.getComm().tompi4py().allreduce(local, op=MPI.SUM), phi)


def _kinematic(comm, n_owned, force_dofs):
    """(weights 1 on the owned kinematic unknowns and 0 on the force unknowns, or None
    without force unknowns; their global number :func:`inertia_offset`)."""
    if force_dofs is None:
        return None, 0
    d = np.asarray(force_dofs)
    d = d[d < n_owned]
    weights = np.ones(n_owned)
    weights[d] = 0.0
    return weights, inertia_offset(comm, len(d))


def inertia_offset(comm, owned_forces):
    r"""The negative eigenvalues the force block adds to the inertia of a saddle-point
    tangent: its number of force unknowns (``owned_forces`` on this rank, summed).

    The mixed tangent is K = [[A, Bᵀ], [B, −S]] with the compliance S ≥ 0. For S > 0 the
    congruence K = Lᵀ diag(A + BᵀS⁻¹B, −S) L, L = [[I, 0], [−S⁻¹B, I]], and Sylvester's law
    of inertia give neg(K) = neg(A + BᵀS⁻¹B) + n_f: the condensed stiffness (the
    displacement form's tangent with its reduced axial and shear integration) plus one per
    force unknown. For S = 0 (rigid limits) and B of full rank n_f (the strains at the
    reduced points are independent), neg(K) = neg(ZᵀAZ) + n_f, Z a basis of ker B (the
    constrained stiffness); a mixed S with zero and positive entries combines both. So the
    count less n_f is the inertia the displacement form would report (zero on the
    constrained rows, whose diagonal is 1)."""
    from mpi4py import MPI

    return comm.allreduce(int(owned_forces), op=MPI.SUM)


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
