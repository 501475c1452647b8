r"""The integrator's state of a transient run: the Lagrange equations of the beam in one step.

The kinetic energy :func:`~beamfx.physics.inertia.kinetic_energy` is written in the unknowns
(u, q) and their rates, and the inertia forces are its Lagrange derivative,

.. math:: δq \cdot \Big(\frac{d}{dt}\frac{∂T}{∂\dot q} - \frac{∂T}{∂q}\Big)
   = \frac{∂p}{∂\dot q}[\ddot q] + \frac{∂p}{∂q}[\dot q] - \frac{∂T}{∂q}[δq],
   \qquad p = \frac{∂T}{∂\dot q}[δq],

built with ``ufl.derivative`` on placeholder rate fields that the integrator
(:mod:`beamfx.solvers.integrators`) then replaces by its expressions of the unknown
:math:`q_{n+1}`. Gyroscopic and centrifugal terms come out of the derivatives, consistent with
the quaternion parametrisation, and the Jacobian is exact.

The march that steps it is :func:`beamfx.analyses.transient.solve_transient`.
"""

import numpy as np
import ufl

from ..physics import coupled
from ..physics.inertia import angular_velocity, point_kinetic_energy
from ..physics.kinematics import displacement
from ..solvers.integrators import AlphaStep
from .dofs import owned_size, subspace_dofs
from .predictor import AccelerationTrend
from .section_fields import section_kinetic_energy
from .strain_rates import StrainHistory, bdf2_weights

#: the names of the time-stepping state in :meth:`Dynamics.state` (and a checkpoint), in the
#: order of ``Dynamics.state_values``
STATE_NAMES = ("q_n", "v_n", "a_n", "qdd_n")


def _trend(settings, size, owned, comm):
    """The accelerations' history for Newton's starting point (:mod:`.predictor`), for the
    Richardson scheme's copies only (None: the start with unchanged acceleration). The plain
    generalized-α spin-up at dt = 0.025 (Ω·dt = 0.15, ρ∞ = 0.9) sits at a slowly growing
    instability of the scheme that Newton's error at its tolerance seeds; the extrapolated
    start saves one iteration there, leaves that error larger (still within the tolerance)
    and the 2 x P2 run then fails at t = 17.3 s (with the old start it runs through)."""
    if settings.scheme != "extrapolated":
        return None
    return AccelerationTrend(size, owned, comm)


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
        # work arrays of predict and accept, made once (no arrays made per step)
        self._work = tuple(np.empty_like(self.w_values) for _ in range(4))
        self.trend = _trend(settings, len(self.w_values), owned_size(W), model.comm)
        # dofs per node: displacement (with the nodes' reference positions) and rotation
        V_u, u_dofs = W.sub(0).collapse()
        self.u_dofs = np.asarray(u_dofs).reshape(-1, kin.displacement_size)
        self.u_points = V_u.tabulate_dof_coordinates()
        self.extrapolation = None  # the scheme "extrapolated"'s copies (set by its march)
        self.r_dofs = subspace_dofs(W, 1).reshape(-1, kin.rotation_size)
        self._is_displacement = np.isin(np.arange(len(self.w_values)), self.u_dofs)
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
        if self.trend:
            self.trend.reset()
        if self.strain_history:
            self.strain_history.start()

    def set_step(self, h):
        """The step size constant ``h``, written into its storage (what ``self.h.value = h``
        does, without its copy dispatch) only when it changed: most steps keep the last."""
        if self._h_storage != h:
            self._h_storage[...] = h

    def predict(self, h):
        """Newton's starting point: the generalized-α update of q with the acceleration
        extrapolated from the last steps (:mod:`~beamfx.analyses.predictor`; the scheme
        "extrapolated" only, see ``trend``; else and at the start: unchanged acceleration),
        and the prescribed values of the supports at t_{n+1} (a mismatch there would start
        Newton from a state with a sudden strain at the support)."""
        q_n, v_n, a_n, _ = self.state_values
        w, tmp = self.w_values, self._work[0]
        # AlphaStep.predict in place (the same operations): q_n + h v_n + (h² ½) a_n
        np.add(q_n, np.multiply(h, v_n, out=tmp), out=w)
        np.add(w, np.multiply(h**2 * 0.5, a_n, out=tmp), out=w)
        if self.trend:
            self.trend.add_to(w, self.scheme.p.beta, h, tmp)  # + β h² (ã_{n+1} - a_n)
        _set_bc(w, self.model.bcs, None, 1.0)  # fem.set_bc's call, no wrapper

    def accept(self, h):
        """Move the converged q_{n+1} (in the model's unknowns) into the state at t_n, and
        its acceleration into the predictor's history."""
        a_n, a_old = self.state_values[2], self._work[3]
        if self.trend:
            a_old[:] = a_n
        _advance_in_place(self.scheme.p, h, self.w_values, self.state_values, self._work[:3])
        if self.strain_history:
            self.strain_history.accept(h)
        self.state_values[0][:] = self.w_values  # q_n
        if self.project_rates:
            self._tangent_rates()
        if self.trend:
            self.trend.accept(a_n, a_old, h)

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
        q = self.w_values
        _, _, qdd = self.scheme.advance(q, *self.state_values, h)
        e = h**2 * abs(self.scheme.p.beta - 1 / 6) * (qdd - self.state_values[3])
        scale = tolerance * (np.abs(q) + np.where(self._is_displacement, length, 1.0))
        n = owned_size(self.model.W)
        comm = self.model.comm
        total = comm.allreduce(float(np.sum((e[:n] / scale[:n]) ** 2)))
        return np.sqrt(total / comm.allreduce(n))

    def state(self):
        """Copies of the time-stepping state (q, v, a, q̈ at t_n and the predictor's history),
        for a checkpoint."""
        arrays = {k: a.copy() for k, a in zip(STATE_NAMES, self.state_values)}
        if self.trend:
            arrays |= self.trend.state()
        return arrays | (self.strain_history.state() if self.strain_history else {})

    def set_state(self, arrays):
        """Restore the time-stepping state saved by :meth:`state`; the model's unknowns follow
        q (without the predictor's history, an older checkpoint's next step starts Newton
        with unchanged acceleration)."""
        for k, a in zip(STATE_NAMES, self.state_values):  # (the Functions' arrays, kept)
            a[:] = arrays[k]
        if self.trend:
            self.trend.set_state(arrays)
        self.w_values[:] = self.state_values[0]
        if self.strain_history:
            self.strain_history.set_state(arrays)


