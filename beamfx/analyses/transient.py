r"""Transient dynamics: the Lagrange equations of the beam stepped in time.

The kinetic energy :func:`~beamfx.physics.inertia.kinetic_energy` is written in the unknowns
(u, q) and their rates, and the inertia forces are its Lagrange derivative,

.. math:: δq \cdot \Big(\frac{d}{dt}\frac{∂T}{∂\dot q} - \frac{∂T}{∂q}\Big)
   = \frac{∂p}{∂\dot q}[\ddot q] + \frac{∂p}{∂q}[\dot q] - \frac{∂T}{∂q}[δq],
   \qquad p = \frac{∂T}{∂\dot q}[δq],

built with ``ufl.derivative`` on placeholder rate fields that the integrator
(:mod:`beamfx.solvers.integrators`) then replaces by its expressions of the unknown
:math:`q_{n+1}`. Gyroscopic and centrifugal terms come out of the derivatives, consistent with
the quaternion parametrisation, and the Jacobian is exact.

Energy bookkeeping, every step: kinetic T, strain Π, work of loads and of prescribed support
motion (trapezoidal rule on force · increment, reactions from the residual), Rayleigh
dissipation; what is left is the integrator's numerical dissipation.
"""

import time
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import ufl

from ..physics import coupled
from ..physics.inertia import angular_velocity, point_kinetic_energy
from ..physics.kinematics import displacement
from ..solvers import NewtonSolver
from ..solvers.integrators import AlphaStep, generalized_alpha, hht, newmark
from ..solvers.snes import SolveFailed
from ..solvers.step_control import EasyGrowth, ErrorBased, StepControl, StepTooSmall
from .checks import model_size
from .conserving import Projection
from .dofs import constrained_dofs, owned_size, subspace_dofs
from .extrapolation import Extrapolation
from .section_fields import section_kinetic_energy
from .strain_rates import StrainHistory, bdf2_weights

SCHEMES = ("generalized_alpha", "hht", "newmark", "conserving", "extrapolated")
CHECKPOINT_STEPS = 50  # the default checkpoints: every this many steps,
CHECKPOINT_SECONDS = 10.0  # and this much wall time after the last one (or the start)


@dataclass(frozen=True)
class TransientSettings:
    """What ``[analysis] type = "transient"`` says (see docs/scenes.md)."""

    t_end: float
    dt: float
    scheme: str = "generalized_alpha"
    rho_inf: float = 0.9  # generalized-α (and the base of "extrapolated")
    hht_alpha: float = 0.05  # HHT
    dt_min: float | None = None  # smallest step after cut-backs (default dt/1000)
    easy_iterations: int = 4  # a step in at most this many iterations may grow the next one
    tolerance: float | None = None  # local error per step, relative (None: iteration control)
    damping_mass: float = 0.0  # Rayleigh a0 (1/s): force a0 M q̇
    damping_stiffness: float = 0.0  # Rayleigh a1 (s): viscous stress a1 C ε̇
    rotary_inertia: str = "full"
    output_every: int = 1  # ParaView frames every n steps (probes and energies every step)
    # steps between checkpoints (0: never); None: every CHECKPOINT_STEPS steps, at most one per
    # CHECKPOINT_SECONDS of wall time (each costs a file written and flushed to disk)
    checkpoint_every: int | None = None

    def __post_init__(self):
        if self.scheme == "extrapolated" and self.tolerance is not None:
            raise ValueError('scheme "extrapolated" steps on a fixed grid: no tolerance')

    def parameters(self):
        """The :class:`~beamfx.solvers.integrators.AlphaParameters` of ``scheme``."""
        if self.scheme == "hht":
            return hht(self.hht_alpha)
        if self.scheme == "newmark":
            return newmark()
        if self.scheme == "conserving":  # trapezoidal steps, then projected (conserving.py)
            return generalized_alpha(1.0)._replace(name="conserving (trapezoidal + projection)")
        if self.scheme == "extrapolated":  # runs at h and h/2 combined (extrapolation.py)
            base = generalized_alpha(self.rho_inf)
            return base._replace(name=f"extrapolated (Richardson h, h/2) {base.name}")
        return generalized_alpha(self.rho_inf)


