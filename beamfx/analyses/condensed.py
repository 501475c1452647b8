r"""The statically condensed beam (:mod:`beamfx.physics.condensed`): a cantilever under point
loads with the rotation field as its only unknown, three per node instead of seven.

In a statically determinate beam the section force is known from the loads, n(s) = the sum
of the forces beyond s, so the strains Γ = C_N⁻¹ Λ0ᵀ Rᵀ n can be eliminated from the
Simo–Reissner energy exactly (:func:`~beamfx.physics.condensed.load_potential`): same
equilibrium, shear and stretch kept (or dropped, with ``[model] shear``/``stretch`` false: the
Kirchhoff rod), a fraction of the unknowns. :func:`~beamfx.analyses.trimming.condensed_fit` says where it applies: a
static analysis of one beam clamped at its start, loaded by point loads (dead or follower
forces; dead, follower or semitangential moments) and nothing else.

The loads' work is local in the rotations except for a follower force F = R(g_a) f at s_a:
n depends on the rotation there. The residual takes F as a constant set from the current g_a
before each assembly; the tangent adds the missing rank-3 term −λ G (∂F/∂g_a) with
G_i = ∂/∂g ∫₀^{s_a} e_i·x' ds (:class:`FollowerCoupling`), so Newton converges quadratically.

Output: the object is a :class:`~beamfx.analyses.formulation.Formulation` on the shared
:class:`~beamfx.analyses.discretisation.Discretisation`, so the probes and field writers read
it like the full model (:meth:`section_parts`). The displacement is integrated from
x' = R(t0 + Λ0 Γ) cell by cell (:meth:`sync`, exact to quadrature); the section force is the
statically determined one, in section axes Λ0ᵀRᵀn.
"""

from functools import cache, cached_property

import numpy as np
import ufl
from mpi4py import MPI

from ..physics import condensed as rod
from ..physics.rotations import np_exp_rotation, np_left_jacobian
from ..spec import resolve_point
from .discretisation import Discretised, discretise
from .dofs import constrained_dofs, global_size, owned_size
from .trimming import condensed_fit

#: largest rotation the rotation vector is trusted with (the map ψ -> R is singular at 2π)
MAX_ANGLE = np.radians(330.0)


#: FFCx table tolerances for the centre-line quadrature: its defaults (rtol 1e-6, atol 1e-9)
#: round basis values within 1e-6 of 0 or ±1 to those numbers, which costs 1e-8 of the
#: displacement at Gauss points near a cell's end (measured: P4, 8 parts per cell)
EXACT_TABLES = {"table_rtol": 1e-15, "table_atol": 1e-15}


@cache
def _gauss(points):
    """Gauss-Legendre points and weights on [-1, 1] (an eigenvalue solve: once per count)."""
    return np.polynomial.legendre.leggauss(points)


def composite_gauss(points, parts):
    """The composite Gauss rule on [0, 1]: ``parts`` equal parts, ``points`` Gauss points in
    each; (points, weights summing to 1), flat. The centre line's quadrature from vertex 0 to
    a node ξ_j uses it scaled by ξ_j (compiled, :meth:`CondensedModel._quadrature_increments`,
    or in NumPy, :func:`~beamfx.analyses.planar_condensed.gauss_increments`)."""
    gx, gw = _gauss(points)
    local = (np.arange(parts)[:, None] + (gx[None, :] + 1) / 2) / parts
    return local.ravel(), np.tile(gw / 2, parts) / parts


class RotationRangeError(ValueError):
    """A rotation beyond :data:`MAX_ANGLE` in the condensed model."""


