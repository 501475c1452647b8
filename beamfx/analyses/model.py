"""A discretised beam model: mesh, unknowns, residual and tangent forms, supports.

Built once per scene; the load factor and prescribed values are ``fem.Constant`` so that load
steps, time steps and parameter sweeps never recompile a form.
"""

import numpy as np
import ufl
from mpi4py import MPI

from ..geometry import BeamSpec, build_mesh
from ..geometry.frames import default_reference
from ..physics import energy
from ..physics.kinematics import (
    displacement,
    rotation_output,
    rotation_vector,
    section_frame,
    strains,
    tangent,
)
from ..physics.rotations import np_quaternion
from .checks import joint_breaks
from .dofs import subspace_dofs
from .spec import DOF_NAMES, resolve_point


def _cell_field(mesh, degree, values):
    """A DG ``degree`` Function with values (n_cells, points, size) at the interpolation points
    of each local cell (scalar if size is 1, and then values may be (n_cells, points))."""
    from dolfinx import fem

    values = np.asarray(values, float)
    size = 1 if values.ndim == 2 else values.shape[2]
    cell = mesh.ufl_cell()
    if size == 1:
        element = ufl.FiniteElement("DG", cell, degree, variant="equispaced")
    else:
        element = ufl.VectorElement("DG", cell, degree, dim=size, variant="equispaced")
    V = fem.FunctionSpace(mesh, element)
    f = fem.Function(V)
    n_points = values.shape[1]
    dofs = V.dofmap.list.array.reshape(-1, n_points)[: len(values)]
    f.x.array.reshape(-1, size)[dofs.ravel()] = values.reshape(-1, size)
    return f


def _dg0(mesh, values):
    """A DG0 Function (scalar or vector) with the given per-local-cell values."""
    values = np.asarray(values, float)
    return _cell_field(mesh, 0, values[:, None])


