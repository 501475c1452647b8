r"""Richardson extrapolation in time: the scheme ``"extrapolated"``.

Two copies of the march run in lockstep on one grid of macro steps H: the *coarse* copy takes
one step H, the *fine* copy two steps H/2, each from its own state and with the base scheme
(generalized-α with the scene's ρ∞; ρ∞ = 1 is the trapezoidal rule). Neither copy is fed
from the other, so each is exactly as stable as the base scheme (a *local* extrapolation,
which restarts both from the combined state, would amplify the unresolved stiff modes, where
the trapezoidal rule's factor is −1, by 4/3 + 1/3 = 5/3 a step). What is shown at every
t_{n+1}: the unknowns, their rates and the support reactions, hence the probes, the frames
and the energy balance, is the combination (:func:`~beamfx.solvers.integrators.richardson`)

.. math:: q = q_{H/2} + \frac{q_{H/2} - q_H}{3},

which removes the h² term of the global error :math:`e_2(t) h^2 + e_3(t) h^3 + e_4(t) h^4`.
The trapezoidal rule (ρ∞ = 1) is symmetric, so e_3 = 0 and the result is fourth order; with
ρ∞ < 1 the numerical damping leaves an h³ term proportional to its dissipation, and the
result is third order with a small constant (both measured in docs/validation).

Quaternion fields (3D): the projection of the rates onto the unit sphere that the other
schemes make after every step (:meth:`~beamfx.analyses.transient.Dynamics._tangent_rates`)
is not smooth in h: with it the error of a 3D cantilever stalls near 1e-5 (h = T/80 and
T/160 equally), without it the order is 4. It is there for ρ∞ = 1, whose meaningless rates
along the quaternion's norm would grow; with ρ∞ < 1 they are damped, so the copies skip it
(ρ∞ = 1 in 3D keeps it, and with it the stall).

The energy balance (:class:`~beamfx.analyses.transient.EnergyBalance`) sums the works
over the shown steps by the trapezoidal rule, second order; its remainder ("numerical") is
then mostly that quadrature error, of either sign.

Cost: three Newton solves per macro step (one at H, two at H/2), i.e. the two runs at H and
H/2 that a user would make to check convergence, with the better answer as a by-product.
It needs smooth data: the h² expansion holds for loads and support motions that are smooth
in time and start with zero acceleration (the run starts at rest, q̈ = 0).
"""

from ..solvers.integrators import richardson
from .dynamics import STATE_NAMES
from .predictor import STATE_KEYS


