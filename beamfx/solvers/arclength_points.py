r"""Critical points of arc-length continuation (:mod:`.arclength`): the inertia of each
converged state, the location of the points a step passed, branch switching and the rules that
redo a step which converged onto another branch.

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
"""

import time

import numpy as np

from .arclength_types import _StepFailed
from .bifurcation import locate, smallest_eigenpair
from .inertia import negative_pivots
from .snes import SolveFailed

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


class _CriticalPoints:
    """The stability checks of :class:`~.arclength.ArcLengthSolver` (a mixin: the solver's
    constructor sets the attributes these methods read)."""

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
