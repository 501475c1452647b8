r"""The planar statically condensed beam: the in-plane angle θ(s) is the only unknown.

A cantilever under point loads that is also a plane problem
(:func:`~beamfx.analyses.trimming.choose_plane` and
:func:`~beamfx.analyses.trimming.condensed_fit` both hold) turns about the plane's normal n
only: R(θ) = exp(θ n̂) (:func:`~beamfx.physics.condensed.plane_rotation`). The strains are
eliminated from the known section force exactly as in the spatial condensed model
(:mod:`beamfx.analyses.condensed`), Γ = C_N⁻¹ Λ0ᵀ Rᵀ n, with shear and stretch kept (or
dropped with ``[model] shear``/``stretch`` false), so one scalar per node is left, and the
angle has no range limit: any number of turns.

The curvature K = Λ0ᵀ n θ' is linear in θ. Under a pure end moment (n = 0) the energy is
½ EI θ'² − M θ(L), whose Galerkin solution on P_k is the exact θ = M s/EI for every k ≥ 1:
one P1 element rolls a beam up into any number of turns. The centre line
x' = R(θ)(t_s + Λ0 Γ) is then integrated cell by cell in closed form (:func:`chord_increments`)
where θ is linear in a cell (P1, straight cells, sections constant in the cell), so the
roll-up is exact to round-off; otherwise by composite Gauss quadrature with the cell split
until θ turns by at most :data:`SUBINTERVAL_ANGLE` in a part: in NumPy where the cells are
straight and the sections constant in them (:func:`gauss_increments`, the same rule as the
compiled expression of the spatial model's quadrature, which curved cells still use).
"""

from functools import cache

import numpy as np
import ufl
from mpi4py import MPI

from ..physics import condensed as rod
from ..physics.kinematics import PLANES, plane_normal
from .condensed import CondensedModel, composite_gauss

#: largest turn of θ in one part of a cell in the quadrature of the centre line (radians):
#: p + 2 Gauss points per part then integrate cos θ and sin θ to about 1e-16
SUBINTERVAL_ANGLE = 0.25


def plane_complex(v, plane):
    """In-plane components of global vectors ``v`` (..., 3) as complex numbers v_a + i v_b
    (a, b the plane's axes, a × b = n): a rotation by θ about n is then e^{iθ}."""
    a, b, _ = PLANES[plane]
    return v[..., a] + 1j * v[..., b]


def _integral_exp(theta0, delta):
    """∫₀¹ e^{i(θ0 + Δ ξ)} dξ = e^{i(θ0 + Δ/2)} sin(Δ/2)/(Δ/2) (the Δ → 0 limit 1 exact)."""
    return np.exp(1j * (theta0 + delta / 2)) * np.sinc(delta / (2 * np.pi))


def _block_parts(A):
    """(α, δ) of 2 × 2 symmetric blocks A = α I + D, D v = δ v̄ (plane complex numbers)."""
    return 0.5 * (A[:, 0, 0] + A[:, 1, 1]), 0.5 * (A[:, 0, 0] - A[:, 1, 1]) + 1j * A[:, 0, 1]


def chord_increments(theta0, theta1, chord, h, sign, A, n):
    r"""u(ξ = 1) − u(ξ = 0) of straight cells with θ linear in ξ, all in plane complex numbers.

    x_ξ = R(θ) c + σ h R A Rᵀ n, c the cell's chord (vertex 0 → 1), h its length, σ = ±1
    (is ξ the arc length's direction), A = Λ0 C_N⁻¹ Λ0ᵀ and n the section force, constant in
    the cell. With A = α I + D (D symmetric, traceless: D v = δ v̄, δ = D_aa + i D_ab),
    R D Rᵀ n = δ n̄ e^{2iθ}, so

        Δu = c (∫e^{iθ} − 1) + σ h (α n + δ n̄ ∫e^{2iθ}),

    both integrals closed form (:func:`_integral_exp`). Arguments are arrays over the cells;
    ``chord`` and ``n`` complex (:func:`plane_complex`), ``A`` (n_cells, 2, 2), the in-plane
    block.
    """
    alpha, delta = _block_parts(A)
    bend = chord * (_integral_exp(theta0, theta1 - theta0) - 1)
    turn = _integral_exp(2 * theta0, 2 * (theta1 - theta0))
    strain = sign * h * (alpha * n + delta * np.conj(n) * turn)
    return bend + strain


