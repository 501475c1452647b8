"""Newton's convergence test with a scale, and what a stop means.

The residual of an assembled nonlinear problem cannot fall below a round-off floor: each entry
is a sum of terms (stiffness times state) that cancel at equilibrium, and every term carries a
relative error of about the machine epsilon. With a stiff axial term (EA·L²/EI of 1e8 and
more) that floor, about eps·EA, lies far above a tolerance of 1e-10 of the load, and Newton
stalls there for ever. :class:`ScaledTest` replaces PETSc's default test (``snes_atol``,
``snes_rtol``, ``snes_stol``) with:

* **residual**: ‖F‖ ≤ max(atol, 1e-10·S), S the force scale of the model: the load norm given
  by the analysis or the norm of the reactions (the internal force at the supports), the
  larger;
* **floor**: ‖F‖ ≤ :data:`FLOOR_FACTOR` × the round-off floor ε‖ |K| (|x| + s) ‖ (|K| the
  tangent's entries in absolute value, s a size per unknown added to the state, e.g. the
  element length for displacements, so that the terms of the reference geometry count), and
  ‖F‖ ≤ :data:`FLOOR_LIMIT`·S (or, without any load, the reactions are at the floor too, or
  the floor is the model's own at its reference geometry: a small load on a stiff model, or
  the floor is the model's stiffness ratio at a state within :data:`STATE_RANGE` times the
  reference sizes and Newton's corrections no longer decrease: EA, GA ≫ EI/L²),
  *and* the increment criteria hold: the last correction is small against the state,
  ‖du‖ ≤ :data:`INCREMENT_TOL`·‖|x| + s‖ (or :data:`SETTLED_TOL`·‖|x| + s‖ once the
  corrections stagnate: round-off moves the state, Newton no longer does), and its
  energy is small, |du·F| ≤ :data:`ENERGY_TOL`·E
  with E the largest of the solve's largest correction energy, the state's |x·Kx| and the
  floor's energy over the state's size, floor·‖|x| + s‖ (what round-off resolves);
* **relative** (only if ``snes_rtol`` is given in ``[solver]``): ‖F‖ ≤ rtol·‖F₀‖ and the
  increment criteria hold.

A step-size stop alone is never convergence. Every stop is reported by its PETSc name with
:data:`REASONS`; a failure also by a cause and a remedy (:func:`diagnose`).
"""

import numpy as np

#: residual tolerance relative to the force scale S
RESIDUAL_TOL = 1e-10
#: how far above the estimated round-off floor a residual still counts as at the floor
FLOOR_FACTOR = 10.0
#: the floor is accepted only if the residual is also below this fraction of the force scale
#: (five digits of equilibrium); a floor above it means the state cannot be resolved
FLOOR_LIMIT = 1e-5
#: the increment criterion at the floor: ‖du‖ ≤ INCREMENT_TOL·‖|x| + s‖ ...
INCREMENT_TOL = 1e-10
#: ... or ‖du‖ ≤ SETTLED_TOL·‖|x| + s‖ once the corrections stagnate (round-off)
SETTLED_TOL = 1e-6
#: the energy criterion at the floor (quadratic in the error: INCREMENT_TOL²)
ENERGY_TOL = 1e-12
#: a floor above FLOOR_LIMIT·S is the model's own (its stiffness ratio) when the state raised
#: it by at most this factor over the floor of the reference geometry (displacements within
#: STATE_RANGE node spacings, rotations within STATE_RANGE rad); a larger factor: a state
#: outside the model's range (the 1e12 and 1e15 N cantilevers: 1e7 and more)
STATE_RANGE = 1e3

