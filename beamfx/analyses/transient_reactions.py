r"""Support reactions of a transient run as a time series, balanced with the applied loads and
the inertia forces.

**What balances.** The step's residual is F(q_{n+1}) = F_int − f(t_{n+1}) + I, with I the
inertia (and Rayleigh damping) forces, the Lagrange derivative of the kinetic energy
evaluated at the integrator's own rates q̇_{n+1}, q̈_{n+1}
(:class:`~beamfx.analyses.transient.Dynamics`). Newton zeroes it at the free dofs; at the held dofs it is the force that holds them,
the reaction r, as in statics (:mod:`beamfx.analyses.reactions`, whose per-point recovery is
reused). Summing every row by the discrete rigid motions (translations, and rotations about the
origin), under which the strain energy is invariant, gives

.. math:: Σ r + Σ f − Σ I = 0,

to Newton's tolerance and round-off. By Noether's theorem (the kinetic energy is invariant under
the same rigid motions, lifted to the rates) Σ I is the rate of the linear momentum and of the
angular momentum about the origin, d/dt (P, L) at (q_{n+1}, q̇_{n+1}, q̈_{n+1}), plus the
resultant of the mass-proportional damping force a0 M q̇ (the stiffness-proportional damping
is internal: its resultant is zero).

**At which time it holds.** The integrators are written in the form of Arnold & Brüls (2007)
(:mod:`beamfx.solvers.integrators`): the equations of motion hold exactly at t_{n+1} with the
physical acceleration q̈_{n+1}, while the α-weighting lives in the auxiliary acceleration a. So
the balance holds at t_{n+1}, with the loads at t_{n+1}, for generalized-α, HHT, Newmark and the
trapezoidal steps of "conserving" (before its projection); in the original Chung–Hulbert form
it would hold at the α-weighted times instead. The Richardson combination of "extrapolated" has
no residual of its own: no reactions are reported for it.

**When.** The reactions cost two vector assemblies (inertia and loads) and a few reductions, so
they are taken at the output steps only (the ParaView frames: ``output_every``, ``[output]
every``/``times``) and at the last step, or at every step if ``[output] reaction_rows =
"steps"`` asks; each is a row of ``reactions.csv`` appended as the run
goes (rank 0; the writer a static run uses too, :mod:`beamfx.io.reaction_files`), a frame of
``reactions.pvd`` beside the other frames of the step, and ``results.json`` keeps the last one
and the largest values over the run.
"""

import time
from typing import NamedTuple

import numpy as np

from ..io.reaction_files import ReactionCsv, columns
from ..physics.rotations import _norm  # np.linalg.norm's value, without its checks
from .dofs import constrained_dofs, owned_size
from .reactions import ReactionRecovery, imbalance

_now = time.perf_counter


class DynamicBalance(NamedTuple):
    """Σ reactions + Σ applied loads − Σ inertia forces, the forces and the moments about the
    origin, relative to Σ|nodal load| + Σ|nodal inertia force| (and Σ(|x||f| + |m|) of both)."""

    force: float
    moment: float
    applied_force: list
    applied_moment: list
    inertia_force: list
    inertia_moment: list
    free_residual: float  # ‖F‖ at the free dofs: Newton's stopping point, bounds the above


class TransientReactions:
    """Reactions and balance of a converged time step (``model.w`` = q_{n+1}, the state at
    t_n not yet moved on). Compiles the inertia forces' form once.

    Args:
        dyn: the :class:`~beamfx.analyses.transient.Dynamics`.
        residual: its residual form, compiled (the Newton solver's), assembled when Newton did
            not keep it.
        loads: ``dyn.loads`` compiled (the energy balance's), None without loads.
    """

    def __init__(self, dyn, residual, loads):
        from ..solvers.forms import compile_form

        self.model, self.residual = dyn.model, residual
        self.recovery = ReactionRecovery(dyn.model)
        self.inertia = compile_form(dyn.inertia_forces)
        self.loads = loads
        self.free = np.ones(owned_size(dyn.model.W), bool)  # owned, not held
        self.size = len(dyn.model.w.x.array)  # owned and ghost entries
        held = constrained_dofs(dyn.model.bcs)
        self.free[held[held < len(self.free)]] = False

    def __call__(self, residual=None):
        """``({point: Reaction}, DynamicBalance)``; ``residual``: the step's residual (owned
        entries, as assembled before the conditions), else assembled. Collective."""
        rec, model = self.recovery, self.model
        if residual is None:
            R = rec.assemble(self.residual)
        else:
            R = np.zeros(self.size)
            R[: len(residual)] = residual
        inertia = rec.assemble(self.inertia)
        if self.loads is None:
            reactions, total, [inert] = rec.at_points(R, [inertia])
            applied = np.zeros(8)
        else:
            reactions, total, [inert, applied] = rec.at_points(
                R, [inertia, rec.assemble(self.loads)]
            )
        free = R[: len(self.free)][self.free]
        squares = float(free @ free)
        free_residual = float(
            np.sqrt(model.comm.allreduce(squares) if model.comm.size > 1 else squares)
        )
        fa, ma, fi, mi = applied[:3], applied[3:6], inert[:3], inert[3:6]
        ratios = imbalance(
            total[:6] + applied[:6] - inert[:6],
            applied[6] + inert[6],
            applied[7] + inert[7],
            reactions,
            rec.length,
        )
        balance = DynamicBalance(
            *ratios,
            fa.tolist(),
            ma.tolist(),
            fi.tolist(),
            mi.tolist(),
            free_residual,
        )
        return reactions, balance