def gauss_increments(theta, xi, parts, chord, h, sign, A, n):
    r"""u(ξ_j) − u(0) at the nodes ξ_j of straight cells, θ of any degree.

    In plane complex numbers (cells, len(ξ)), with x_ξ as in :func:`chord_increments`:

        Δu_j = c (∫₀^ξj e^{iθ} − ξ_j) + σ h (α n ξ_j + δ n̄ ∫₀^ξj e^{2iθ}),

    each integral by the composite Gauss rule of the compiled quadrature
    (:meth:`~beamfx.analyses.condensed.CondensedModel._quadrature_increments`): ``parts`` equal
    parts of [0, ξ_j], p + 2 points in each. ``theta`` (cells, p + 1) holds the nodal angles in
    the order of ``xi`` (the nodes' reference points); the other arguments as in
    :func:`chord_increments`.
    """
    weights, basis = _gauss_rule(tuple(xi.tolist()), parts)
    th = (theta @ basis.T).reshape(len(theta), len(xi), -1)  # θ at each node's points
    e = np.cos(th) + 1j * np.sin(th)  # (a third of np.exp's time for complex arguments)
    ints = e @ weights, (e * e) @ weights  # ∫₀^ξj e^{iθ}, ∫₀^ξj e^{2iθ}, over ξ_j
    alpha, delta = _block_parts(A)
    x = np.asarray(xi)[None, :]
    bend = chord[:, None] * x * (ints[0] - 1)
    strain = (
        (sign * h)[:, None]
        * x
        * (alpha[:, None] * n[:, None] + (delta * np.conj(n))[:, None] * ints[1])
    )
    return bend + strain


@cache
def _gauss_rule(xi, parts):
    """(weights summing to 1, the Lagrange basis of the nodes ``xi`` at each node's points
    (len(ξ) · points, len(ξ))) of the composite Gauss rule on [0, ξ_j] (read only)."""
    from ..io._sections import lagrange_matrix

    local, weights = composite_gauss(len(xi) + 1, parts)  # p + 2 points a part
    nodes = np.asarray(xi)
    basis = np.concatenate([lagrange_matrix(nodes, xj * local) for xj in nodes])
    for a in (weights, basis):
        a.flags.writeable = False
    return weights, basis


def cell_values(f, n_cells):
    """Values (n_cells, size) of a DG0 Function ``f`` on the first ``n_cells`` local cells."""
    size = f.function_space.dofmap.index_map_bs
    dofs = f.function_space.dofmap.list.array[:n_cells]
    return f.x.array.reshape(-1, size)[dofs]


def compliance_blocks(t, reference, twist, compliance, plane):
    """In-plane entries (A_aa, A_ab, A_bb) of A = Λ0 C_N⁻¹ Λ0ᵀ = Σ_k c_k e_k e_kᵀ per cell (rows),
    (a, b) the plane's axes: Λ0 = (t, e2, e3) from the unit tangent ``t``, the orientation
    vector ``reference`` and the ``twist`` (radians) as in
    :func:`~beamfx.physics.kinematics.section_frame`, ``compliance`` the diagonal
    (c_1, c_2, c_3) of C_N⁻¹. NumPy: no expression to compile for values constant in a cell."""
    e3 = reference - np.sum(reference * t, axis=1)[:, None] * t
    e3 = e3 / np.linalg.norm(e3, axis=1)[:, None]
    e2 = np.cross(e3, t)
    c, s = np.cos(twist)[:, None], np.sin(twist)[:, None]
    axes = (t, c * e2 + s * e3, -s * e2 + c * e3)
    a, b, _ = PLANES[plane]

    def entry(i, j):
        return sum(compliance[:, k] * axes[k][:, i] * axes[k][:, j] for k in range(3))

    return np.stack([entry(a, a), entry(a, b), entry(b, b)], axis=1)


def build_model(model, comm, extra_points=(), condense=False):
    """The model a run solves: the statically condensed one of ``model`` if ``condense``
    (:class:`PlanarCondensedModel` of a planar model, else the spatial
    :class:`~beamfx.analyses.condensed.CondensedModel`), else its
    :class:`~beamfx.analyses.model.BeamModel` (full or planar)."""
    if not condense:
        from .model import BeamModel

        return BeamModel(model, comm, extra_points=extra_points)
    cls = PlanarCondensedModel if model.kinematics.plane else CondensedModel
    return cls(model, comm, extra_points=extra_points)


