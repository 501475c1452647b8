"""A discretised beam model: mesh, unknowns, residual and tangent forms, supports.

Built once per scene; the load factor and prescribed values are ``fem.Constant`` so that load
steps, time steps and parameter sweeps never recompile a form.
"""

import numpy as np
import ufl
from mpi4py import MPI

from ..geometry import BeamSpec, build_mesh
from ..physics import energy
from ..physics.kinematics import section_frame, strains, tangent
from ..physics.rotations import np_quaternion
from .spec import DOF_NAMES, resolve_point


def default_reference(tangents):
    """Per tangent (rows): global z, or global x where the centre line runs along z.

    The section frame makes it normal to the tangent (:func:`section_frame`).
    """
    along_z = np.abs(np.asarray(tangents)[:, 2]) > 1 - 1e-8
    return np.where(along_z[:, None], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0])


def _dg0(mesh, values):
    """A DG0 Function (scalar or vector) with the given per-local-cell values."""
    from dolfinx import fem

    values = np.asarray(values, float)
    size = 1 if values.ndim == 1 else values.shape[1]
    V = (
        fem.FunctionSpace(mesh, ("DG", 0))
        if size == 1
        else fem.VectorFunctionSpace(mesh, ("DG", 0), dim=size)
    )
    f = fem.Function(V)
    dofs = V.dofmap.list.array[: len(values)]  # one (blocked) dof per cell
    f.x.array.reshape(-1, size)[dofs] = values.reshape(-1, size)
    return f


class BeamModel:
    """The discrete model of a :class:`~beamfx.analyses.spec.Model`.

    Attributes: ``mesh`` (BeamMesh), ``W`` (mixed space of displacement and rotation), ``w``
    (unknowns), ``load_factor`` (fem.Constant), ``F`` and ``J`` (UFL residual and tangent),
    ``bcs``, ``C_N``/``C_M``/``Lam0`` (UFL), ``points`` (name -> (tag, xyz)).
    """

    def __init__(self, model, comm=MPI.COMM_WORLD, extra_points=()):
        from dolfinx import fem
        from petsc4py import PETSc

        self.spec, self.kin = model, model.kinematics
        degrees = {b.degree for b in model.beams}
        if len(degrees) != 1:
            raise ValueError(
                f"all beams must have the same degree in this version, got {sorted(degrees)}"
            )
        self.degree = p = degrees.pop()

        # named points: every 'at' of supports, loads, springs and probes becomes a vertex
        ats = [x.at for x in (*model.supports, *model.point_loads, *model.springs)] + list(
            extra_points
        )
        self.named = {at: resolve_point(model, at) for at in dict.fromkeys(ats)}
        breaks = {i: [] for i in range(len(model.beams))}
        for b, s, _ in self.named.values():
            breaks[b].append(s)
        specs = [
            BeamSpec(b.name, b.curve, b.elements, tuple(breaks[i]))
            for i, b in enumerate(model.beams)
        ]
        self.mesh = build_mesh(comm, specs, p, {at: xyz for at, (_, _, xyz) in self.named.items()})
        m = self.mesh.mesh
        self.comm = comm

        # per-cell section data (DG0): stiffnesses, reference vector, twist
        beams = model.beams
        cb = self.mesh.cell_beam
        secs = [
            b.section.with_limits(not self.kin.shear, not self.kin.stretch, b.curve.length)
            for b in beams
        ]
        stiff = np.array([s.stiffnesses() for s in secs])[cb] if len(cb) else np.empty((0, 6))
        ref = default_reference(self._cell_tangents())
        for i, b in enumerate(beams):
            if b.orientation is not None:
                ref[cb == i] = b.orientation
        twist = np.deg2rad([beams[b].twist_deg for b in cb])
        self.stiffness = _dg0(m, stiff)
        self.reference, self.twist = _dg0(m, ref), _dg0(m, twist)
        kp = 10 * max(max(s.EA, s.GA_y, s.GA_z) for s in (b.section for b in beams))
        self.k_penalty = fem.Constant(m, PETSc.ScalarType(kp))

        # unknowns: displacement P_k (3) and rotation P_k (quaternion 4, or rotation vector 3)
        cell = m.ufl_cell()
        U = ufl.VectorElement("Lagrange", cell, p, dim=3)
        Q = ufl.VectorElement("Lagrange", cell, p, dim=self.kin.rotation_size)
        self.W = fem.FunctionSpace(m, ufl.MixedElement([U, Q]))
        self.w = fem.Function(self.W, name="unknowns")
        self._q0_dofs = self.W.sub(1).sub(0).collapse()[1] if self.kin.finite else []
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
        self._build_forms()
        self.bcs, self._bc_values = self._build_supports()

    # --- set-up ----------------------------------------------------------------------------

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

    def _build_forms(self):
        spec, kin = self.spec, self.kin
        u, rot = ufl.split(self.w)
        v_u, v_rot = ufl.split(ufl.TestFunction(self.W))
        Gamma, K = strains(kin, u, rot, self.t0, self.Lam0)
        Pi = energy.strain_energy(Gamma, K, self.C_N, self.C_M, self.dx_shear, self.dx)
        if kin.finite:
            Pi += energy.quaternion_penalty(rot, self.k_penalty, self.dx)
        for sp in spec.springs:
            dP, side = self.point_measure(sp.at)
            e = energy.spring_energy(u, [float(k) for k in sp.stiffness])
            Pi += (e(side) if side else e) * dP

        def vec(x):
            return ufl.as_vector([float(c) for c in x])

        def work_of(load):
            return energy.load_work(
                kin, rot, v_u, v_rot, vec(load.force), vec(load.moment), load.follower
            )

        work = 0
        for ld in spec.point_loads:
            dP, side = self.point_measure(ld.at)
            wk = work_of(ld)
            work += (wk(side) if side else wk) * dP
        names = [b.name for b in spec.beams]
        for dl in spec.distributed_loads:
            wk = work_of(dl)
            on_beam = 1.0 if dl.beam is None else self._beam_indicator(names.index(dl.beam))
            work += on_beam * wk * self.dx
        if any(spec.gravity):
            rho_A = self._dg0_beam_values([b.section.rho_A for b in spec.beams])
            work += rho_A * ufl.dot(vec(spec.gravity), v_u) * self.dx
        self.Pi = Pi
        self.F = ufl.derivative(Pi, self.w, ufl.TestFunction(self.W))
        if work != 0:
            self.F -= self.load_factor * work
        self.J = ufl.derivative(self.F, self.w, ufl.TrialFunction(self.W))

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
                values.append((c, value))
        return bcs, values

    def _support_targets(self, sup):
        """(subspace, component, value as a function of the load factor) per constrained scalar."""
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

    # --- state -----------------------------------------------------------------------------

    def reset(self):
        """Undeformed state: u = 0 and q = (1, 0, 0, 0) (or θ = 0)."""
        self.w.x.array[:] = 0.0
        self.w.x.array[self._q0_dofs] = 1.0

    def set_load_factor(self, lam):
        """Scale loads and prescribed values (a prescribed rotation turns by lam times its angle)."""
        self.load_factor.value = lam
        for c, value in self._bc_values:
            c.value = value(lam)

    def unknowns(self):
        """Global number of unknowns."""
        im = self.W.dofmap.index_map
        return im.size_global * self.W.dofmap.index_map_bs