#: PETSc's SNES reasons and what they mean here
REASONS = {
    "CONVERGED_FNORM_ABS": "residual below the scaled absolute tolerance (residual criterion)",
    "CONVERGED_FNORM_RELATIVE": "residual reduced by snes_rtol, with a small increment",
    "CONVERGED_SNORM_RELATIVE": "residual at its round-off floor, with a small increment and "
    "energy (floor criterion)",
    "CONVERGED_ITS": "stopped at a fixed number of iterations (snes_type ksponly)",
    "CONVERGED_ITERATING": "still iterating",
    "DIVERGED_MAX_IT": "snes_max_it iterations without meeting the convergence test",
    "DIVERGED_LINE_SEARCH": "the line search found no decrease of the residual",
    "DIVERGED_LINEAR_SOLVE": "the linear solve failed (singular or indefinite tangent)",
    "DIVERGED_FNORM_NAN": "the residual became NaN or infinite",
    "DIVERGED_DTOL": "the residual grew beyond snes_divergence_tolerance times the first one",
    "DIVERGED_FUNCTION_DOMAIN": "the state left the domain of the residual",
    "DIVERGED_FUNCTION_COUNT": "too many residual evaluations (snes_max_funcs)",
    "DIVERGED_LOCAL_MIN": "stuck in a local minimum of the residual norm",
    "DIVERGED_INNER": "an inner solve failed",
    "DIVERGED_JACOBIAN_DOMAIN": "the tangent could not be evaluated at the state",
    "DIVERGED_TR_DELTA": "the trust region became too small",
}

#: the PETSc reason of each outcome of :meth:`ScaledTest.check`
CODES = {
    None: "CONVERGED_ITERATING",
    "nan": "DIVERGED_FNORM_NAN",
    "residual": "CONVERGED_FNORM_ABS",
    "relative": "CONVERGED_FNORM_RELATIVE",
    "floor": "CONVERGED_SNORM_RELATIVE",
}

#: remedies by cause
REMEDIES = {
    "divergence": "smaller load steps: [analysis] steps = {steps} (or more)",
    "stagnation above the floor": "smaller load steps: [analysis] steps = {steps}; if it "
    'persists, the load may be past a limit point (use type = "arclength")',
    "floor above the force scale": "a smaller load (check its units: the displacements and "
    "rotations reached are far outside the model's range) or a stiffer section",
    "stagnation at the floor": "the increments do not settle at the round-off floor: the "
    "stiffness ratio is too large for double precision on this mesh (fewer or lower-degree "
    "elements, or shear = false / stretch = false in [model])",
    "max iterations": "more iterations ([solver] snes_max_it = 50) or smaller load steps: "
    "[analysis] steps = {steps}",
    "line search": 'the default full Newton step: [solver] snes_linesearch_type = "basic"',
    "linear solve": "check supports: the structure is a mechanism or lost its stiffness "
    '(a limit point: use type = "arclength")',
    "nan": "smaller load steps: [analysis] steps = {steps}; a NaN also comes from a state "
    "outside the model's range (a folded element)",
    "other": "see the PETSc reason",
}


def reason_names():
    """{code: name} of PETSc's SNES reasons."""
    from petsc4py import PETSc

    return {v: k for k, v in vars(PETSc.SNES.ConvergedReason).items() if not k.startswith("_")}


def describe(reason):
    """'NAME (what it means)' of a PETSc reason name."""
    return f"{reason} ({REASONS[reason]})" if reason in REASONS else str(reason)