class FollowerCoupling:
    """The follower forces' tangent terms (rank 3 with a rotation vector, rank 1 with a plane
    angle) and their values from the current rotations; ``model.np_rotation`` maps the
    rotation unknowns at a node to the rotation matrix."""

    def __init__(self, model, forces):
        import dolfinx.fem.petsc  # noqa: F401  (fem.petsc)
        from dolfinx import fem

        self.model, self.forces = model, forces  # [(Constant F, f0, point, G forms)]
        self.G = [[fem.petsc.create_vector(G_i) for G_i in f[3]] for f in forces]
        V = model.W
        self.bs = bs = V.dofmap.index_map_bs  # rotation unknowns per node: 3 or 1
        self._bc_dofs = constrained_dofs(model.bcs)
        owned = owned_size(V)
        self._rows = np.arange(owned, dtype=np.int32)
        self._rows_global = V.dofmap.index_map.local_range[0] * bs + self._rows
        self._tip = [self._point_dofs(f[2]) for f in forces]

    def _point_dofs(self, at):
        """Global indices of the dofs of g at a named point (every rank), and the local ones
        on the rank that owns them (else None)."""
        from dolfinx import fem

        m, V = self.model.mesh.mesh, self.model.W
        verts = self.model.mesh.point_tags.find(self.model.mesh.points[at][0])
        local = fem.locate_dofs_topological(V, 0, verts)
        owned = [d for d in local if d < V.dofmap.index_map.size_local]
        start = V.dofmap.index_map.local_range[0]
        bs = self.bs
        mine = [(start + d) * bs + np.arange(bs) for d in owned[:1]]
        found = [x for part in m.comm.allgather(mine) for x in part]
        return found[0].astype(np.int32), (owned[0] * bs + np.arange(bs)) if owned else None

    def _g_at(self, dofs):
        """The rotation vector at a point, from the rank that owns it (collective)."""
        local = dofs[1]
        g = self.model.w.x.array[local] if local is not None else np.zeros(self.bs)
        return self.model.comm.allreduce(g, op=MPI.SUM)

    def update(self):
        """F = R(g_a) f0 into the constants, from the current rotations."""
        for (F, f0, _, _), dofs in zip(self.forces, self._tip):
            F.value[:] = self.model.np_rotation(self._g_at(dofs)) @ f0

    def reset(self):
        """Put the reference forces f0 back into the constants (the undeformed state)."""
        for F, f0, _, _ in self.forces:
            F.value[:] = f0

    def add_to_tangent(self, A):
        """A −= λ Σ_i G_i ⊗ ∂F_i/∂g_a (rows of this rank; constrained rows left alone)."""
        import dolfinx.fem.petsc as fp
        from petsc4py import PETSc

        lam = float(self.model.load_factor.value)
        A.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
        for (_, f0, _, forms), G, dofs in zip(self.forces, self.G, self._tip):
            dF = self._force_derivative(f0, self._g_at(dofs))  # (3 components, bs dofs)
            rows = []
            for vec, form in zip(G, forms):
                with vec.localForm() as local:
                    local.set(0.0)
                fp.assemble_vector(vec, form)
                vec.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
                rows.append(vec.array_r[: len(self._rows)].copy())
            G_local = np.array(rows).T  # (owned rows, 3)
            G_local[self._bc_dofs[self._bc_dofs < len(self._rows)]] = 0.0
            A.setValues(self._rows_global, dofs[0], -lam * G_local @ dF, addv=True)
        A.assemble()

    def _force_derivative(self, f0, g, h=1e-7):
        """∂(R(g) f0)/∂g by central differences (3 × bs; R is smooth in g)."""
        rotate = self.model.np_rotation
        out = np.zeros((3, len(g)))
        for j in range(len(g)):
            e = np.zeros(len(g))
            e[j] = h
            out[:, j] = (rotate(g + e) - rotate(g - e)) @ f0
        return out / (2 * h)

    def destroy(self):
        """Free the PETSc vectors of the G_i forms."""
        for G in self.G:
            for v in G:
                v.destroy()


