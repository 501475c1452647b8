"""Settings, step records and results of arc-length continuation (:mod:`.arclength`)."""

from dataclasses import dataclass
from typing import NamedTuple


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
    reason: str  # "target", "stop" (the ``stop`` callback of the trace), "max_steps"
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