class AbsoluteTangent:
    """|K|·v for the round-off floor: a matrix of the tangent's pattern with its entries in
    absolute value (refilled from the tangent on each call)."""

    def __init__(self, A):
        self.B = A.duplicate(copy=False)
        self.v, self.out = A.createVecs()
        self._pattern = None  # (row pointers, columns) of B, as bytes

    def floor(self, A, x, sizes):
        """ε‖ |A| (|x| + sizes) ‖₂ (``sizes``: local owned array or None). Collective."""
        rows, cols, vals = A.getValuesCSR()
        # the same pattern: the same bytes (PETSc's index arrays, one dtype), compared without
        # np.array_equal's dispatch (4 µs of a 11 µs estimate)
        same = self._pattern is not None and self._pattern == (rows.tobytes(), cols.tobytes())
        comm = A.getComm()
        if comm.getSize() > 1:  # the copy is collective: every rank or none
            from mpi4py import MPI

            same = comm.tompi4py().allreduce(same, op=MPI.LAND)
        if not same:  # a new copy: the pattern may have grown (a coupling's entries added)
            self.B.destroy()
            self.B = A.duplicate(copy=True)
            self._pattern = (rows.tobytes(), cols.tobytes())
        self.B.setValuesCSR(rows, cols, np.abs(vals))
        self.B.assemble()
        eps = np.finfo(float).eps
        self.geometry = 0.0  # the part of the reference geometry alone: ε‖ |A| sizes ‖₂
        if sizes is not None:
            self.v.setArray(sizes)
            self.B.mult(self.v, self.out)
            self.geometry = float(eps * self.out.norm())
        state = np.abs(x.getArray(readonly=True))
        self.v.setArray(state if sizes is None else state + sizes)
        self.B.mult(self.v, self.out)
        return float(eps * self.out.norm())

    def destroy(self):
        """Free the PETSc objects."""
        for obj in (self.B, self.v, self.out):
            obj.destroy()