class StepRecord(NamedTuple):
    """An accepted time step: its size, Newton iterations, cut-backs and energies."""

    step: int
    time: float
    dt: float
    iterations: int
    residuals: tuple
    cutbacks: int
    energy: dict  # kinetic, strain, work_loads, work_supports, dissipated_damping, numerical


class TransientResult(NamedTuple):
    """The accepted time steps of a transient run and why it ended."""

    steps: tuple  # StepRecord of accepted steps (all of them)
    newton_iterations: int
    seconds: dict
    stopped_by: str  # "t_end" or the reason of a failure


class TransientFailed(SolveFailed):
    """A time step that Newton could not take even at the smallest step size."""


class Dynamics:
    """Residual and Jacobian of one time step, and the energy forms, for a :class:`BeamModel`.

    The state at t_n lives in Functions (``q_n``, ``v_n``, ``a_n``, ``qdd_n``); the step
    size ``h`` is a constant, so changing it recompiles nothing.
    """

    def __init__(self, model, settings):
        from dolfinx import fem
        from petsc4py import PETSc

        self.model, self.settings = model, settings
        W, w, kin, d = model.W, model.w, model.kin, model.discretisation
        self.q_n, self.v_n, self.a_n, self.qdd_n = (fem.Function(W) for _ in range(4))
        # views of the Functions' values (fixed memory), looked up once: each ``.x.array``
        # costs a microsecond, and a step asks for them a dozen times
        self.w_values = w.x.array
        self.state_values = tuple(f.x.array for f in (self.q_n, self.v_n, self.a_n, self.qdd_n))
        # dofs per node: displacement (with the nodes' reference positions) and rotation
        V_u, u_dofs = W.sub(0).collapse()
        self.u_dofs = np.asarray(u_dofs).reshape(-1, kin.displacement_size)
        self.u_points = V_u.tabulate_dof_coordinates()
        self.extrapolation = None  # the scheme "extrapolated"'s copies (set by its march)
        self.r_dofs = subspace_dofs(W, 1).reshape(-1, kin.rotation_size)
        self._is_displacement = np.zeros(len(self.q_n.x.array), bool)
        self._is_displacement[self.u_dofs.ravel()] = True
        self._quaternion = kin.finite and not kin.plane
        self.project_rates = self._quaternion  # see _tangent_rates (and extrapolation.py)
        mesh = model.mesh.mesh

        def constant(x):
            return fem.Constant(mesh, PETSc.ScalarType(x))

        params = settings.parameters()
        self.h = constant(settings.dt)
        self._h_storage = self.h.value  # the view Constant.value returns: see set_step
        self.scheme = AlphaStep(params, self.h, params._replace(**{
            k: constant(getattr(params, k)) for k in ("alpha_m", "alpha_f", "beta", "gamma")
        }))  # fmt: skip
        a0, a1 = constant(settings.damping_mass), constant(settings.damping_stiffness)
        V, A = fem.Function(W), fem.Function(W)  # placeholders of q̇ and q̈
        test = ufl.TestFunction(W)

        def T_of(q, v):
            (_, rot), (u_dot, rot_dot) = ufl.split(q), ufl.split(v)
            T = section_kinetic_energy(kin, rot, u_dot, rot_dot, d, settings.rotary_inertia)
            u_dot3, omega = displacement(kin, u_dot), angular_velocity(kin, rot, rot_dot)
            return T * d.dx + d.point_mass_terms(
                lambda pm: point_kinetic_energy(kin, rot, u_dot3, omega, pm.mass, pm.inertia)
            )

        T = T_of(w, V)
        p = ufl.derivative(T, V, test)
        inertia = ufl.derivative(p, V, A) + ufl.derivative(p, w, V) - ufl.derivative(T, w, test)
        power = 0  # dissipated power of the Rayleigh damping, as a form of V
        if settings.damping_mass:
            inertia += a0 * p
            power += a0 * 2 * T
        v_expr, qdd_expr = self.scheme.rates(w, self.q_n, self.v_n, self.a_n, self.qdd_n)
        # the inertia (and damping) forces of the step: their resultant is the rate of the
        # momenta at t_{n+1} (transient_reactions.py)
        self.inertia_forces = ufl.replace(inertia, {V: v_expr, A: qdd_expr})
        self.strain_history = None
        if settings.damping_stiffness:  # viscous stresses a1 C ε̇ on objective rates
            sh = self.strain_history = StrainHistory(model, self.h)
            c0 = bdf2_weights(self.h, sh.h_prev, sh.second)[0]  # ∂ε̇/∂ε_{n+1}
            D = d.strain_energy(*sh.rate(), scale=a1 / c0, dx=sh.dx)
            self.inertia_forces += ufl.derivative(D, w, test)  # a1 C ε̇ · δε
            stored = self.strain_history.stored_rate()
            power += 2 * d.strain_energy(*stored, scale=a1, dx=self.strain_history.dx)
        self.F = model.F + self.inertia_forces
        self.J = ufl.derivative(self.F, w, ufl.TrialFunction(W))
        # energies at the state (w, v_n): evaluated after v_n holds the new velocity
        self.kinetic = ufl.replace(T, {V: self.v_n})
        # of a free body only (nothing holds it): supported, they are not conserved anyway
        free = not (model.spec.supports or model.spec.springs)
        self.momenta = self._momenta(settings.rotary_inertia) if free else []
        self.power = ufl.replace(power, {V: self.v_n}) if power != 0 else None
        self.loads = model.load_factor * model.work if model.work is not None else None

    def _momenta(self, rotary):
        """Linear and angular momentum (about the origin), global axes: ∫ ρA u̇ ds and
        ∫ x × ρA u̇ + Λ J Λᵀ ω ds, plus the point masses' m u̇ and x × m u̇ + R J0 Rᵀ ω;
        conserved by a free body under no load."""
        from ..physics.inertia import angular_velocity, point_inertia, spatial_inertia
        from ..physics.kinematics import displacement

        m, kin, d = self.model, self.model.kin, self.model.discretisation
        (u, rot), (u_dot, rot_dot) = ufl.split(m.w), ufl.split(self.v_n)
        velocity = displacement(kin, u_dot)
        x = ufl.SpatialCoordinate(m.mesh.mesh) + displacement(kin, u)
        omega = angular_velocity(kin, rot, rot_dot)
        p = d.inertia[0] * velocity
        L = ufl.cross(x, p)
        if d.matrices is not None:  # ∂T/∂u̇ and ∂T/∂ω of the offset mass: + ω × s, + s × u̇
            s = coupled.first_moment(kin, rot, d.Lam0, d.matrices.M)
            p += ufl.cross(omega, s)
            L = ufl.cross(x, p) + ufl.cross(s, velocity)
            L += coupled.spatial_rotary(kin, rot, d.Lam0, d.matrices.M) * omega
        elif rotary != "none":
            J = spatial_inertia(kin, rot, d.Lam0, [d.inertia[i] for i in (1, 2, 3)], rotary)
            L += J * omega

        def point_p(pm):
            return float(pm.mass) * velocity

        def point_L(pm):
            return ufl.cross(x, point_p(pm)) + point_inertia(kin, rot, pm.inertia) * omega

        return [
            p[i] * d.dx + d.point_mass_terms(lambda pm, i=i: point_p(pm)[i]) for i in range(3)
        ] + [L[i] * d.dx + d.point_mass_terms(lambda pm, i=i: point_L(pm)[i]) for i in range(3)]

    def start(self):
        """State at t = 0 from the model's current unknowns, at rest (q̇ = q̈ = a = 0)."""
        self.q_n.x.array[:] = self.model.w.x.array
        for f in (self.v_n, self.a_n, self.qdd_n):
            f.x.array[:] = 0.0
        if self.strain_history:
            self.strain_history.start()

    def set_step(self, h):
        """The step size constant ``h``, written into its storage (what ``self.h.value = h``
        does, without its copy dispatch) only when it changed: most steps keep the last."""
        if self._h_storage != h:
            self._h_storage[...] = h

    def predict(self, h):
        """Newton's starting point: the step with unchanged acceleration, and the prescribed
        values of the supports at t_{n+1} (a mismatch there would start Newton from a state
        with a sudden strain at the support)."""
        q_n, v_n, a_n, _ = self.state_values
        self.w_values[:] = self.scheme.predict(q_n, v_n, a_n, h)
        _set_bc(self.w_values, self.model.bcs, None, 1.0)  # fem.set_bc's call, no wrapper

    def accept(self, h):
        """Move the converged q_{n+1} (in the model's unknowns) into the state at t_n."""
        q_n, v_n, a_n, qdd_n = self.state_values
        v_n[:], a_n[:], qdd_n[:] = self.scheme.advance(self.w_values, *self.state_values, h)
        if self.strain_history:
            self.strain_history.accept(h)
        q_n[:] = self.w_values
        if self.project_rates:
            self._tangent_rates()

    def _tangent_rates(self):
        r"""Quaternion rates consistent with |q| = 1: q̇·q = 0 and q̈·q = −|q̇|² at each node.
        The norm direction has no mass; an integrator without numerical damping (ρ∞ = 1,
        Newmark) would let its meaningless rates grow from step to step until Newton fails
        (measured: the 3D flying spaghetti at t ≈ 27 s), so they are removed."""
        q = self.q_n.x.array[self.r_dofs]
        qq = np.sum(q * q, axis=1, keepdims=True)
        v = self.v_n.x.array[self.r_dofs]
        v -= np.sum(q * v, axis=1, keepdims=True) / qq * q
        self.v_n.x.array[self.r_dofs] = v
        vv = np.sum(v * v, axis=1, keepdims=True)
        for f in (self.a_n, self.qdd_n):
            a = f.x.array[self.r_dofs]
            f.x.array[self.r_dofs] = a - (np.sum(q * a, axis=1, keepdims=True) + vv) / qq * q

    def error_estimate(self, h, tolerance, length):
        r"""Local error of the step just converged, in units of the tolerance (≤ 1: accept).

        The Zienkiewicz–Xie estimate :math:`e = h^2 |β - 1/6|\,(\ddot q_{n+1} - \ddot q_n)`,
        the leading term of the Taylor series that the Newmark relations truncate, per dof
        scaled by ``tolerance``·(|q_{n+1}| + ``length``) for displacements and
        ``tolerance``·(|q_{n+1}| + 1) for rotations; root mean square over the owned dofs.
        """
        q = self.model.w.x.array
        arrays = [f.x.array for f in (self.q_n, self.v_n, self.a_n, self.qdd_n)]
        _, _, qdd = self.scheme.advance(q, *arrays, h)
        e = h**2 * abs(self.scheme.p.beta - 1 / 6) * (qdd - self.qdd_n.x.array)
        scale = tolerance * (np.abs(q) + np.where(self._is_displacement, length, 1.0))
        n = owned_size(self.model.W)
        comm = self.model.comm
        total = comm.allreduce(float(np.sum((e[:n] / scale[:n]) ** 2)))
        return np.sqrt(total / comm.allreduce(n))

    def state(self):
        """Copies of the time-stepping state (q, v, a, q̈ at t_n), for a checkpoint."""
        arrays = {k: getattr(self, k).x.array.copy() for k in ("q_n", "v_n", "a_n", "qdd_n")}
        return arrays | (self.strain_history.state() if self.strain_history else {})

    def set_state(self, arrays):
        """Restore the time-stepping state saved by :meth:`state`; the model's unknowns follow q."""
        for k in ("q_n", "v_n", "a_n", "qdd_n"):
            getattr(self, k).x.array[:] = arrays[k]
        self.model.w.x.array[:] = self.q_n.x.array
        if self.strain_history:
            self.strain_history.set_state(arrays)


