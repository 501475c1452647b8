"""Energy bookkeeping of a transient run, every step.

Kinetic T, strain Π, work of loads and of prescribed support motion (trapezoidal rule on
force · increment, reactions from the residual), Rayleigh dissipation; what is left is the
integrator's numerical dissipation.
"""

import numpy as np

from .dofs import constrained_dofs, owned_size


def _assemble_scalar(form):
    """``dolfinx.fem.assemble_scalar(form)`` (the same call), its import made once."""
    from dolfinx import fem

    global _assemble_scalar
    _assemble_scalar = fem.assemble_scalar
    return fem.assemble_scalar(form)


#: the ``note`` of results.json's ``energy`` when loads jump at t = 0 (:func:`sudden_loads`)
JUMP_NOTE = (
    "loads jump at t = 0 (the run starts at rest, zero acceleration): the first step's "
    "trapezoidal work is not the true work; numerical includes the difference"
)


def _at_start(history, t_end, samples=101):
    """Whether a load history is non-zero at t = 0 (None: the constant 1): |f(0)| above
    1e-9 of its largest |f| over [0, ``t_end``] (a smooth ramp's round-off is not a jump)."""
    if history is None:
        return True
    values = np.abs(np.asarray(history(np.linspace(0.0, t_end, samples)), float))
    return bool(values[0] > 1e-9 * values.max(initial=0.0))


def sudden_loads(spec, t_end, start="rest"):
    """The loads of ``spec`` (a :class:`~beamfx.spec.Model`) that act at t = 0 on a
    transient's start at rest: point and distributed loads whose history is non-zero there
    (none: constant), and gravity; none after a static start (its state balances them).
    The time integrators start with zero acceleration, so for them such a load jumps on
    during the first step, and the trapezoidal work ½ (f(0) + f(h))·Δq of that step is not
    the work it did (twice it for a constant load, but with "extrapolated":
    :func:`jump_line`): the balance's ``numerical`` share holds the difference. Returns
    their descriptions, e.g. ``["the point load at 'b:end'"]``."""
    if start == "static":
        return []
    out = []
    for ld in spec.point_loads:
        if (any(ld.force) or any(ld.moment)) and _at_start(ld.history, t_end):
            out.append(f"the point load at {ld.at!r}")
    for dl in spec.distributed_loads:
        if (any(dl.force) or any(dl.moment)) and _at_start(dl.history, t_end):
            where = "all beams" if dl.beam is None else repr(dl.beam)
            out.append(f"the distributed load on {where}")
    if any(spec.gravity):
        out.append("gravity")
    return out


def jump_line(loads, scheme):
    """The log line of :func:`sudden_loads` (``loads``: their descriptions) for the time
    integrator ``scheme``. Measured on a cantilever under a constant tip force: the first
    step's "numerical" is half its trapezoidal work with "generalized_alpha", "hht",
    "newmark" and "conserving"; "extrapolated" (two copies combined) books no such share in
    its first step, but its h² expansion assumes loads that start smoothly."""
    share = (
        "the extrapolation's error expansion assumes loads that start smoothly"
        if scheme == "extrapolated"
        else "about half that step's load work for a constant load"
    )
    return (
        f"note: {', '.join(loads)} act(s) from t = 0 on a state at rest: the integrator "
        "starts with zero acceleration, as if the load jumped on during the first step, "
        "while the trapezoidal work ½ (f(0) + f(h))·Δq counts it from t = 0: the first "
        f"step's work is not the true work and the energy balance's 'numerical' includes the "
        f'difference ({share}; a history rising from 0, or start = "static", avoids it)'
    )