class ScaledTest:
    """The convergence test (module docstring) as a SNES convergence callback; one record per
    iteration in ``records``, and ``how`` the last solve converged ('residual', 'floor',
    'relative') or None."""

    def __init__(self, solver):
        self.solver = solver  # NewtonSolver: A, atol, rtol, force_scale, reactions, sizes
        self.absolute = AbsoluteTangent(solver.A)
        self.F_prev, self.Kx = solver.b.duplicate(), solver.b.duplicate()
        self.reset()

    def reset(self):
        """Forget the last solve (called before each)."""
        self.records, self.how = [], None
        self.first_energy, self.state_energy, self.floor = 0.0, None, None
        self.state_norm = None

    def __call__(self, snes, it, norms):
        """PETSc's reason after iteration ``it`` (norms: ‖x‖, ‖du‖, ‖F‖); ITERATING to go on."""
        from petsc4py import PETSc

        F = self.solver.b  # the SNES's residual vector (getFunction() costs a tuple a call)
        du = snes.getSolutionUpdate() if it > 0 else None
        how = self.check(it, norms, F, du, snes.getSolution())
        return getattr(PETSc.SNES.ConvergedReason, CODES[how])

    def check(self, it, norms, F, du, x):
        """The test after iteration ``it`` of any Newton loop (SNES's, the arc length's):
        'residual', 'floor' or 'relative' when converged (also set as ``how``), 'nan', or
        None to go on.

        Args:
            it: the iteration (0: the residual of the starting state).
            norms: (‖x‖, ‖du‖, ‖F‖) at this iteration.
            F: the residual vector at ``x`` (copied for the next energy criterion).
            du: the last correction (None at ``it`` 0).
            x: the state (the iterate).
        """
        xnorm, ynorm, fnorm = norms
        s = self.solver
        record = {"fnorm": fnorm, "step": ynorm, "state": xnorm, "energy": None, "floor": None}
        self.records.append(record)
        scale = max(s.force_scale, s.reactions)
        record["scale"] = scale
        tol = max(s.atol, RESIDUAL_TOL * scale)
        if it > 0:
            record["energy"] = abs(du.dot(self.F_prev))
            self.first_energy = max(self.first_energy or 0.0, record["energy"])
        F.copy(self.F_prev)
        if not np.isfinite(fnorm):
            return "nan"
        if fnorm <= tol:
            self.how = "residual"
            return self.how
        if it == 0:
            return None
        relative = s.rtol and fnorm <= s.rtol * self.records[0]["fnorm"]
        if relative and self.increment_small(record, x):
            self.how = "relative"
            return self.how
        if self.floor is None:  # once per solve: the tangent hardly changes at this stage
            self.floor = self.absolute.floor(s.A, x, s.sizes)
            self.geometry_floor = self.absolute.geometry
        record["floor"] = self.floor
        if fnorm > FLOOR_FACTOR * self.floor:
            return None
        if not (self._resolvable(fnorm, scale) or self._settled_in_range()):
            return None
        if not self.increment_small(record, x):
            return None
        self.how = "floor"
        return self.how

    def _resolvable(self, fnorm, scale):
        """Whether a residual at the floor may be accepted against the force scale: below
        FLOOR_LIMIT·S; or without any load (the reactions are round-off too); or when the
        floor is that of the model at its own reference geometry (a small load on a model
        with a stiff term: nothing resolves it better, and the settled increments say the
        state is exact to round-off), but not when a huge state raised it."""
        unloaded = self.solver.force_scale == 0.0 and scale <= FLOOR_FACTOR * self.floor
        geometric = self.geometry_floor >= 0.5 * self.floor
        return fnorm <= FLOOR_LIMIT * scale or unloaded or geometric

    def _settled_in_range(self):
        """Whether a residual at the floor but above FLOOR_LIMIT·S may still be accepted: the
        floor is the model's (its stiffness ratio: EA, GA ≫ EI/L² make eps·|K||x| exceed
        1e-5 of the load at a moderate state), not one a huge state raised (at most
        :data:`STATE_RANGE` times the reference geometry's), and Newton has stopped: its
        corrections no longer decrease (the last three within a factor 10). The increment
        and energy criteria are checked after (:meth:`increment_small`): the corrections
        are then within :data:`SETTLED_TOL` of the state, as for a floor of the reference
        geometry (:meth:`_resolvable`). The residual is the round-off of the internal
        forces, not an error of the state: the state is as exact as its corrections say.
        Corrections at 1e-12 of the state, as asked before, are not reached where the
        solve's own round-off moves the state more: the Pai beam at EA, GA × 1e6 on 32×P4
        elements, whose corrections stagnate near 1e-8 of its state as soon as its floor
        exceeds twice the reference geometry's."""
        if self.floor > STATE_RANGE * self.geometry_floor:
            return False
        steps = [r["step"] for r in self.records[1:]][-3:]
        return len(steps) == 3 and max(steps) <= 10 * min(steps)

    def linear(self, x, fnorm):
        """The test after one linear solve (``snes_type ksponly``): the residual criterion, or
        the floor without the increment criteria (the solve is exact but for round-off)."""
        s = self.solver
        scale = max(s.force_scale, s.reactions)
        self.records.append({"fnorm": fnorm, "step": 0.0, "state": 0.0, "scale": scale})
        self.floor = self.absolute.floor(s.A, x, s.sizes)
        if fnorm <= max(s.atol, RESIDUAL_TOL * scale):
            self.how = "residual"
        elif fnorm <= FLOOR_FACTOR * self.floor:
            self.how = "floor"

    def increment_small(self, record, x):
        """The increment criteria of the last iteration: ‖du‖ ≤ :meth:`allowed` and
        |du·F| ≤ ENERGY_TOL·E, E the larger of the solve's largest correction energy and the
        state's |x·Kx| (K the last tangent)."""
        if record["step"] > self.allowed(record, x):
            return False
        if self.state_energy is None:
            self.solver.A.mult(x, self.Kx)
            self.state_energy = abs(x.dot(self.Kx))
        # the energy resolvable at all: the floor's forces over the state's size (a state far
        # smaller than the reference geometry, e.g. the first arc-length step of a stiff model,
        # has |x·Kx| below it, and corrections at round-off then fail against |x·Kx|)
        resolvable = (self.floor or 0.0) * self.state_norm
        record["reference"] = max(self.first_energy, self.state_energy, resolvable)
        return record["energy"] <= ENERGY_TOL * record["reference"]

    def allowed(self, record, x):
        """The largest correction that counts as settled: INCREMENT_TOL·‖|x| + s‖, or, once
        the corrections stagnate (the last three within a factor 10: round-off moves the
        state, Newton no longer does), SETTLED_TOL·‖|x| + s‖. A penalty (EA, GA ≫ EI/L²)
        makes Newton converge slowly in the soft (bending) unknowns while the residual sits
        at the stiff terms' floor: a correction of 1e-6 of the state there still leaves an
        error of 1e-6, and the next ones shrink. Near a singular tangent (a limit or
        bifurcation point) round-off moves the state along the null vector by floor/μ at
        every iteration: the corrections stagnate. The state is measured with the sizes s
        of the floor estimate (the reference geometry), as the floor is."""
        if self.state_norm is None:
            self.state_norm = self.measure(x)
        record["state"] = self.state_norm
        steps = [r["step"] for r in self.records[1:]][-3:]
        settled = len(steps) == 3 and max(steps) <= 10 * min(steps)
        return (SETTLED_TOL if settled else INCREMENT_TOL) * self.state_norm

    def measure(self, x):
        """‖|x| + s‖₂ of the state ``x`` (s the solver's sizes; ‖x‖ without). Collective."""
        sizes = self.solver.sizes
        if sizes is None:
            return x.norm()
        local = np.abs(x.getArray(readonly=True)) + sizes
        return float(np.sqrt(x.getComm().tompi4py().allreduce(float(local @ local))))

    def destroy(self):
        """Free the PETSc objects."""
        self.absolute.destroy()
        self.F_prev.destroy()
        self.Kx.destroy()


