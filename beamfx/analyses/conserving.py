r"""The conserving scheme: trapezoidal steps projected back onto energy and momenta.

After each load-free, undamped step of the trapezoidal rule (generalized-α with ρ∞ = 1) the
velocities are projected, in the metric of the mass matrix M(q_{n+1}), onto the set where
the total energy and (for a free body) the linear and angular momentum keep their values
at t_n. With :math:`r_k(q)` the rigid-body velocity fields (translations along the axes,
rotations about the axes through the origin), the momenta are :math:`g_k = r_k^T M \dot q`
(Noether), so the projection is explicit:

.. math::
   \dot q_{n+1} = \sum_k c_k r_k + α\,(\tilde{\dot q} - \tilde{\dot q}_{rigid}),
   \qquad G c = g_n,\quad G_{kl} = r_k^T M r_l,

where :math:`\tilde{\dot q}_{rigid}` is the M-orthogonal projection of the trapezoidal
velocity on the rigid fields, and α scales the rest so that
:math:`T(\dot q_{n+1}) + Π(q_{n+1}) = H_n` (the two parts are M-orthogonal, so T splits).
The correction is of the size of the trapezoidal rule's local energy and momentum errors,
:math:`O(h^3)`, so the scheme stays second order; energy and momenta hold to round-off and
solver tolerance over any number of steps. It is the post-step form of the constraint
energy–momentum idea of Kuhl & Ramm (1996) and the standard projection of Hairer, Lubich &
Wanner (Geometric Numerical Integration, 2006, §IV.4).

Steps with loads, damping or moving supports are not projected (their energy balance is
what the run reports); a supported body keeps only its energy (its momenta are not
conserved).
"""

import numpy as np

from ..physics.kinematics import PLANES


class Projection:
    """Energy (and momentum) projection of the velocities after an accepted step.

    Args:
        dyn: the :class:`~beamfx.analyses.transient.Dynamics` (its ``v_n`` holds the
            trapezoidal velocity at t_{n+1} when :meth:`apply` is called).
        balance: the :class:`~beamfx.analyses.transient.EnergyBalance` (compiled T and Π).
    """

    def __init__(self, dyn, balance):
        from ..solvers.forms import compile_form
        from .modal import mass_ufl

        self.dyn, self.balance, m = dyn, balance, dyn.model
        spec = m.spec
        # momenta are conserved by a free body with finite (rotation-invariant) kinematics
        self.rigid = not (spec.supports or spec.springs) and m.kin.finite
        if self.rigid:
            import dolfinx.fem.petsc as fp

            self.M_form = compile_form(mass_ufl(m, dyn.settings.rotary_inertia))
            self.M = fp.create_matrix(self.M_form)
        self.applies = not (
            dyn.settings.damping_mass or dyn.settings.damping_stiffness
        ) and not any(s.timed for s in spec.supports)
        self.target = None  # (H_n, momenta g_n) of the last accepted state

    def _rigid_fields(self):
        """Arrays of the rigid-body velocity fields at the current q: translations along the
        (in-plane) axes, then rotations about the axes through the origin."""
        d, kin = self.dyn, self.dyn.model.kin
        w, ud, rd = d.model.w.x.array, d.u_dofs, d.r_dofs
        axes = PLANES[kin.plane][:2] if kin.plane else (0, 1, 2)
        x = d.u_points.copy()  # current positions of the displacement nodes
        for c, a in enumerate(axes):
            x[:, a] += w[ud[:, c]]
        fields = []
        for c in range(len(axes)):
            f = np.zeros_like(w)
            f[ud[:, c]] = 1.0
            fields.append(f)
        for k in [PLANES[kin.plane][2]] if kin.plane else [0, 1, 2]:
            e = np.eye(3)[k]
            f = np.zeros_like(w)
            v = np.cross(e, x)
            for c, a in enumerate(axes):
                f[ud[:, c]] = v[:, a]
            if kin.plane:
                f[rd[:, 0]] = 1.0
            else:  # q̇ = ½ (0, e) ∘ q: the spatial angular velocity e
                q = w[rd]
                f[rd[:, 0]] = -0.5 * q[:, 1:] @ e
                f[rd[:, 1:]] = 0.5 * (q[:, :1] * e + np.cross(e, q[:, 1:]))
            fields.append(f)
        return fields

    def _operators(self):
        """At the current q: the rigid fields r_k, M r_k and the Gram matrix G = rᵀ M r
        (None for a body whose momenta are not conserved). Collective."""
        import dolfinx.fem.petsc as fp

        if not self.rigid:
            return None
        M = self.M
        M.zeroEntries()
        fp.assemble_matrix(M, self.M_form)
        M.assemble()
        r = []
        for f in self._rigid_fields():
            rk = M.createVecRight()
            rk.array[:] = f[: len(rk.array)]
            r.append(rk)
        Mr = [M.createVecLeft() for _ in r]
        for rk, Mrk in zip(r, Mr):
            M.mult(rk, Mrk)
        G = np.array([[Mrk.dot(rl) for rl in r] for Mrk in Mr])
        return r, Mr, G

    def _momenta(self, operators):
        """g_k = (M r_k)ᵀ q̇ at the current velocities, or None."""
        if operators is None:
            return None
        return np.array([Mrk.dot(self.dyn.v_n.vector) for Mrk in operators[1]])

    def _load_free(self, t):
        """Whether no load acts at time t (every load has a history that is zero there)."""
        m = self.dyn.model
        if m.work is None:
            return True
        loads = (*m.spec.point_loads, *m.spec.distributed_loads)
        return not any(m.spec.gravity) and all(
            ld.history is not None and float(ld.history(t)) == 0.0 for ld in loads
        )

    def apply(self, t_n, t):
        """Project the velocities at t_{n+1} = ``t`` if no load acted at t_n or t_{n+1};
        then remember the state's energy and momenta as the next target."""
        from petsc4py import PETSc

        b = self.balance
        operators = self._operators()  # q is not changed by the projection: assembled once
        Pi = b.scalar(b.Pi)
        if self.applies and self._load_free(t_n) and self._load_free(t):
            H0, g0 = self.target
            v = self.dyn.v_n.vector
            T_rigid = 0.0
            if operators is not None:
                r, _, G = operators
                c_now, c_new = np.linalg.solve(G, self._momenta(operators)), np.linalg.solve(G, g0)
                for ck, rk in zip(c_now, r):
                    v.axpy(-ck, rk)  # the flexible part
                T_rigid = 0.5 * c_new @ G @ c_new
            v.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
            T_flex = b.scalar(b.T)
            room = H0 - Pi - T_rigid
            alpha = np.sqrt(room / T_flex) if room > 0 and T_flex > 1e-14 * abs(H0) else 1.0
            v.scale(alpha)
            if operators is not None:
                for ck, rk in zip(c_new, r):
                    v.axpy(ck, rk)
            v.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        self._remember(operators, Pi)

    def remember(self):
        """Take the current state's energy and momenta as the target (start, restart)."""
        self._remember(self._operators(), self.balance.scalar(self.balance.Pi))

    def _remember(self, operators, Pi):
        """The target from the current velocities (energy and momenta measured, not assumed,
        so round-off does not accumulate unseen)."""
        self.target = (self.balance.scalar(self.balance.T) + Pi, self._momenta(operators))
        for vec in (*operators[0], *operators[1]) if operators is not None else ():
            vec.destroy()