class CondensedModel(Discretised):
    """The statically condensed beam of a :class:`~beamfx.spec.Model` (see the module
    doc): a :class:`~beamfx.analyses.formulation.Formulation` whose unknown ``w`` is the
    rotation vector field g on ``W`` (P_k, 3 components), plus ``u`` (the displacement, derived
    by :meth:`sync`) and ``coupling`` (the follower forces' tangent terms, or None).

    The rotation parametrisation is in the hooks :meth:`_space`, :meth:`rotation_of`,
    :meth:`quaternion_of`, :meth:`curvature_of`, :meth:`_moment_work` and :meth:`np_rotation`;
    :class:`~beamfx.analyses.planar_condensed.PlanarCondensedModel` overrides them with the
    plane angle.
    """

    #: name of the unknown field
    field_name = "rotation_vector"

    def __init__(self, model, comm=MPI.COMM_WORLD, extra_points=()):
        from dolfinx import fem
        from petsc4py import PETSc

        why = condensed_fit(model)
        if why:
            raise ValueError(f"the statically condensed model does not apply: {why}")
        # finite kinematics (condensed_fit); shear and stretch decide the compliance
        self.spec, self.kin = model, model.kinematics
        self.discretisation = d = discretise(model, comm, extra_points)
        m, p = d.mesh.mesh, d.degree
        self.load_factor = fem.Constant(m, PETSc.ScalarType(0.0))
        C, kin = d.stiffness, self.kin
        self.compliance = ufl.diag(  # C_N⁻¹, zero where the scene drops stretch or shear
            ufl.as_vector(
                [1 / C[0] if kin.stretch else 0.0]
                + [1 / C[i] if kin.shear else 0.0 for i in (1, 2)]
            )
        )
        # the cells' vertex 0 -> 1 direction against increasing arc length (DOLFINx may
        # reverse a cell): t_s = ±t0 is the tangent d/ds, for the terms linear in it
        self._s_ends = s_ends = d.cell_arc_lengths([0.0, 1.0])  # geometry: kept for sync
        self._flipped = s_ends[:, 0] > s_ends[:, 1]
        self.t_s = d.cell_function(np.where(self._flipped, -1.0, 1.0)) * d.t0
        self.W = self._space(m, p)
        self.w = fem.Function(self.W, name=self.field_name)
        U = fem.FunctionSpace(m, ufl.VectorElement("Lagrange", m.ufl_cell(), p, dim=3))
        self.u = fem.Function(U, name="displacement")  # derived: :meth:`sync`
        # the node order of a cell of U, as reference coordinates (for sync)
        self._xi = np.asarray(U.element.interpolation_points()).reshape(-1)
        self.dx = ufl.dx(domain=m, metadata={"quadrature_degree": 2 * p + 2})
        self._build_forms()
        verts = self.mesh.point_tags.find(self.mesh.points[model.supports[0].at][0])
        clamp = fem.locate_dofs_topological(self.W, 0, verts)
        bs = self.W.dofmap.index_map_bs
        zero = np.zeros(bs) if bs > 1 else PETSc.ScalarType(0.0)
        self.bcs = [fem.dirichletbc(zero, clamp, self.W)]
        self.coupling = FollowerCoupling(self, self._followers) if self._followers else None
        self._integrator = self._chain_data = None
        self._synced = None  # (load factor, w) that ``u`` was last integrated from

    # --- the rotation parametrisation (hooks) -----------------------------------------------

    def _space(self, m, p):
        """The space of the unknowns: the rotation vector, P_p, 3 components."""
        from dolfinx import fem

        return fem.FunctionSpace(m, ufl.VectorElement("Lagrange", m.ufl_cell(), p, dim=3))

    def quaternion_of(self, g):
        """Unit quaternion (UFL) of the unknowns ``g``."""
        return rod.rotation_quaternion(g)

    def rotation_of(self, g):
        """Rotation matrix R (UFL) of the unknowns ``g``."""
        from ..physics.rotations import rotation

        return rotation(rod.rotation_quaternion(g))

    def curvature_of(self, g):
        """K = Λ0ᵀ axial(Rᵀ R') (section axes) of the unknowns ``g``."""
        d = self.discretisation
        return rod.curvature(g, d.t0, d.Lam0)

    @staticmethod
    def np_rotation(g):
        """Rotation matrix of the unknowns at one node (NumPy): exp(ĝ)."""
        return np_exp_rotation(g)

    def _moment_work(self, ld, g, v):
        M = ufl.as_vector([float(c) for c in ld.moment])
        if ld.kind == "semitangential":
            from ..physics.rotations import quaternion_rotation_vector

            return ufl.derivative(
                ufl.dot(M, quaternion_rotation_vector(rod.rotation_quaternion(g))), g, v
            )
        return ufl.dot(M, rod.virtual_rotation(g, v, spatial=ld.kind == "dead"))

    def spatial_moment(self, ld, g):
        """The moment (global axes) that the point load ``ld``'s moment exerts at the nodal
        unknowns ``g`` of its point (NumPy), the one :meth:`_moment_work` does work with:
        dead M, follower R M, semitangential J⁻ᵀ M (potential M·ψ, ψ = g; δθ = J δψ with J
        the left Jacobian of exp, :func:`~beamfx.physics.rotations.np_left_jacobian`), all
        times the load factor."""
        M = float(self.load_factor.value) * np.asarray(ld.moment, float)
        if ld.kind == "follower":
            return self.np_rotation(g) @ M
        if ld.kind == "semitangential":
            return np.linalg.solve(np_left_jacobian(g).T, M)
        return M

    # --- forms ------------------------------------------------------------------------------

    def _before(self, at):
        """DG0 indicator of the cells between the clamp and the named point."""
        s_a = resolve_point(self.spec, at)[1]
        span = self.mesh.cell_span
        return self.discretisation.cell_function(
            (np.max(span, axis=1) <= s_a + 1e-12 * (1 + s_a)) * 1.0
        )

    def _build_forms(self):
        from dolfinx import fem
        from petsc4py import PETSc

        from ..solvers.forms import compile_form

        d = self.discretisation
        g, v, m = self.w, ufl.TestFunction(self.W), self.mesh.mesh
        self._forces, followers, moments = [], [], 0
        for ld in self.spec.point_loads:
            if any(ld.force):
                F = fem.Constant(m, PETSc.ScalarType((0.0, 0.0, 0.0)))
                F.value[:] = ld.force
                before = self._before(ld.at)
                self._forces.append((before, F))
                if ld.kind == "follower":
                    followers.append((F, np.asarray(ld.force, float), ld.at, before))
            if any(ld.moment):
                moments += d.at_point(ld.at, self._moment_work(ld, g, v))
        n = self.load_factor * self.section_force()
        R = self.rotation_of(g)
        K = self.curvature_of(g)
        Pi = rod.bending_energy(K, d.C_M, self.dx) - rod.load_potential(
            R, n, self.t_s, d.Lam0, self.compliance, self.dx
        )
        self.F = ufl.derivative(Pi, g, v) - self.load_factor * moments
        self.J = ufl.derivative(self.F, g, ufl.TrialFunction(self.W))
        self.work = None  # the residual is not linear in the load factor (arc length: no)
        # follower forces: ∂(residual)/∂(force at the point), for the tangent's coupling term
        self._followers = [
            (
                F,
                f0,
                at,
                [compile_form(ufl.derivative(before * x * self.dx, g, v)) for x in self.x_dot],
            )
            for F, f0, at, before in followers
        ]

    @cached_property
    def x_dot(self):
        """The centre line's x' = R(t_s + Λ0 Γ) (UFL, global axes), for the follower forces'
        coupling and the centre line by quadrature; built where used (the closed-form centre
        line of the planar model needs none)."""
        n = self.load_factor * self.section_force()
        d = self.discretisation
        return rod.position_rate(self.rotation_of(self.w), n, self.t_s, d.Lam0, self.compliance)

    # --- state ------------------------------------------------------------------------------

    def reset(self):
        """Back to the undeformed state: zero rotations and displacements, reference forces."""
        self.w.x.array[:] = 0.0
        self.u.x.array[:] = 0.0
        self._synced = None
        if self.coupling:
            self.coupling.reset()

    def set_load_factor(self, lam):
        """Set the load factor λ that scales every load."""
        self.load_factor.value = lam

    def unknowns(self):
        """Global number of unknowns (rotation components per node times the nodes)."""
        return global_size(self.W)

    def largest_angle(self):
        """Largest nodal rotation angle |ψ| (the parametrisation is singular at 2π)."""
        psi = self.w.x.array.reshape(-1, 3)
        local = float(np.linalg.norm(psi, axis=1).max(initial=0.0))
        return self.comm.allreduce(local, op=MPI.MAX)

    def check_state(self):
        """Raise if a rotation came near 2π, where the rotation vector is no longer valid."""
        angle = self.largest_angle()
        if angle > MAX_ANGLE:
            raise RotationRangeError(
                f"a section rotated by {np.degrees(angle):.0f} degrees: the statically condensed "
                f"model (rotation vector) is valid below {np.degrees(MAX_ANGLE):.0f}; set "
                '[model] condense = "none" for the quaternion model'
            )

    # --- output -----------------------------------------------------------------------------

    def section_force(self):
        """n(s) = Σ of the forces beyond s, global axes (statics of the cantilever)."""
        return sum((before * F for before, F in self._forces), start=ufl.as_vector([0.0] * 3))

    def section_parts(self):
        """(X, u, quaternion, Λ0, N, M) as UFL, for :func:`beamfx.io._sections.section_expression`."""
        d, g = self.discretisation, self.w
        R = self.rotation_of(g)
        N = d.Lam0.T * (R.T * (self.load_factor * self.section_force()))
        M = d.C_M * self.curvature_of(g)
        X = ufl.SpatialCoordinate(self.mesh.mesh)
        return X, self.u, self.quaternion_of(g), d.Lam0, N, M

    def _increments(self, xi):
        """u(node) − u(vertex 0) of each local cell's nodes (n_cells, len(xi), 3)."""
        return self._quadrature_increments(xi)

    def _quadrature_increments(self, xi, subintervals=1):
        """:meth:`_increments` by Gauss quadrature of u_ξ = ±|J| (x' − t_s) from vertex 0 to
        each node ξ_j: ``subintervals`` equal parts of [0, ξ_j], p + 2 points in each (one
        expression compiled per count, cached). The node at vertex 0 (ξ = 0) gets zero
        without quadrature (its points would all be ξ = 0: a quarter of a P3 cell's)."""
        from dolfinx import fem

        from ..solvers.forms import JIT_PARAMS

        m = self.mesh.mesh
        cache = self._integrator = self._integrator or {}
        moved = xi != 0  # the nodes integrated to
        if subintervals not in cache:
            local, weights = composite_gauss(self.degree + 2, subintervals)
            points = (xi[moved, None] * local[None, :]).reshape(-1, 1)
            x_xi = ufl.Jacobian(m)[:, 0]  # dX/dξ = |J| t0: u_ξ = |J| (t0·t_s) u'
            sign = ufl.dot(self.t_s, self.discretisation.t0)
            u_xi = sign * ufl.sqrt(ufl.dot(x_xi, x_xi)) * (self.x_dot - self.t_s)
            expr = fem.Expression(
                u_xi, points, form_compiler_params=EXACT_TABLES, jit_params=dict(JIT_PARAMS)
            )
            cells = np.arange(m.topology.index_map(1).size_local, dtype=np.int32)
            cache[subintervals] = (expr, weights, cells, int(np.count_nonzero(moved)))
        expr, gw, cells, k = cache[subintervals]
        n = len(cells)
        vals = expr.eval(cells).reshape(n, k, len(gw), 3)
        inc = np.zeros((n, len(xi), 3))
        inc[:, moved] = xi[None, moved, None] * np.einsum("cngi,g->cni", vals, gw)
        return inc

    def _in_sync(self):
        """Whether ``u`` was integrated from the current ``w`` and load factor (on every
        rank: collective)."""
        last = self._synced
        same = (
            last is not None
            and last[0] == float(self.load_factor.value)
            and np.array_equal(last[1], self.w.x.array)
        )
        return same if self.comm.size == 1 else self.comm.allreduce(same, op=MPI.LAND)

    def _chain(self):
        """What :meth:`sync` needs of the mesh, found once (the geometry does not change):
        the local cells' count, their flips, the node at vertex 1, the order of all cells
        along the beam (their s_a over all ranks, sorted), this rank's offset in it, and the
        dofs of ``u`` per local cell. Collective the first time."""
        if self._chain_data is None:
            m, xi = self.mesh.mesh, self._xi
            n = m.topology.index_map(1).size_local
            s_a = self._s_ends[:n].min(axis=1)
            parts = self.comm.allgather(s_a) if self.comm.size > 1 else [s_a]
            order = np.argsort(np.concatenate(parts), kind="stable")
            offset = sum(len(p) for p in parts[: self.comm.rank])
            one = int(np.argmin(np.abs(xi - 1.0)))  # the node at vertex 1
            dofs = self.u.function_space.dofmap.list.array.reshape(-1, len(xi))[:n]
            self._chain_data = (n, self._flipped[:n], one, order, offset, dofs.ravel())
        return self._chain_data

    def sync(self):
        """Integrate the displacement u = ∫ (x' − t0) ds from the clamp into ``self.u``.

        Each node's u is the value at its cell's vertex 0 plus the cell's increment to it
        (:meth:`_increments`), the vertex values chained from the clamp along the beam.
        Collective: the per-cell increments of all ranks are allgathered (few cells).
        Nothing is done if ``w`` and the load factor are those of the last call (a step's
        probes, reactions and frame each ask): ``u`` and the follower forces are functions
        of them alone.
        """
        if self._in_sync():
            return
        stamp = (float(self.load_factor.value), self.w.x.array.copy())
        if self.coupling:  # follower forces from the converged rotations
            self.coupling.update()
        inc = self._increments(self._xi)
        n, flipped, one, order, offset, dofs = self._chain()
        step = np.where(flipped[:, None], -inc[:, one], inc[:, one])  # from s_a to s_b
        # one rank: its own part (an allgather pickles it: a third of this call's time)
        steps = np.concatenate(self.comm.allgather(step)) if self.comm.size > 1 else step
        at_s_a = np.zeros((len(steps), 3))
        at_s_a[order] = np.cumsum(np.vstack([np.zeros(3), steps[order][:-1]]), axis=0)
        mine = at_s_a[offset : offset + n]
        u_v0 = mine + np.where(flipped[:, None], step, 0.0)
        self.u.x.array.reshape(-1, 3)[dofs] = (u_v0[:, None, :] + inc).reshape(-1, 3)
        self.u.x.scatter_forward()
        self._synced = stamp