def _set_bc(*args):
    """``dolfinx.cpp.fem.set_bc(*args)`` (the same call), its import made once."""
    from dolfinx.cpp.fem import set_bc

    global _set_bc
    _set_bc = set_bc
    return set_bc(*args)


def _assemble_scalar(form):
    """``dolfinx.fem.assemble_scalar(form)`` (the same call), its import made once."""
    from dolfinx import fem

    global _assemble_scalar
    _assemble_scalar = fem.assemble_scalar
    return fem.assemble_scalar(form)


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
        if self.previous is not None:
            n = self.n_owned
            dq = np.subtract(self.dyn.w_values[:n], q_old[:n], out=self._dq)
            prev, mean = self.previous, self._mean

            def trapezoid(key):
                np.add(prev[key], now[key], out=mean)
                return self._sum(float(np.dot(np.multiply(0.5, mean, out=mean), dq)))

            if self.f_loads is not None:
                self.values["work_loads"] += trapezoid("loads")
            if self.moving:
                self.values["work_supports"] += trapezoid("reaction")
            for (g0, f0), (g1, f1) in zip(prev.get("penalty") or [], now["penalty"]):
                self.values["work_supports"] += 0.5 * (g0 + g1) * (f1 - f0)
            self.values["dissipated_damping"] += 0.5 * (prev["power"] + now["power"]) * h
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

    def get(self):
        """The energy accounts, for a checkpoint."""
        return {"values": dict(self.values), "initial": self.initial, "previous": self.previous}

    def set(self, saved):
        """Restore the energy accounts saved by :meth:`get`."""
        self.values, self.initial, self.previous = (
            dict(saved["values"]),
            saved["initial"],
            saved["previous"],
        )