class PlanarCondensedModel(CondensedModel):
    """The statically condensed beam of a planar :class:`~beamfx.spec.Model`
    (``kinematics.plane`` set): ``w`` is the angle θ about the plane's normal on ``W`` (P_k,
    scalar), ``u`` the displacement (global axes, derived by :meth:`sync`). See the module
    doc."""

    field_name = "rotation_angle"

    def __init__(self, model, comm=MPI.COMM_WORLD, extra_points=()):
        if not model.kinematics.plane:
            raise ValueError("the planar condensed model needs a planar model (kinematics.plane)")
        self.normal = plane_normal(model.kinematics)
        self._n = np.eye(3)[PLANES[model.kinematics.plane][2]]
        self._cell_data = self._closed = self._straight = self._end_data = None
        super().__init__(model, comm, extra_points)

    # --- the rotation parametrisation -------------------------------------------------------

    def _space(self, m, p):
        """The space of the unknowns: the angle, P_p, scalar."""
        from dolfinx import fem

        return fem.FunctionSpace(m, ufl.FiniteElement("Lagrange", m.ufl_cell(), p))

    def quaternion_of(self, g):
        """(cos θ/2, sin θ/2 n): the unit quaternion of the rotation by θ about n."""
        n = self.normal
        return ufl.as_vector([ufl.cos(g / 2)] + [ufl.sin(g / 2) * n[i] for i in range(3)])

    def rotation_of(self, g):
        """R(θ) about the plane's normal (:func:`~beamfx.physics.condensed.plane_rotation`)."""
        return rod.plane_rotation(g, self.normal)

    def curvature_of(self, g):
        """K = Λ0ᵀ n θ' (section axes)."""
        d = self.discretisation
        return rod.plane_curvature(g, self.normal, d.t0, d.Lam0)

    def np_rotation(self, g):
        """Rotation matrix by the angle g[0] about the plane's normal (NumPy)."""
        from ..physics.rotations import np_exp_rotation

        return np_exp_rotation(float(g[0]) * self._n)

    def _moment_work(self, ld, g, v):
        """M·n δθ: a moment normal to the plane (choose_plane) works the same dead, follower or
        semitangential, since R n = n."""
        return float(np.dot(ld.moment, self._n)) * v

    def spatial_moment(self, ld, g):
        """The moment (global axes) of :meth:`_moment_work` at any angle: (M·n) n times the
        load factor (its other components do no work)."""
        return float(self.load_factor.value) * float(np.dot(ld.moment, self._n)) * self._n

    # --- state ------------------------------------------------------------------------------

    def largest_angle(self):
        """Largest nodal |θ| (no limit applies: the angle is valid at any size)."""
        local = float(np.abs(self.w.x.array).max(initial=0.0))
        return self.comm.allreduce(local, op=MPI.MAX)

    def check_state(self):
        """Nothing to check: R(θ) is valid at any angle."""

    # --- output -----------------------------------------------------------------------------

    def closed_form(self):
        """Whether :meth:`sync` integrates the centre line in closed form: P1 (straight cells,
        θ linear) and every section field constant in a cell."""
        return self.degree == 1 and self._constant_sections()

    def _constant_sections(self):
        d = self.discretisation
        return all(f.function_space.ufl_element().degree() == 0 for f in (d.stiffness, d.twist))

    def straight_cells(self):
        """Whether :meth:`sync` integrates the centre line in NumPy (:func:`gauss_increments`):
        every section field constant in a cell, and every cell straight with |J| constant: its
        geometry nodes (equispaced in ξ, :func:`~beamfx.geometry.mesh.build_mesh`) at
        X0 + ξ (X1 − X0), to 1e-12 of its length; on every rank (collective)."""
        m = self.mesh.mesh
        n = m.topology.index_map(1).size_local
        x = m.geometry.x[m.geometry.dofmap.array.reshape(-1, self.degree + 1)[:n]]
        chord = x[:, 1] - x[:, 0]  # vertices first, then the interior nodes
        length2 = np.einsum("ci,ci->c", chord, chord)
        along = np.einsum("cki,ci->ck", x - x[:, :1], chord) / length2[:, None]
        off = x - x[:, :1] - along[..., None] * chord[:, None, :]
        k = self.degree  # the equispaced nodes' ξ in DOLFINx's order: 0, 1, 1/k, ..., (k-1)/k
        steps = along - np.array([0.0, 1.0, *np.arange(1, k) / k])[: k + 1]
        tol = 1e-12 * np.sqrt(length2)
        straight = bool(
            np.all(np.linalg.norm(off, axis=2) <= tol[:, None])
            and np.all(np.abs(steps) * np.sqrt(length2)[:, None] <= tol[:, None])
        )
        return self.comm.allreduce(straight and self._constant_sections(), op=MPI.LAND)

    def _data(self):
        """Per local cell: its cells' indices, chord (plane complex) and its length, σ, the
        in-plane block of A = Λ0 C_N⁻¹ Λ0ᵀ (2 × 2, :func:`compliance_blocks`: the sections
        and frames are constant in a cell where :meth:`closed_form` holds) and the expression
        of the section force n at the midpoint (None without forces). Built once: the
        geometry does not change."""
        from dolfinx import fem

        from ..solvers.forms import JIT_PARAMS

        d, m = self.discretisation, self.mesh.mesh
        if self._cell_data is None:
            cells = np.arange(m.topology.index_map(1).size_local, dtype=np.int32)
            nodes = m.geometry.dofmap.array.reshape(-1, self.degree + 1)[: len(cells)]
            chord = m.geometry.x[nodes[:, 1]] - m.geometry.x[nodes[:, 0]]  # vertices first
            AA = np.zeros((len(cells), 3))  # the Kirchhoff rod: no compliance
            if self.kin.shear or self.kin.stretch:
                C = cell_values(d.stiffness, len(cells))
                kept = [self.kin.stretch, self.kin.shear, self.kin.shear]
                compliance = np.where(kept, 1.0 / C[:, :3], 0.0)
                t = chord / np.linalg.norm(chord, axis=1)[:, None]  # t0 = J/|J| (straight)
                reference = cell_values(d.reference, len(cells))
                twist = cell_values(d.twist, len(cells))[:, 0]
                AA = compliance_blocks(t, reference, twist, compliance, self.kin.plane)
            force = None  # no forces: n = 0 (and no expression with no domain to compile)
            if self._forces:
                n = self.load_factor * self.section_force()
                force = fem.Expression(n, np.array([[0.5]]), jit_params=dict(JIT_PARAMS))
            block = np.stack([AA[:, [0, 1]], AA[:, [1, 2]]], axis=1)
            sign = np.where(self._flipped[: len(cells)], -1.0, 1.0)
            c = plane_complex(chord, self.kin.plane)
            self._cell_data = (cells, c, np.linalg.norm(chord, axis=1), sign, block, force)
        return self._cell_data

    def _increments(self, xi):
        """u(node) − u(vertex 0) per local cell: closed form where θ is linear in a straight
        cell (:meth:`closed_form`), else composite Gauss with parts of at most
        :data:`SUBINTERVAL_ANGLE` of turn: in NumPy in straight cells
        (:meth:`straight_cells`), else by the compiled expression of the spatial model."""
        if self._closed is None:  # the sections, the geometry and the degree do not change
            self._closed = self.closed_form()
            self._straight = not self._closed and self.straight_cells()
        ends, dofs, n_zero = self._ends(xi)
        theta = self.w.x.array[dofs]
        if not self._closed:
            turn = float(np.ptp(theta, axis=1).max(initial=0.0)) if len(theta) else 0.0
            if self.comm.size > 1:  # (the maximum over one rank is its own)
                turn = self.comm.allreduce(turn, op=MPI.MAX)
            parts = 2 ** int(np.ceil(np.log2(max(1.0, turn / SUBINTERVAL_ANGLE))))
            if not self._straight:
                return self._quadrature_increments(xi, parts)
        cells, c, h, sign, block, force = self._data()
        n = plane_complex(force.eval(cells).reshape(-1, 3), self.kin.plane) if force else n_zero
        (i0, i1), (a, b) = ends, PLANES[self.kin.plane][:2]
        inc = np.zeros((len(cells), len(xi), 3))
        if self._closed:
            du = chord_increments(theta[:, i0], theta[:, i1], c, h, sign, block, n)
            inc[:, i1, a], inc[:, i1, b] = du.real, du.imag
        else:
            du = gauss_increments(theta, xi, parts, c, h, sign, block, n)
            inc[:, :, a], inc[:, :, b] = du.real, du.imag
        return inc

    def _ends(self, xi):
        """((ξ = 0 node, ξ = 1 node), the θ dofs per local cell, the section force of a
        model without forces: zero) for the closed form (the dofs for the quadrature's
        turn too), found once."""
        if self._end_data is None:
            n_cells = self.mesh.mesh.topology.index_map(1).size_local
            dofs = self.W.dofmap.list.array.reshape(-1, len(xi))[:n_cells]
            n_zero = plane_complex(np.zeros((n_cells, 3)), self.kin.plane)
            self._end_data = ((int(np.argmin(xi)), int(np.argmax(xi))), dofs, n_zero)
        return self._end_data


__all__ = [
    "PlanarCondensedModel",
    "build_model",
    "cell_values",
    "chord_increments",
    "compliance_blocks",
    "gauss_increments",
    "plane_complex",
]