class Extrapolation:
    """The coarse and fine copies of the state at t_n, stepped together.

    Args:
        dyn: the :class:`~beamfx.analyses.transient.Dynamics`; its own state is the one
            shown (the combination), the copies live here.
        solver: its Newton solver.
        balance: its :class:`~beamfx.analyses.transient.EnergyBalance` (for the reactions).
    """

    COPIES = ("coarse", "fine")

    def __init__(self, dyn, solver, balance):
        self.dyn, self.solver, self.balance = dyn, solver, balance
        self.copies = None  # {"coarse": state, "fine": state} at t_n (None: the shown one)
        self._new = None  # what :meth:`accept` makes of the step just solved
        if dyn.settings.rho_inf < 1.0:
            dyn.project_rates = False  # damped: the projection is not needed, and costs order

    def _substep(self, t, h, start=None):
        """Newton for the step from ``t`` to t + h of the state the Dynamics holds, from
        ``start`` (unknowns at t + h) if given, else from the Dynamics' predictor."""
        dyn = self.dyn
        dyn.set_step(h)
        dyn.model.set_time(t + h)
        dyn.predict(h)
        if start is not None:
            dyn.model.w.x.array[:] = start
        return self.solver.solve()

    def _march(self, name, t, h, n, start=None):
        """``n`` steps of h/n of the copy ``name`` (Newton's last one from ``start``, if
        given): (reports, its state at t + h and the reactions there), the state None if a
        step failed."""
        self.dyn.set_state(self.copies[name])
        reports, reaction = [], 0.0
        for i in range(n):
            reports.append(self._substep(t + i * h / n, h / n, start if i == n - 1 else None))
            if not reports[-1].converged:
                return reports, None, None
            if i == n - 1:  # from Newton's last residual where it kept it (the same numbers)
                self.balance.reactions(self.solver.residual_at_solution())
                reaction = self.balance.reaction
            self.dyn.accept(h / n)
        return reports, self.dyn.state(), reaction

    def solve(self, t, h):
        """Step both copies from ``t`` to t + h; the model's unknowns then hold the combined
        q_{n+1} and the Dynamics the shown state at t_n again. Returns one report: converged
        if all three solves did, with their iterations and residuals."""
        dyn = self.dyn
        shown = dyn.state()
        if self.copies is None:
            self.copies = {k: {a: v.copy() for a, v in shown.items()} for k in self.COPIES}
        # the fine copy first: its q(t + h) starts the coarse step's Newton. The copies differ
        # by their errors in time, where the predictor (a Taylor polynomial in the inertial
        # frame) is off by about (Ωh)³ r/6 on a part turning at Ω (a spin-up's 10 m beam at
        # Ω·h = 0.6: 0.36 m, and Newton diverged)
        reports, fine, r_fine = self._march("fine", t, h, 2)
        coarse = None
        if fine is not None:
            more, coarse, r_coarse = self._march("coarse", t, h, 1, fine["q_n"])
            reports += more
        dyn.set_state(shown)
        if coarse is not None:
            # the copies' predictor histories are their own (every step starts from a copy):
            # not combined, the shown state has none
            both = {k: richardson(coarse[k], fine[k]) for k in fine if k not in STATE_KEYS}
            self._new = {"coarse": coarse, "fine": fine}, both, richardson(r_coarse, r_fine)
            dyn.model.w.x.array[:] = both["q_n"]
            dyn.set_step(h)
        last = reports[-1]
        return last._replace(
            converged=coarse is not None,
            iterations=sum(r.iterations for r in reports),
            residuals=tuple(x for r in reports for x in r.residuals),
        )

    def accept(self):
        """Move both copies and the shown state on to t_{n+1} (after :meth:`solve`)."""
        self.copies, both, reaction = self._new
        self.balance.reaction = reaction
        self.dyn.set_state(both)
        self._new = None

    def arrays(self):
        """The copies' states, for a checkpoint (names ``coarse_q_n``, ``fine_v_n``, ...)."""
        if self.copies is None:
            return {}
        return {f"{c}_{k}": a for c, s in self.copies.items() for k, a in s.items()}

    def restore(self, arrays):
        """The copies from a checkpoint's ``arrays`` (none saved: both start from the shown
        state, a restart that perturbs the h² term once).

        Every array saved of a copy (:meth:`arrays`) comes back: its q, q̇, a, q̈, the
        predictor's history (:mod:`.predictor`; an older checkpoint without it: order 0
        once) and, with stiffness damping, its strain history (:mod:`.strain_rates`: ε_n,
        ε_{n−1}, ε̇_n and the last step). Without the latter each copy restarted its strain
        rates from the shown state's combined strains by a backward difference: the first
        step after a restart was off by 5e-8 and the restart no longer bit-identical."""
        names = [f"{c}_{k}" for c in self.COPIES for k in STATE_NAMES]
        if not all(n in arrays for n in names):
            self.copies = None
            return
        self.copies = {c: _copy_arrays(arrays, f"{c}_") for c in self.COPIES}


def _copy_arrays(arrays, prefix):
    """``{name: copy}`` of the ``arrays`` whose name starts with ``prefix`` (taken off)."""
    return {k[len(prefix) :]: a.copy() for k, a in arrays.items() if k.startswith(prefix)}