class EnergyBalance:
    """Kinetic and strain energy, work of loads and supports, and dissipation, step by step.

    Works are trapezoidal sums of (force at t_n + force at t_{n+1})/2 · Δq over the dofs;
    the supports' forces are the reactions (the residual without boundary conditions, on
    the constrained dofs), assembled only if a support moves (else they do no work).

    Args:
        dyn: the :class:`Dynamics`.
        residual: its residual ``dyn.F``, compiled (the Newton solver's).
    """

    def __init__(self, dyn, residual):
        import dolfinx.fem.petsc as fp

        from ..solvers.forms import compile_form

        self.dyn, m = dyn, dyn.model
        self.T = compile_form(dyn.kinetic)
        self.Pi = compile_form(m.Pi)
        self.P = compile_form(dyn.power) if dyn.power is not None else None
        self.f_loads = compile_form(dyn.loads) if dyn.loads is not None else None
        self.momenta = [compile_form(f) for f in dyn.momenta]
        self.residual = residual
        self.moving = any(s.timed for s in m.spec.supports)
        # supports in local axes: penalties whose target moves with f(t); their work is
        # ∫ ∂Π/∂f df (trapezoidal), the rest of the support work is reaction · Δq
        self.penalty_motion = [(compile_form(g), c) for g, c in m.penalty_motion]
        self.vec = fp.create_vector(self.residual)
        self.n_owned = owned_size(m.W)
        mask = np.zeros(len(m.w.x.array), bool)
        mask[constrained_dofs(m.bcs)] = True
        self.mask = mask[: self.n_owned]  # constrained, owned dofs (as _vector's rows)
        self._reactions = (np.zeros(self.n_owned), np.zeros(self.n_owned))
        self._dq, self._mean = np.zeros(self.n_owned), np.zeros(self.n_owned)
        self._w_owned = dyn.w_values[: self.n_owned]  # a view of the unknowns, kept
        self.reaction = None
        self.values = dict.fromkeys(("work_loads", "work_supports", "dissipated_damping"), 0.0)
        self.previous = self.initial = None
        comm = m.comm  # sums over the ranks (none to make on one: a few µs a step saved)
        self._sum = comm.allreduce if comm.size > 1 else (lambda x: x)

    def scalar(self, form):
        """Value of a compiled scalar form (e.g. ``T``, ``Pi``) over all ranks. Collective."""
        return self._sum(_assemble_scalar(form))

    def _vector(self, form):
        import dolfinx.fem.petsc as fp
        from petsc4py import PETSc

        with self.vec.localForm() as b:
            b.set(0.0)
        fp.assemble_vector(self.vec, form)
        self.vec.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        return self.vec.array_r[: self.n_owned].copy()

    def reactions(self, residual=None):
        """Support reactions at the converged q_{n+1}: call before the state moves on (the
        residual's rates are expressions of the state at t_n). ``residual``: F there (owned
        entries), if the Newton solver kept it (else it is assembled)."""
        if not self.moving:
            self.reaction = 0.0
            return
        F = self._vector(self.residual) if residual is None else residual
        # F·mask into the one of two arrays that the previous step's reaction is not
        out = self._reactions[0] if self._reactions[0] is not self.reaction else self._reactions[1]
        self.reaction = np.multiply(F, self.mask, out=out)

    def record(self, q_old, h):
        """Energies at the accepted state; ``q_old`` the unknowns at t_n (None at t = 0).
        The works' sums run in arrays made once (the same operations as ``0.5 * (f_n +
        f_{n+1})·(q - q_old)``, so the same numbers)."""
        now = {
            "loads": self._vector(self.f_loads) if self.f_loads is not None else 0.0,
            "reaction": self.reaction,
            "power": self.scalar(self.P) if self.P is not None else 0.0,
            "penalty": [[self.scalar(g), float(c.value)] for g, c in self.penalty_motion],
        }
        prev, values = self.previous, self.values
        if prev is not None:
            if self.f_loads is not None or self.moving:  # Δq, owned entries
                np.subtract(self._w_owned, q_old[: self.n_owned], out=self._dq)
            if self.f_loads is not None:
                values["work_loads"] += self._trapezoid(prev["loads"], now["loads"])
            if self.moving:
                values["work_supports"] += self._trapezoid(prev["reaction"], now["reaction"])
            for (g0, f0), (g1, f1) in zip(prev.get("penalty") or [], now["penalty"]):
                values["work_supports"] += 0.5 * (g0 + g1) * (f1 - f0)
            values["dissipated_damping"] += 0.5 * (prev["power"] + now["power"]) * h
        self.previous = now
        out = {"kinetic": self.scalar(self.T), "strain": self.scalar(self.Pi), **self.values}
        if self.momenta:
            momenta = [self.scalar(f) for f in self.momenta]
            out["linear_momentum"], out["angular_momentum"] = momenta[:3], momenta[3:]
        if self.initial is None:
            self.initial = out["kinetic"] + out["strain"]
        out["numerical"] = (
            out["work_loads"]
            + out["work_supports"]
            - out["dissipated_damping"]
            - (out["kinetic"] + out["strain"] - self.initial)
        )
        return out

    def _trapezoid(self, before, after):
        """0.5 (``before`` + ``after``) · Δq summed over the ranks, in the arrays made once."""
        mean = np.add(before, after, out=self._mean)
        return self._sum(float(np.dot(np.multiply(0.5, mean, out=mean), self._dq)))

    def set(self, saved):
        """Restore the energy accounts: ``values``, ``initial`` and ``previous`` of a checkpoint
        (:func:`~beamfx.analyses.transient_checkpoint.restore_state`)."""
        self.values, self.initial, self.previous = (
            dict(saved["values"]),
            saved["initial"],
            saved["previous"],
        )