def control_state(control):
    """The step controller's state: the next step size and the growth policy's counters."""
    from dataclasses import fields

    growth = control.growth
    private = {f.name: getattr(growth, f.name) for f in fields(growth) if f.name.startswith("_")}
    return {"size": float(control.size), "growth": type(growth).__name__, "state": private}


def restore_control(control, state):
    """Put a saved :func:`control_state` back into ``control`` (same policy)."""
    control.size = float(state["size"])
    if state.get("growth") == type(control.growth).__name__:
        for k, v in state.get("state", {}).items():
            if k.startswith("_") and hasattr(control.growth, k):
                setattr(control.growth, k, v)


def checkpoint_state(dyn, balance, control, t, step):
    """(header, arrays) of the state to go on from ``t``: the state at t_n, the energy
    balance, the step controller (see :mod:`beamfx.io.checkpoint` for the file)."""
    arrays = dyn.state()
    if dyn.extrapolation:
        arrays |= dyn.extrapolation.arrays()
    previous = balance.previous or {}
    saved = {"values": dict(balance.values), "initial": balance.initial}
    saved["power"] = previous.get("power")
    saved["penalty"] = previous.get("penalty")
    for key in ("loads", "reaction"):
        value = previous.get(key)
        if isinstance(value, np.ndarray):
            arrays[f"balance_{key}"], value = value, "array"
        saved[key] = value
    header = {"t": float(t), "step": int(step), "size": float(control.size)}
    return {**header, "controller": control_state(control), "balance": saved}, arrays