def _row(step, time, reactions, balance):
    row = [step, time]
    for r in reactions.values():
        row += [*r.force, *r.moment, *r.position]
    row += [*balance.applied_force, *balance.applied_moment]
    row += [*balance.inertia_force, *balance.inertia_moment]
    return row + [balance.force, balance.moment, balance.free_residual]


class Peaks:
    """The largest |force| and |moment| of each point and the largest balance residuals over
    the rows seen, with their times."""

    def __init__(self, points):
        self.points = {at: {"force": 0.0, "force_time": None, "moment": 0.0, "moment_time": None}
                       for at in points}  # fmt: skip
        self.balance = {"force": 0.0, "moment": 0.0}
        self.rows = 0

    def add(self, time, forces, moments, balance):
        """A row: ``forces``/``moments`` {point: 3-vector}, ``balance`` (force, moment)."""
        self.rows += 1
        for at, peak in self.points.items():
            for key, vec in (("force", forces[at]), ("moment", moments[at])):
                size = _norm(np.asarray(vec, float))
                if peak[f"{key}_time"] is None or size > peak[key]:
                    peak[key], peak[f"{key}_time"] = size, float(time)
        for key, value in zip(("force", "moment"), balance):
            self.balance[key] = max(self.balance[key], float(value))

    def add_csv_row(self, cells):
        """A row of ``reactions.csv`` read back (a restart)."""
        v = [float(c) for c in cells]
        forces = {at: v[2 + 9 * i : 5 + 9 * i] for i, at in enumerate(self.points)}
        moments = {at: v[5 + 9 * i : 8 + 9 * i] for i, at in enumerate(self.points)}
        self.add(v[1], forces, moments, v[-3:-1])


class ReactionSeries:
    """``reactions.csv``, one row per output step (rank 0, the file open for the run), and
    the summary of ``results.json``: the hook ``reactions`` of
    :func:`~beamfx.analyses.transient.solve_transient`.

    Args:
        folder: the output folder.
        comm: the run's communicator.
        want: ``want(step, time, last)``: whether the step is an output step (the frames').
        t_restart: the checkpoint's time on a restart: the rows after it are cut away, the
            peaks read back from those kept.
    """

    def __init__(self, folder, comm, want, t_restart=None):
        self.path, self.comm, self.want = folder / "reactions.csv", comm, want
        self.t_restart = t_restart
        self.csv = ReactionCsv(self.path, comm)
        self.compute = self.latest = None
        self.seconds = 0.0  # wall time of the output steps' reactions and rows

    def start(self, dyn, residual, loads):
        """Compile what the reactions need (``residual`` and ``loads``: the compiled forms of
        :class:`TransientReactions`); start (or cut back) the file. Collective."""
        self.compute = TransientReactions(dyn, residual, loads)
        points = list(self.compute.recovery.points)
        self.peaks = Peaks(points)
        for cells in self.csv.start(columns(points), self.t_restart):
            self.peaks.add_csv_row(cells)

    def __call__(self, step, time, last, residual):
        """The reactions of a converged step, if it is an output step. Collective."""
        if not self.want(step, time, last):
            return
        t0 = _now()
        reactions, balance = self.compute(residual)
        forces = {at: r.force for at, r in reactions.items()}
        moments = {at: r.moment for at, r in reactions.items()}
        self.peaks.add(time, forces, moments, (balance.force, balance.moment))
        self.latest = (step, time, reactions, balance)
        self.csv.write(_row(step, time, reactions, balance))
        self.seconds += _now() - t0

    def at_step(self, step):
        """``{point: {force, moment, position}}`` of output step ``step`` if its reactions
        were taken (the ParaView frame of the step), else None."""
        if self.latest is None or self.latest[0] != step:
            return None
        return {at: r._asdict() for at, r in self.latest[2].items()}

    def close(self):
        """Close the file (rank 0)."""
        self.csv.close()

    def entries(self):
        """``reactions`` and ``reaction_balance`` of ``results.json`` at the last output step
        (the shape of a static run's, the balance with the inertia forces and its largest
        residuals over the run); None before any."""
        if self.latest is None:
            return None
        step, time, reactions, balance = self.latest
        return {
            "reactions": {at: r._asdict() for at, r in reactions.items()},
            "reaction_balance": {
                **balance._asdict(),
                "time": time,
                "step": step,
                "max_force": self.peaks.balance["force"],
                "max_moment": self.peaks.balance["moment"],
            },
        }

    def summary(self):
        """The ``reaction_history`` entry of ``results.json``: the file, its rows, and the
        largest |force| and |moment| of each point over the run, with their times."""
        return {"csv": self.path.name, "rows": self.peaks.rows, "peaks": self.peaks.points}