def _stagnates(f):
    """The last three residuals within a factor 10 of one another (no Newton progress)."""
    tail = f[-3:]
    return len(tail) == 3 and max(tail) <= 10 * min(tail)


def diagnose(reason, records, floor):
    """(cause, detail) of a failed solve: the PETSc ``reason`` name, the test's per-iteration
    ``records`` and the round-off ``floor`` estimated at the last iterate."""
    f = [r["fnorm"] for r in records]
    if reason == "DIVERGED_FNORM_NAN" or not np.all(np.isfinite(f)):
        return "nan", "the residual is not finite"
    simple = {
        "DIVERGED_LINEAR_SOLVE": "linear solve",
        "DIVERGED_LINE_SEARCH": "line search",
        "DIVERGED_DTOL": "divergence",
    }
    if reason in simple:
        return simple[reason], describe(reason)
    if not f:
        return "other", describe(reason)
    last, least = f[-1], min(f)
    numbers = f"|F| from {f[0]:.3e} to {last:.3e} (least {least:.3e}), round-off floor {floor:.3e}"
    if len(f) > 1 and min(f[len(f) // 2 :]) > f[0]:
        return "divergence", f"the residual grew: {numbers}"
    scale = records[-1].get("scale", 0.0)
    if _stagnates(f) and last <= FLOOR_FACTOR * floor and last > FLOOR_LIMIT * scale:
        return "floor above the force scale", (
            f"{numbers}; the residual cannot be resolved below {last / scale:.1e} of the force "
            f"scale {scale:.3e} (needed: {FLOOR_LIMIT:g}): the state is outside what double "
            "precision resolves (huge stretches or rotations, or an extreme stiffness ratio)"
        )
    if _stagnates(f) and last <= FLOOR_FACTOR * floor:
        r = records[-1]
        step = r["step"] / r["state"] if r["state"] else np.inf
        return "stagnation at the floor", (
            f"{numbers}; the last increment |du|/|x| = {step:.2e} (criterion {INCREMENT_TOL:g}, "
            f"or {SETTLED_TOL:g} once the increments stagnate)"
        )
    if _stagnates(f):
        return "stagnation above the floor", numbers
    if reason == "DIVERGED_MAX_IT":
        return "max iterations", f"still converging: {numbers}"
    return "other", f"{describe(reason)}: {numbers}"


def remedy(cause, steps=None):
    """The remedy of a ``cause`` (REMEDIES), with a number of load steps to suggest if known."""
    text = REMEDIES.get(cause or "other", REMEDIES["other"])
    return text.format(steps=steps if steps else "<more than now>")