def restore_state(saved, dyn, balance, control):
    """Put a checkpoint's (header, arrays) back: state, energy balance and step controller;
    returns (t, step)."""
    header, arrays = saved
    dyn.set_state(arrays)
    if dyn.extrapolation:
        dyn.extrapolation.restore(arrays)
    b = header["balance"]
    previous = None
    if b["power"] is not None:
        previous = {"power": b["power"], "penalty": b.get("penalty")}
        for key in ("loads", "reaction"):
            value = b.get(key)
            previous[key] = arrays[f"balance_{key}"] if value == "array" else (value or 0.0)
    balance.set({"values": b["values"], "initial": b["initial"], "previous": previous})
    restore_control(control, header["controller"])
    return header["t"], header["step"]


def _begin(saved, dyn, balance, control, on_step, log):
    """(t, step) to march from: the checkpoint ``saved``, else t = 0 at rest (recorded)."""
    model = dyn.model
    if saved is not None:
        t, step = restore_state(saved, dyn, balance, control)
        model.set_time(t)
        log(f"restart from the checkpoint at t = {t:.6g} (step {step})")
        return t, step
    model.set_time(0.0)
    dyn.start()
    balance.reactions()
    record = StepRecord(0, 0.0, 0.0, 0, (), 0, balance.record(None, 0.0))
    if on_step:
        on_step(record)
    return 0.0, 0


class _March(NamedTuple):
    """What every step of a march uses."""

    model: object
    settings: TransientSettings
    dyn: Dynamics
    solver: NewtonSolver
    balance: EnergyBalance
    projection: object  # the conserving scheme's Projection, or None
    dt_min: float
    length: float  # the scale of the displacements, for the error estimate
    log: object
    reactions: object = None  # called at each converged step (transient_reactions.py)