class BeamModel:
    """The discrete model of a :class:`~beamfx.analyses.spec.Model`.

    Attributes: ``mesh`` (BeamMesh), ``W`` (mixed space of displacement and rotation), ``w``
    (unknowns), ``load_factor`` (fem.Constant), ``F`` and ``J`` (UFL residual and tangent),
    ``bcs``, ``C_N``/``C_M``/``Lam0`` (UFL), ``points`` (name -> (tag, xyz)).
    """

    def __init__(self, model, comm=MPI.COMM_WORLD, extra_points=()):
        from dolfinx import fem
        from petsc4py import PETSc

        from .checks import check_planar

        self.spec, self.kin = model, model.kinematics
        check_planar(model)
        # one DOLFINx mesh holds one element type: every beam gets the highest degree asked for
        self.degree = p = max(b.degree for b in model.beams)
        self.raised_degree = [b.name for b in model.beams if b.degree < p]

        # named points: every 'at' of supports, loads, springs, masses and probes becomes a vertex
        ats = [
            x.at for x in (*model.supports, *model.point_loads, *model.springs, *model.point_masses)
        ] + list(extra_points)
        self.named = {at: resolve_point(model, at) for at in dict.fromkeys(ats)}
        breaks = {i: [] for i in range(len(model.beams))}
        for b, s, _ in self.named.values():
            breaks[b].append(s)
        for b, s in joint_breaks(model):
            breaks[b].append(s)
        specs = [
            BeamSpec(b.name, b.curve, b.elements, tuple(breaks[i]))
            for i, b in enumerate(model.beams)
        ]
        self.mesh = build_mesh(comm, specs, p, {at: xyz for at, (_, _, xyz) in self.named.items()})
        m = self.mesh.mesh
        self.comm = comm

        # section data per cell: stiffness and inertia (DG_p where a section varies, else DG0),
        # reference vector and twist (DG0)
        beams = model.beams
        cb = self.mesh.cell_beam
        self.stiffness, self.inertia, raw_max = self._section_fields()
        ref = default_reference(self._cell_tangents())
        for i, b in enumerate(beams):
            if b.orientation is not None:
                ref[cb == i] = b.orientation
        twist = np.deg2rad([beams[b].twist_deg for b in cb])
        self.reference, self.twist = _dg0(m, ref), _dg0(m, twist)
        self.k_penalty = fem.Constant(m, PETSc.ScalarType(10 * raw_max))

        # unknowns: displacement P_k (3) and rotation P_k (quaternion 4, or rotation vector 3)
        cell = m.ufl_cell()
        U = ufl.VectorElement("Lagrange", cell, p, dim=self.kin.displacement_size)
        Q = ufl.VectorElement("Lagrange", cell, p, dim=self.kin.rotation_size)
        self.W = fem.FunctionSpace(m, ufl.MixedElement([U, Q]))
        self.w = fem.Function(self.W, name="unknowns")
        quaternion = self.kin.finite and not self.kin.plane
        self._q0_dofs = subspace_dofs(self.W, 1, 0) if quaternion else []
        self.reset()

        # measures: shear/axial with p Gauss points (exact to 2p-1), the rest with p+1
        self.dx_shear = ufl.dx(domain=m, metadata={"quadrature_degree": 2 * p - 1})
        self.dx = ufl.dx(domain=m, metadata={"quadrature_degree": 2 * p})
        self.t0 = tangent(m)
        self.Lam0 = section_frame(self.t0, self.reference, self.twist)
        C = self.stiffness
        self.C_N = ufl.diag(ufl.as_vector([C[0], C[1], C[2]]))
        self.C_M = ufl.diag(ufl.as_vector([C[3], C[4], C[5]]))

        self.load_factor = fem.Constant(m, PETSc.ScalarType(0.0))
        self.time, self._load_histories = 0.0, []
        self._build_forms()
        self.bcs, self._bc_values = self._build_supports()

    # --- set-up ----------------------------------------------------------------------------

    def _cell_arc_lengths(self, X):
        """Arc length of the reference points ``X`` (in [0, 1]) of each local cell."""
        m, spans = self.mesh.mesh, self.mesh.cell_span
        n = len(spans)
        nodes = m.geometry.dofmap.array.reshape(-1, self.degree + 1)[:n]
        x0 = m.geometry.x[nodes[:, 0]]
        flipped = np.zeros(n, bool)  # DOLFINx may reverse a cell: its vertex 0 is then at s_b
        for i, b in enumerate(self.spec.beams):
            sel = self.mesh.cell_beam == i
            if np.any(sel):
                at_a = np.linalg.norm(x0[sel] - b.curve.points(spans[sel, 0]), axis=1)
                at_b = np.linalg.norm(x0[sel] - b.curve.points(spans[sel, 1]), axis=1)
                flipped[sel] = at_b < at_a
        s0 = np.where(flipped, spans[:, 1], spans[:, 0])
        s1 = np.where(flipped, spans[:, 0], spans[:, 1])
        return s0[:, None] + np.asarray(X)[None, :] * (s1 - s0)[:, None]

    def _section_fields(self):
        """Stiffness (EA, GA_y, GA_z, GJ, EI_y, EI_z) and inertia (rho_A, rho_I) fields, the
        shear-rigid/inextensible limits applied; and the largest EA or GA before the limits."""
        kin, beams, cb = self.kin, self.spec.beams, self.mesh.cell_beam
        varies = any(b.section.varies for b in beams)
        q = self.degree if varies else 0
        X = np.r_[0.0, 1.0, np.arange(1, q) / q] if q else np.array([0.5])  # basix DG order
        S = self._cell_arc_lengths(X)
        stiff = np.zeros((len(cb), len(X), 6))
        mass = np.zeros((len(cb), len(X), 4))
        raw_max = 0.0
        for i, b in enumerate(beams):
            sel = cb == i
            samples = b.section.along(S[sel].ravel()) if np.any(sel) else b.section.along([0.0])
            raw_max = max(raw_max, max(max(x.EA, x.GA_y, x.GA_z) for x in samples))
            limited = {}
            for x in samples:
                if id(x) not in limited:
                    limited[id(x)] = x.with_limits(not kin.shear, not kin.stretch, b.curve.length)
            stiff[sel] = np.array([limited[id(x)].stiffnesses() for x in samples]).reshape(
                -1, len(X), 6
            )[: np.count_nonzero(sel)]
            mass[sel] = np.array([x.inertias() for x in samples]).reshape(-1, len(X), 4)[
                : np.count_nonzero(sel)
            ]
        if np.any(stiff <= 0):
            raise ValueError("a section stiffness is not positive somewhere along a beam")
        raw_max = self.comm.allreduce(raw_max, op=MPI.MAX)
        m = self.mesh.mesh
        return _cell_field(m, q, stiff), _cell_field(m, q, mass), raw_max

    def _cell_tangents(self):
        m = self.mesh.mesh
        nodes = m.geometry.dofmap.array.reshape(-1, self.degree + 1)[: len(self.mesh.cell_beam)]
        d = m.geometry.x[nodes[:, 1]] - m.geometry.x[nodes[:, 0]]  # chord from end 0 to end 1
        return d / np.maximum(np.linalg.norm(d, axis=1)[:, None], 1e-300)

    def point_measure(self, at):
        """``ds`` at an end vertex, ``dS`` (with '+' restriction) at an inner vertex."""
        tag = self.mesh.points[at][0]
        m = self.mesh.mesh
        m.topology.create_connectivity(0, 1)
        c = m.topology.connectivity(0, 1)
        vertices = self.mesh.point_tags.find(tag)
        n_local = max([len(c.links(v)) for v in vertices], default=0)
        if self.comm.allreduce(n_local, op=MPI.MAX) > 2:
            raise ValueError(
                f"{at!r} joins more than two elements: loads and springs there are not supported"
            )
        inner = self.comm.allreduce(n_local, op=MPI.MAX) == 2
        if inner:
            return ufl.dS(domain=m, subdomain_data=self.mesh.point_tags)(tag), "+"
        return ufl.ds(domain=m, subdomain_data=self.mesh.point_tags)(tag), None

    def _at_point(self, at, integrand):
        """``integrand`` integrated at the named point (restricted there if it is inside)."""
        dP, side = self.point_measure(at)
        return (integrand(side) if side else integrand) * dP

    def point_mass_terms(self, integrand):
        """Σ over the scene's point masses of ``integrand(point_mass)`` (UFL) at its point; 0 if
        there are none. E.g. the mass form with :func:`~beamfx.physics.inertia.point_mass_form`,
        or the kinetic energy with :func:`~beamfx.physics.inertia.point_kinetic_energy`."""
        return sum((self._at_point(pm.at, integrand(pm)) for pm in self.spec.point_masses), start=0)

    def _build_forms(self):
        spec, kin = self.spec, self.kin
        u, rot = ufl.split(self.w)
        u3 = displacement(kin, u)
        test = ufl.TestFunction(self.W)
        v_u, v_rot = ufl.split(test)
        Gamma, K = strains(kin, u, rot, self.t0, self.Lam0)
        Pi = energy.strain_energy(Gamma, K, self.C_N, self.C_M, self.dx_shear, self.dx)
        if kin.finite and not kin.plane:
            Pi += energy.quaternion_penalty(rot, self.k_penalty, self.dx)
        for sp in spec.springs:
            k_u, k_r = [float(k) for k in sp.stiffness], [float(k) for k in sp.rotational]
            if any(k_u):
                Pi += self._at_point(sp.at, energy.spring_energy(u3, k_u))
            if any(k_r):
                Pi += self._at_point(sp.at, energy.rotational_spring_energy(kin, rot, k_r))
        for sup in spec.supports:
            if sup.axes == "local":
                Pi += self._at_point(sup.at, self._local_support_penalty(sup, u3, rot))

        def vec(x):
            return ufl.as_vector([float(c) for c in x])

        def work_of(load):
            return energy.load_work(
                kin, rot, v_u, v_rot, vec(load.force), vec(load.moment), load.kind, load.arm
            )

        work = 0
        for ld in spec.point_loads:
            work += self._history_factor(ld) * self._at_point(ld.at, work_of(ld))
        names = [b.name for b in spec.beams]
        for dl in spec.distributed_loads:
            on_beam = 1.0 if dl.beam is None else self._beam_indicator(names.index(dl.beam))
            work += self._history_factor(dl) * on_beam * work_of(dl) * self.dx
        if any(spec.gravity):
            rho_A = self.inertia[0]
            work += rho_A * ufl.dot(vec(spec.gravity), displacement(kin, v_u)) * self.dx
        self.Pi = Pi
        self.F = ufl.derivative(Pi, self.w, test)
        self.work = None  # virtual work of the loads at load factor 1 (None: no loads)
        if work != 0:
            self.work = work
            self.F -= self.load_factor * work
        self.J = ufl.derivative(self.F, self.w, ufl.TrialFunction(self.W))

    def _history_factor(self, load):
        """1, or a constant that :meth:`set_time` sets to the load's history f(t)."""
        from dolfinx import fem
        from petsc4py import PETSc

        if load.history is None:
            return 1.0
        c = fem.Constant(self.mesh.mesh, PETSc.ScalarType(load.history(0.0)))
        self._load_histories.append((c, load.history))
        return c

    def _local_support_penalty(self, sup, u3, rot):
        """Stiff springs on the fixed dofs in the section axes Λ0 at the point (values scaled by
        the load factor). Stiffness 1e9·(largest EA, GA or GJ, EI)/(shortest element)."""
        h = self.comm.allreduce(np.min(np.diff(self.mesh.cell_span, axis=1)), op=MPI.MIN)
        C = self.stiffness
        k_u = 1e9 * ufl.max_value(ufl.max_value(C[0], C[1]), C[2]) / h
        k_r = 1e9 * ufl.max_value(ufl.max_value(C[3], C[4]), C[5]) / h
        local_u = self.Lam0.T * u3
        local_r = self.Lam0.T * rotation_vector(self.kin, rot)
        terms = 0
        for d in sup.fix:
            i = DOF_NAMES.index(d)
            if i < 3:
                value, target, k = local_u[i], self.load_factor * sup.displacement[i], k_u
            else:
                value, target, k = local_r[i - 3], self.load_factor * sup.rotation[i - 3], k_r
            terms += energy.constraint_penalty([value], [target], k)
        return terms

    def _dg0_beam_values(self, per_beam):
        return _dg0(self.mesh.mesh, np.asarray(per_beam, float)[self.mesh.cell_beam])

    def _beam_indicator(self, beam_index):
        """DG0 function: 1 on the cells of one beam, 0 elsewhere."""
        return self._dg0_beam_values(
            [1.0 if i == beam_index else 0.0 for i in range(len(self.spec.beams))]
        )

    def _build_supports(self):
        """One scalar Dirichlet condition per fixed component; values are fem.Constants."""
        from dolfinx import fem
        from petsc4py import PETSc

        m = self.mesh.mesh
        bcs, values = [], []
        for sup in self.spec.supports:
            if sup.axes == "local":
                continue  # penalty springs in the forms
            bad = [d for d in sup.fix if d not in DOF_NAMES]
            if bad:
                raise ValueError(
                    f"support at {sup.at!r}: unknown dofs {bad}; allowed {list(DOF_NAMES)}"
                )
            verts = self.mesh.point_tags.find(self.mesh.points[sup.at][0])
            targets = self._support_targets(sup)
            for sub, comp, value in targets:
                V = self.W.sub(sub).sub(comp)
                dofs = fem.locate_dofs_topological(V, 0, verts)
                c = fem.Constant(m, PETSc.ScalarType(value(0.0)))
                bcs.append(fem.dirichletbc(c, dofs, V))
                values.append((c, value, sup.history))
        return bcs, values

    def _support_targets(self, sup):
        """(subspace, component, value as a function of the load factor) per constrained scalar."""
        if self.kin.plane:
            return self._planar_support_targets(sup)
        fixed_u = [DOF_NAMES.index(d) for d in sup.fix if d.startswith("u")]
        fixed_r = [DOF_NAMES.index(d) - 3 for d in sup.fix if d.startswith("r")]
        d = np.asarray(sup.displacement, float)
        rot = np.asarray(sup.rotation, float)
        out = [(0, i, lambda lam, i=i: lam * d[i]) for i in fixed_u]
        if not self.kin.finite:
            return out + [(1, i, lambda lam, i=i: lam * rot[i]) for i in fixed_r]
        if len(fixed_r) == 3:  # all four quaternion components; the angle grows with the load
            angle = np.linalg.norm(rot)
            axis = rot if angle > 0 else np.array([1.0, 0.0, 0.0])
            return out + [
                (1, i, lambda lam, i=i: np_quaternion(axis, lam * angle)[i]) for i in range(4)
            ]
        if np.any(rot[fixed_r]):
            raise ValueError(
                f"support at {sup.at!r}: a prescribed rotation needs rx, ry and rz fixed"
            )
        return out + [(1, 1 + i, lambda lam: 0.0) for i in fixed_r]  # rotation axis normal to these

    def _planar_support_targets(self, sup):
        """Planar model: the in-plane dofs; out-of-plane ones do not exist (zero by construction)."""
        dofs = {name: (sub, comp) for name, sub, comp in self.kin.dofs()}
        values = np.r_[sup.displacement, sup.rotation]
        out = []
        for d in sup.fix:
            i = DOF_NAMES.index(d)
            if d in dofs:
                out.append((*dofs[d], lambda lam, v=values[i]: lam * v))
            elif values[i]:
                raise ValueError(
                    f"support at {sup.at!r}: {d} = {values[i]} leaves the plane "
                    f"{self.kin.plane} of the planar model"
                )
        return out

    # --- state -----------------------------------------------------------------------------

    def reset(self):
        """Undeformed state: u = 0 and q = (1, 0, 0, 0) (or θ = 0)."""
        self.w.x.array[:] = 0.0
        self.w.x.array[self._q0_dofs] = 1.0

    def set_load_factor(self, lam):
        """Scale loads and prescribed values (a prescribed rotation turns by lam times its angle)."""
        self.load_factor.value = lam
        for c, value, history in self._bc_values:
            c.value = value(lam * (1.0 if history is None else float(history(self.time))))

    def set_time(self, t):
        """Time of a transient: loads and supports with a history take their values at ``t``
        (times the load factor, which a transient keeps at 1)."""
        self.time = t
        for c, history in self._load_histories:
            c.value = float(history(t))
        self.set_load_factor(float(self.load_factor.value))

    # --- what solvers and writers ask of every model (CondensedModel answers differently) ---

    #: a non-local term the forms cannot hold (:class:`~beamfx.solvers.NewtonSolver` ``coupling``)
    coupling = None

    def check_state(self):
        """Raise if the state left the model's range: never (quaternions cover any rotation)."""

    def sync(self):
        """Bring derived fields up to date before output: none (u is an unknown)."""

    def section_parts(self):
        """(X, u, rotation output, Λ0, N = C_N Γ, M = C_M K) as UFL, for
        :func:`beamfx.io._sections.section_expression`."""
        u, rot = ufl.split(self.w)
        Gamma, K = strains(self.kin, u, rot, self.t0, self.Lam0)
        X = ufl.SpatialCoordinate(self.mesh.mesh)
        return (
            X,
            displacement(self.kin, u),
            rotation_output(self.kin, rot),
            self.Lam0,
            self.C_N * Gamma,
            self.C_M * K,
        )

    def unknowns(self):
        """Global number of unknowns."""
        im = self.W.dofmap.index_map
        return im.size_global * self.W.dofmap.index_map_bs