def _advance_in_place(p, h, q, state, work):
    """:meth:`AlphaStep.advance <beamfx.solvers.integrators.AlphaStep.advance>` of the
    converged q_{n+1} = ``q`` with parameters ``p``, written into the ``state`` arrays (q_n,
    v_n, a_n, q̈_n; q_n is left alone) through the three ``work`` arrays: the same
    floating-point operations in the same order (so the same numbers, bit for bit), with no
    array made (a step made sixteen)."""
    _, v_n, a_n, qdd_n = state
    a, tmp, tmp2 = work
    # a = (q - q_n - h v_n - (h² (½ - β)) a_n) / (β h²)
    np.subtract(q, state[0], out=a)
    np.subtract(a, np.multiply(h, v_n, out=tmp), out=a)
    np.subtract(a, np.multiply(h**2 * (0.5 - p.beta), a_n, out=tmp), out=a)
    np.divide(a, p.beta * h**2, out=a)
    # q̈ = ((1 - α_m) a + α_m a_n - α_f q̈_n) / (1 - α_f), before a_n and q̈_n move on
    np.add(np.multiply(1 - p.alpha_m, a, out=tmp), np.multiply(p.alpha_m, a_n, out=tmp2), out=tmp)
    np.subtract(tmp, np.multiply(p.alpha_f, qdd_n, out=tmp2), out=tmp)
    np.divide(tmp, 1 - p.alpha_f, out=qdd_n)
    # v = v_n + (h (1 - γ)) a_n + (h γ) a
    np.add(v_n, np.multiply(h * (1 - p.gamma), a_n, out=tmp), out=v_n)
    np.add(v_n, np.multiply(h * p.gamma, a, out=tmp), out=v_n)
    a_n[:] = a


def _set_bc(*args):
    """``dolfinx.cpp.fem.set_bc(*args)`` (the same call), its import made once."""
    from dolfinx.cpp.fem import set_bc

    global _set_bc
    _set_bc = set_bc
    return set_bc(*args)