def _step(m, control, t, failed):
    """Newton from ``t`` at the control's step size, cut back until a step is accepted:
    (h, the size wanted before the end time shortened it, report, cut-backs, error estimate or
    None); ``model.w`` then holds q_{n+1}.

    Raises:
        TransientFailed: below the smallest step size, after ``failed()`` (the checkpoint).
    """
    s, model, dyn = m.settings, m.model, m.dyn
    wanted = control.size  # kept if only the end time shortens this step
    h = control.size = min(wanted, s.t_end - t)
    cutbacks, tried, error = 0, [], None
    while True:
        report = _newton(m, t, h)
        if report.converged and s.tolerance:
            error = dyn.error_estimate(h, s.tolerance, m.length)
            if error <= 1.0 or h <= m.dt_min * (1 + 1e-9):
                return h, wanted, report, cutbacks, error
            reason_ = f"local error {error:.3g} x tolerance"
            tried.append((h, reason_, report.residuals))
            model.w.x.array[:] = dyn.q_n.x.array
            h, cutbacks = control.rejected(error), cutbacks + 1
            continue
        if report.converged:
            return h, wanted, report, cutbacks, error
        tried.append((h, report.reason, report.residuals))
        model.w.x.array[:] = dyn.q_n.x.array
        cutbacks += 1
        try:
            h = control.rejected()
        except StepTooSmall:
            failed()
            raise TransientFailed(_failure(t, m.dt_min, tried)) from None
        m.log(f"  t = {t:.6g}: {report.reason} with dt = {2 * h:.3g}; retrying with {h:.3g}")


def _newton(m, t, h):
    """The Newton solve(s) of the step from ``t`` to t + h: ``model.w`` then holds q_{n+1}."""
    dyn = m.dyn
    if dyn.extrapolation:
        return dyn.extrapolation.solve(t, h)
    dyn.set_step(h)
    m.model.set_time(t + h)
    dyn.predict(h)
    return m.solver.solve()


def _accept(m, t, h, q_old, step):
    """Move the state on from ``t`` to t + h (step ``step``) after a converged step (``q_old``
    gets q_n); returns the energy balance at t + h. The support reactions are taken before
    the state moves on: the residual's rates are expressions of the state at t_n."""
    q_old[:] = m.dyn.state_values[0]  # q_n
    if m.dyn.extrapolation:
        m.dyn.extrapolation.accept()
    else:
        residual = m.solver.residual_at_solution()
        m.balance.reactions(residual)
        if m.reactions is not None:
            m.reactions(step, t + h, t + h >= m.settings.t_end * (1 - 1e-12), residual)
        m.dyn.accept(h)
    if m.projection:
        m.projection.apply(t, t + h)
    return m.balance.record(q_old, h)


def _march(model, s, options, prefix, log, reactions=None):
    """The :class:`_March` of ``model`` with ``settings`` ``s``, and the forms' compile time."""
    from ..solvers.forms import compile_seconds

    c0 = compile_seconds[0]
    dyn = Dynamics(model, s)
    solver = NewtonSolver(dyn.F, dyn.J, model.w, model.bcs, prefix, options)
    solver.set_atol(max(1e-14 * float(model.k_penalty.value), 1e-14))
    balance = EnergyBalance(dyn, solver.F)
    if balance.moving or reactions:  # the reactions of each step from Newton's last residual
        solver.keep_residual()
    if reactions and s.scheme != "extrapolated":  # (a combination has no residual of its own)
        reactions.start(dyn, solver.F, balance.f_loads)
    else:
        reactions = None
    projection = Projection(dyn, balance) if s.scheme == "conserving" else None
    if s.scheme == "extrapolated":
        dyn.extrapolation = Extrapolation(dyn, solver, balance)
    dt_min = s.dt_min or s.dt / 1000
    length = model_size(model.spec)
    quiet = log or (lambda _: None)
    m = _March(model, s, dyn, solver, balance, projection, dt_min, length, quiet, reactions)
    return m, compile_seconds[0] - c0


