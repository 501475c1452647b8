r"""Objective strain rates for stiffness-proportional damping: the strains differentiated in
time at the quadrature points.

The viscous stresses a1 C ε̇ must vanish in any rigid motion, a steady spin included. The
directional derivative ∂ε/∂q [q̇] with the integrator's rates q̇ does not: generalized-α
rates are linear combinations of past states, and those of a rotating displacement field
(frequency ω) and of its quaternions (frequency ω/2) are too fast by different factors,
about 1 + (ωh)²/12 and 1 + (ωh)²/48 in a steady spin. Their mismatch is a shear rate
≈ (ωh)²/16 · ω in a steadily spinning beam, which the damping turns into a drag and a
dissipation that never ends (measured: 3.3 W at a1 = 0.05 s, 2 Hz, h = 10 ms, the Pai
strip, 4 × P3). The strains ε = (Γ, K) (section axes) are objective at every time level,
so a difference quotient of them vanishes whenever they stay constant. Here the two-step
backward difference (BDF2, variable step; ω = h/h_prev):

.. math:: \dot ε_{n+1} = \frac{1}{h}\Big(\frac{1 + 2ω}{1 + ω} ε_{n+1} − (1 + ω) ε_n
   + \frac{ω^2}{1 + ω} ε_{n-1}\Big),

second order, and a plain filter of the strains: it carries no state of its own that could
drift (the integrator's relations applied to the strains do: their parasitic root near
−ρ∞ grew in a spinning strip at ρ∞ = 0.9). The first step (no ε_{n−1}) is a backward
difference. ε_n, ε_{n−1} and ε̇_n (for the dissipated power) live in a quadrature space of the
degree of ``dx_shear`` (2p − 1, which integrates the bending part exactly on straight
elements too); the damping forms use that measure for both parts.
"""

import numpy as np
import ufl

#: names of the stored fields (state of a checkpoint); ``strain_steps``: (h_prev, 1 if ε_{n−1})
FIELDS = ("strain_n", "strain_nm1", "strain_rate_n")


def strain_vector(model):
    """(Γ, K) of the model's unknowns as one 6-vector (section axes)."""
    Gamma, K = model.strains
    return ufl.as_vector([Gamma[i] for i in range(3)] + [K[i] for i in range(3)])


def bdf2_weights(h, h_prev, second):
    """Weights (c0, c1, c2) of ε_{n+1}, ε_n, ε_{n−1} in ε̇_{n+1}; a backward difference if not
    ``second``. Numbers or UFL expressions (``second`` then 1 or 0)."""
    r = h / h_prev
    c0 = (1 + 2 * r) / (1 + r) / h
    c2 = r**2 / (1 + r) / h
    return second * c0 + (1 - second) / h, -(second * (c0 + c2) + (1 - second) / h), second * c2


class StrainHistory:
    """ε_n, ε_{n−1}, ε̇_n at the quadrature points of ``dx_shear``.

    Args:
        model: the :class:`~beamfx.analyses.model.BeamModel`.
        h: the step size (a constant that the march sets before each Newton solve).
    """

    def __init__(self, model, h):
        from dolfinx import fem
        from petsc4py import PETSc

        d, mesh = model.discretisation, model.mesh.mesh
        degree = d.dx_shear.metadata()["quadrature_degree"]
        element = ufl.VectorElement(
            "Quadrature", mesh.ufl_cell(), degree, dim=6, quad_scheme="default"
        )
        self.Q = fem.FunctionSpace(mesh, element)
        self.model, self.h = model, h
        self.fields = {k: fem.Function(self.Q) for k in FIELDS}
        self.h_prev = fem.Constant(mesh, PETSc.ScalarType(1.0))
        self.second = fem.Constant(mesh, PETSc.ScalarType(0.0))
        points = _quadrature_points(degree)
        self._strain = fem.Expression(strain_vector(model), points)
        index = _dof_index(self.Q, len(points))
        self._cells, self._index = np.arange(len(index), dtype=np.int32), index.ravel()
        self.dx = d.dx_shear

    def rate(self):
        """ε̇_{n+1} as a UFL expression of the model's unknowns q_{n+1}, as (Γ̇, K̇)."""
        f = self.fields
        c0, c1, c2 = bdf2_weights(self.h, self.h_prev, self.second)
        return _split(c0 * strain_vector(self.model) + c1 * f["strain_n"] + c2 * f["strain_nm1"])

    def stored_rate(self):
        """ε̇_n (after :meth:`accept`: at the new time), as (Γ̇, K̇)."""
        return _split(self.fields["strain_rate_n"])

    def _strain_now(self):
        """ε of the model's current unknowns at the quadrature points (local cells, ghosts
        included), as an array in the layout of a Function of ``Q``."""
        values = self._strain.eval(self._cells)
        out = np.zeros_like(self.fields["strain_n"].x.array)
        out[self._index] = values.ravel()
        return out

    def start(self):
        """At rest in the current state: ε_0 from the unknowns, no earlier level."""
        self.fields["strain_n"].x.array[:] = self._strain_now()
        self.fields["strain_rate_n"].x.array[:] = 0.0
        self.second.value = 0.0

    def accept(self, h):
        """Move the strains of the converged q_{n+1} (the model's unknowns) into ε_n."""
        f = {k: self.fields[k].x.array for k in FIELDS}
        c0, c1, c2 = bdf2_weights(h, float(self.h_prev.value), float(self.second.value))
        s = self._strain_now()
        f["strain_rate_n"][:] = c0 * s + c1 * f["strain_n"] + c2 * f["strain_nm1"]
        f["strain_nm1"][:] = f["strain_n"]
        f["strain_n"][:] = s
        self.h_prev.value, self.second.value = h, 1.0

    def state(self):
        """Copies of the stored fields and steps (for a checkpoint)."""
        out = {k: f.x.array.copy() for k, f in self.fields.items()}
        out["strain_steps"] = np.array([float(self.h_prev.value), float(self.second.value)])
        return out

    def set_state(self, arrays):
        """Restore :meth:`state`; without it (an older checkpoint) ε_n from the unknowns and
        a backward difference for the next step."""
        if not all(k in arrays for k in FIELDS + ("strain_steps",)):
            self.start()
            return
        for k in FIELDS:
            self.fields[k].x.array[:] = arrays[k]
        self.h_prev.value, self.second.value = (float(x) for x in arrays["strain_steps"])


def _split(v):
    return ufl.as_vector([v[i] for i in range(3)]), ufl.as_vector([v[i] for i in range(3, 6)])


def _quadrature_points(degree):
    """The reference points of FFCx's "default" rule of ``degree`` on the interval."""
    import basix

    points, _ = basix.make_quadrature(basix.CellType.interval, degree)
    return points


def _dof_index(Q, n_points):
    """(local cells, points × 6) array positions of each cell's values in a Function of Q."""
    bs = Q.dofmap.index_map_bs
    imap = Q.mesh.topology.index_map(Q.mesh.topology.dim)
    n_cells = imap.size_local + imap.num_ghosts
    dofs = Q.dofmap.list.array.reshape(n_cells, n_points).astype(np.int64)
    return (bs * dofs[:, :, None] + np.arange(bs)).reshape(n_cells, n_points * bs)