def solve_transient(
    model,
    settings,
    on_step=None,
    log=None,
    progress=None,
    options=None,
    checkpoint=None,
    saved=None,
    prefix="beamfx_transient_",
    reactions=None,
):
    """March from t = 0 (at rest in the model's current state) to ``settings.t_end``.

    Each step is one Newton solve (SNES) for q_{n+1}. A step that fails is retried with half
    the step size down to ``dt_min``; after ``easy_iterations`` or fewer the step grows by 1.5
    up to ``dt``; with ``settings.tolerance`` the local error estimate
    (:meth:`Dynamics.error_estimate`) rejects and sizes the steps instead.
    ``on_step(record)`` is called after every accepted step (and at t = 0 with step 0), so
    output is written as the run goes. ``checkpoint(header, arrays)`` is called every
    ``checkpoint_every`` steps (:func:`checkpoint_due`), at the end, before a failure is
    raised and when the march is interrupted (:mod:`beamfx.interrupt`: a SIGINT or SIGTERM
    stops it at an accepted step, ``stopped_by`` then names the signal), with
    :func:`checkpoint_state`; pass such a state as ``saved`` to go on from it.
    ``reactions``: its ``start(dyn, residual, loads)`` once, then ``reactions(step, t, last,
    residual)`` at every converged step before the state moves on
    (:class:`~beamfx.analyses.transient_reactions.ReactionSeries`; not with "extrapolated").

    Raises:
        TransientFailed: naming the time, the step size and the residual history, after the
            last good state was checkpointed.
    """
    from ..interrupt import pending, reason

    t_start, s = time.perf_counter(), settings
    m, compile_time = _march(model, s, options, prefix, log, reactions)
    dyn, balance, solver = m.dyn, m.balance, m.solver
    growth = ErrorBased() if s.tolerance else EasyGrowth(1.5, s.easy_iterations, 2, clean=True)
    control = StepControl(s.dt, s.dt, m.dt_min, growth)

    def save(t, step):
        if checkpoint:
            checkpoint(*checkpoint_state(dyn, balance, control, t, step))

    model.set_load_factor(1.0)
    t, step = _begin(saved, dyn, balance, control, on_step, m.log)
    if m.projection:
        m.projection.remember()
    records, iterations, stopped_by = [], 0, "t_end"
    saved_at = [time.perf_counter()]  # wall time of the last checkpoint (or of the start)
    q_old = model.w.x.array.copy()
    while t < s.t_end * (1 - 1e-12):
        h, wanted, report, cutbacks, error = _step(
            m, control, t, lambda t=t, step=step: save(t, step)
        )
        energy = _accept(m, t, h, q_old, step + 1)
        t, step, iterations = t + h, step + 1, iterations + report.iterations
        record = StepRecord(step, t, h, report.iterations, report.residuals, cutbacks, energy)
        records.append(record)
        if on_step:
            on_step(record)
        if progress:
            progress(record)
        if not cutbacks and h < wanted:
            control.size = wanted
        control.accepted(report.iterations, cutbacks, error)
        signum = pending(model.comm)
        if signum:
            stopped_by = reason(signum)
            break
        if checkpoint_due(s.checkpoint_every, step, saved_at, model.comm):
            save(t, step)
            saved_at[0] = time.perf_counter()
    save(t, step)
    seconds = {"compile": compile_time, **solver.seconds, "total": time.perf_counter() - t_start}
    solver.destroy()
    return TransientResult(tuple(records), iterations, seconds, stopped_by)


def checkpoint_due(every, step, saved_at, comm):
    """Whether accepted step ``step`` gets a checkpoint: every ``every`` steps (0: never); by
    default (None) every :data:`CHECKPOINT_STEPS` steps once :data:`CHECKPOINT_SECONDS` of
    wall time have passed since ``saved_at[0]`` (rank 0's clock decides: collective then).
    A short run then writes its checkpoint at the end only, a long one loses at most about
    that much work to a killed process."""
    if every is not None:
        return bool(every) and step % every == 0
    if step % CHECKPOINT_STEPS:
        return False
    due = time.perf_counter() - saved_at[0] >= CHECKPOINT_SECONDS
    return comm.bcast(due) if comm.size > 1 else due


def _failure(t, dt_min, tried):
    """The message of a step that failed at every size: each try and its residuals."""
    lines = [
        f"  dt = {dt:.3g}: {why}, residuals {', '.join(f'{r:.3e}' for r in res)}"
        for dt, why, res in tried
    ]
    return (
        f"time step from t = {t:.6g} failed at every step size down to "
        f"dt_min = {dt_min:.3g}:\n" + "\n".join(lines)
    )
