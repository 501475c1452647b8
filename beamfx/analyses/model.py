"""The Simo–Reissner beam model: unknowns, residual and tangent forms, supports, on a shared
:class:`~beamfx.analyses.discretisation.Discretisation`.

Built once per scene; the load factor and prescribed values are ``fem.Constant`` so that load
steps, time steps and parameter sweeps never recompile a form. With ``kinematics.plane`` it is
the planar model (two displacements and one angle per node).
"""

import numpy as np
import ufl
from mpi4py import MPI

from ..physics import coupled, energy, mixed
from ..physics.kinematics import displacement, rotation_output, rotation_vector, strains
from ..physics.rotations import np_quaternion
from ..spec import DOF_NAMES
from .checks import check_planar
from .discretisation import Discretised, discretise
from .dofs import global_size, subspace_dofs
from .mechanisms import check_mechanisms
from .mixed import quaternion_penalty
from .releases import HINGE_SIZE, hinge_bcs, hinge_fields, member_rotation


def _check_partition(mesh, comm):
    """Every rank must own a cell: the quaternion model aborts (SEGV in PETSc) on a rank
    without one, so refuse before that with the numbers."""
    cells = mesh.topology.index_map(mesh.topology.dim).size_local
    empty = comm.allreduce(int(cells == 0))
    if empty:
        total = comm.allreduce(cells)
        raise ValueError(
            f"{total} element(s) on {comm.size} MPI ranks leave {empty} rank(s) without one: "
            "use more elements or fewer ranks"
        )


class BeamModel(Discretised):
    """The discrete Simo–Reissner model of a :class:`~beamfx.spec.Model`: a
    :class:`~beamfx.analyses.formulation.BeamFormulation`.

    Unknowns: displacement P_k (3, or 2 in a plane) and rotation P_k (quaternion 4, rotation
    vector 3 for the linear kinematics, or one angle in a plane), in the mixed space ``W``.
    Loads and supports are scaled by ``load_factor``; those with a history also by f(t)
    (:meth:`set_time`). Supports in global axes are Dirichlet conditions, in local axes stiff
    penalty springs.
    """

    #: where the quaternion penalty sees |q|: "nodal" (the default: only at the nodes of q,
    #: :func:`~beamfx.physics.energy.nodal_measure`, which cannot lock) or "quadrature" (the
    #: model's ``dx``, whose Gauss points hold |q_h| = 1 between the nodes too: it locks)
    PENALTY_RULES = ("nodal", "quadrature")

    def __init__(self, model, comm=MPI.COMM_WORLD, extra_points=(), penalty_rule="nodal"):
        from dolfinx import fem
        from petsc4py import PETSc

        self.spec, self.kin = model, model.kinematics
        check_planar(model)
        self.discretisation = d = discretise(model, comm, extra_points)
        _check_partition(d.mesh.mesh, comm)
        m, p = d.mesh.mesh, d.degree
        self.mixed = model.formulation == "mixed"
        if penalty_rule not in self.PENALTY_RULES:
            raise ValueError(f"penalty_rule {penalty_rule!r}: one of {list(self.PENALTY_RULES)}")
        self.penalty_rule = penalty_rule
        self.k_penalty = fem.Constant(m, PETSc.ScalarType(self._penalty_scale()))

        # unknowns: displacement P_k (3) and rotation P_k (quaternion 4, or rotation vector 3)
        cell = m.ufl_cell()
        U = ufl.VectorElement("Lagrange", cell, p, dim=self.kin.displacement_size)
        Q = ufl.VectorElement("Lagrange", cell, p, dim=self.kin.rotation_size)
        # released joints: the hinge unknowns of the enriched elements (analyses.releases)
        self.hinges = hinge_fields(d, self.kin, model.releases) if model.releases else None
        H = [ufl.VectorElement("DG", cell, 0, dim=HINGE_SIZE)] if model.releases else []
        # the mixed form's section force, DG_{p-1}: the last subspace (``force_index``)
        size = self.kin.displacement_size
        N = [ufl.VectorElement("DG", cell, p - 1, dim=size)] if self.mixed else []
        self.force_index = 2 + len(H) if self.mixed else None
        self.W = fem.FunctionSpace(m, ufl.MixedElement([U, Q, *H, *N]))
        self.w = fem.Function(self.W, name="unknowns")
        quaternion = self.kin.finite and not self.kin.plane
        self._q0_dofs = subspace_dofs(self.W, 1, 0) if quaternion else []
        self.reset()

        self.load_factor = fem.Constant(m, PETSc.ScalarType(0.0))
        self.time, self._load_histories = 0.0, []
        self.penalty_motion = []  # (∂Π/∂f form, f(t) constant) of local supports
        self._build_forms()
        self.bcs, self._bc_values = self._build_supports()
        self._bc_views = None  # the constants' storage, by _set_supports
        if model.releases:
            self.bcs += hinge_bcs(self.W, self.hinges)
            check_mechanisms(self)

    # --- forms -----------------------------------------------------------------------------

    def _build_forms(self):
        spec, kin, d = self.spec, self.kin, self.discretisation
        u, rot = ufl.split(self.w)[:2]
        u3 = displacement(kin, u)
        test = ufl.TestFunction(self.W)
        v_u, v_rot = ufl.split(test)[:2]
        Gamma, K = strains(kin, u, self._member_rotation(), d.t0, d.Lam0)
        self.strains = (Gamma, K)
        Pi = self._strain_energy(Gamma, K)
        if kin.finite and not kin.plane:
            Pi += energy.quaternion_penalty(rot, self.k_penalty, self.penalty_measure())
        ground = 0  # springs to ground and local-axes supports: their forces are reactions
        for sp in spec.springs:
            k_u, k_r = [float(k) for k in sp.stiffness], [float(k) for k in sp.rotational]
            if any(k_u):
                ground += d.at_point(sp.at, energy.spring_energy(u3, k_u))
            if any(k_r):
                ground += d.at_point(sp.at, energy.rotational_spring_energy(kin, rot, k_r))
        for sup in spec.supports:
            if sup.axes == "local":
                ground += d.at_point(sup.at, self._local_support_penalty(sup, u3, rot))
        self.Pi_ground = None if isinstance(ground, int) else ground
        if self.Pi_ground is not None:
            Pi += ground

        def vec(x):
            return ufl.as_vector([float(c) for c in x])

        def load_vec(x):
            """A load vector as a ``fem.Constant``: forms of scenes that differ only in load
            values share one compiled kernel. A zero vector stays UFL's zero, so its terms
            vanish from the form as before."""
            from dolfinx import fem
            from petsc4py import PETSc

            if not any(float(c) for c in x):
                return vec(x)
            return fem.Constant(self.mesh.mesh, np.asarray(x, dtype=PETSc.ScalarType))

        def work_of(load):
            force, moment = load_vec(load.force), load_vec(load.moment)
            if getattr(load, "axes", "global") == "section":  # components in Λ0's axes
                force, moment = d.Lam0 * force, d.Lam0 * moment
            return energy.load_work(kin, rot, v_u, v_rot, force, moment, load.kind, load.arm)

        work = 0
        joints = {}  # dead loads at joints of > 2 elements, by history and axes: one field each
        for ld in spec.point_loads:  # constant on a cell: dead forces, moments if θ is linear
            exact = ld.kind == "dead" and not (kin.finite and not kin.plane and any(ld.moment))
            if exact and d.elements_at(ld.at) > 2:
                axes = getattr(ld, "axes", "global")
                joints.setdefault((id(ld.history), axes), (ld.history, axes, []))[2].append(ld)
                continue
            work += self._time_factor(ld.history) * d.at_point(ld.at, work_of(ld), exact)
        for history, axes, loads in joints.values():
            work += self._time_factor(history) * self._joint_work(loads, axes, v_u, v_rot)
        names = [b.name for b in spec.beams]
        for dl in spec.distributed_loads:
            if dl.beam is None:
                on_beam = 1.0
            elif dl.profile is None:
                on_beam = d.beam_indicator(names.index(dl.beam))
            else:  # the profile at the interpolation points, like a section varying along s
                on_beam = d.beam_profile(names.index(dl.beam), dl.profile)
            work += self._time_factor(dl.history) * on_beam * work_of(dl) * d.dx
        if any(spec.gravity):
            work += self._gravity_work(rot, v_u, v_rot)
        self.Pi = Pi
        self.F = ufl.derivative(Pi, self.w, test)
        self.work = None  # virtual work of the loads at load factor 1 (None: no loads)
        if work != 0:
            self.work = work
            self.F -= self.load_factor * work
        self.J = ufl.derivative(self.F, self.w, ufl.TrialFunction(self.W))

    def _gravity_work(self, rot, v_u, v_rot):
        """Virtual work of the weight (gravity ``spec.gravity``, nonzero) of the beams and of
        the point masses. Beams: ρA g·δu per length, and with matrix sections the moment of
        the weight of an offset mass centre. A point mass ``[[masses]]`` has its centre of
        mass at its point (its ``inertia`` is about that point): its weight m g acts there as
        a dead force, m g·δu; its rotary inertia weighs nothing more and has no moment arm."""
        from dolfinx import fem
        from petsc4py import PETSc

        spec, kin, d = self.spec, self.kin, self.discretisation
        g_xyz = [float(c) for c in spec.gravity]
        g = ufl.as_vector(g_xyz)
        work = d.inertia[0] * ufl.dot(g, displacement(kin, v_u)) * d.dx
        if d.matrices is not None:  # the moment of the weight of an offset mass centre
            work += coupled.gravity_moment_work(kin, rot, v_rot, d.Lam0, d.matrices.M, g) * d.dx
        for pm in spec.point_masses:
            if pm.mass > 0:  # m g a constant of the form, as a point load's force
                mg = np.asarray(g_xyz, dtype=PETSc.ScalarType) * pm.mass
                weight = fem.Constant(self.mesh.mesh, mg)
                work += d.at_point(pm.at, ufl.dot(weight, displacement(kin, v_u)), cell_exact=True)
        return work

    def _joint_work(self, loads, axes, v_u, v_rot):
        """Virtual work (a form) of dead point ``loads`` at joints where more than two elements
        meet, all components in ``axes``: one density field for the forces and one for the
        moments (:meth:`~beamfx.analyses.discretisation.Discretisation.joint_load_density`),
        the work of each load being linear in its force and moment."""
        d, kin = self.discretisation, self.kin
        fields = []
        for part in ("force", "moment"):
            pairs = [(ld.at, getattr(ld, part)) for ld in loads if any(getattr(ld, part))]
            f = d.joint_load_density(pairs) if pairs else ufl.as_vector([0.0, 0.0, 0.0])
            fields.append(d.Lam0 * f if axes == "section" and pairs else f)
        rot = ufl.split(self.w)[1]
        return energy.load_work(kin, rot, v_u, v_rot, fields[0], fields[1], "dead") * d.dx

    def _penalty_scale(self):
        """The quaternion penalty k_p: 10 times the largest EA or GA (before the section
        limits); the mixed form's own (:func:`~beamfx.analyses.mixed.quaternion_penalty`)."""
        if self.mixed:
            return quaternion_penalty(self.discretisation)
        return 10 * self.discretisation.stiffness_scale

    def penalty_measure(self):
        """The measure of the quaternion penalty (:attr:`PENALTY_RULES`): the residual's, and
        that of every form that integrates the penalty again (the buckling penalty tangent)."""
        d = self.discretisation
        if self.penalty_rule == "nodal":
            return energy.nodal_measure(d.mesh.mesh, self.W.sub(1).ufl_element())
        return d.dx

    def _strain_energy(self, Gamma, K):
        """The strain energy: the displacement form's, or Π_HR of the section force unknown
        (:mod:`beamfx.physics.mixed`)."""
        d = self.discretisation
        if not self.mixed:
            return d.strain_energy(Gamma, K)
        S_N = mixed.compliance(self.kin, d.stiffness) if d.matrices is None else None
        C = None if d.matrices is None else d.matrices.C
        return mixed.strain_energy(self.section_force(), Gamma, K, S_N, d.C_M, d.dx_shear, d.dx, C)

    def section_force(self, w=None):
        """The mixed form's section force (section axes) of ``w`` (default ``self.w``)."""
        n = ufl.split(self.w if w is None else w)[self.force_index]
        return mixed.section_force(self.kin, n, self.discretisation.Lam0)

    def _member_rotation(self):
        """The rotation field of the members: the node field, with the released relative
        rotations in the elements next to released ends (:mod:`beamfx.analyses.releases`)."""
        parts = ufl.split(self.w)
        if self.hinges is None:
            return parts[1]
        return member_rotation(self.kin, parts[1], parts[2], self.hinges)

    def _time_factor(self, history):
        """1 if ``history`` is None, else a constant that :meth:`set_time` sets to f(t)."""
        from dolfinx import fem
        from petsc4py import PETSc

        if history is None:
            return 1.0
        c = fem.Constant(self.mesh.mesh, PETSc.ScalarType(history(0.0)))
        self._load_histories.append((c, history))
        return c

    def _local_support_penalty(self, sup, u3, rot):
        """Stiff springs on the fixed dofs in the section axes Λ0 at the point (values scaled by
        the load factor and, in a transient, by the support's history of each part, as the
        global supports are). Stiffness 1e9·(largest EA, GA or GJ, EI)/(shortest element)."""
        disc = self.discretisation
        h = disc.min_cell_length()
        C = disc.stiffness
        k_u = 1e9 * ufl.max_value(ufl.max_value(C[0], C[1]), C[2]) / h
        k_r = 1e9 * ufl.max_value(ufl.max_value(C[3], C[4]), C[5]) / h
        local_u = disc.Lam0.T * u3
        local_r = disc.Lam0.T * rotation_vector(self.kin, rot)
        factors = [self._time_factor(sup.history_of(part)) for part in (0, 1)]
        terms, slopes = 0, [0, 0]  # slopes: ∂Π/∂f of each part (the work of a moving support)
        for d in sup.fix:
            i = DOF_NAMES.index(d)
            part = int(i >= 3)
            value = (local_u if i < 3 else local_r)[i % 3]
            unit = self.load_factor * (sup.displacement if i < 3 else sup.rotation)[i % 3]
            target, k = factors[part] * unit, (k_u, k_r)[part]
            terms += energy.constraint_penalty([value], [target], k)
            slopes[part] += -k * (value - target) * unit
        for f, slope in zip(factors, slopes):
            if not isinstance(f, float) and not isinstance(slope, int):
                self.penalty_motion.append((self.discretisation.at_point(sup.at, slope), f))
        return terms

    def _build_supports(self):
        """One scalar Dirichlet condition per fixed component; values are fem.Constants."""
        from dolfinx import fem
        from petsc4py import PETSc

        m = self.mesh.mesh
        bcs, values, spaces = [], [], {}
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
                if (sub, comp) not in spaces:  # once: each sub() copies the dofmap, O(N)
                    spaces[sub, comp] = self.W.sub(sub).sub(comp)
                V = spaces[sub, comp]
                dofs = fem.locate_dofs_topological(V, 0, verts)
                c = fem.Constant(m, PETSc.ScalarType(value(0.0)))
                bcs.append(fem.dirichletbc(c, dofs, V))
                values.append((c, value, sup.history_of(sub)))
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
        self._set_supports(lam)

    def _set_supports(self, lam):
        """The prescribed values at load factor ``lam`` and the current time, written into
        the constants' storage (the view ``Constant.value`` returns, kept: what ``.value = v`` does,
        without its copyto dispatch at every step)."""
        if self._bc_views is None:
            self._bc_views = [(c.value, v, h) for c, v, h in self._bc_values]
        factors = {None: 1.0}  # each history evaluated once (a support has one per dof)
        for storage, value, history in self._bc_views:
            if history not in factors:
                factors[history] = _value_at(history, self.time)
            storage[...] = value(lam * factors[history])

    def set_time(self, t):
        """Time of a transient: loads and supports with a history take their values at ``t``
        (times the load factor, which a transient keeps at 1)."""
        self.time = t
        for c, history in self._load_histories:
            c.value = _value_at(history, t)
        self._set_supports(float(self.load_factor.value))

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
        d = self.discretisation
        u, rot = ufl.split(self.w)[:2]
        Gamma, K = self.strains
        X = ufl.SpatialCoordinate(d.mesh.mesh)
        N, M = d.resultants(Gamma, K)
        if self.mixed:  # the unknown itself (C_N Γ is 0·∞ in a rigid limit)
            N = self.section_force()
            if d.matrices is not None:
                A, B, D = coupled.blocks(d.matrices.C)
                M = B.T * ufl.inv(A) * N + (D - B.T * ufl.inv(A) * B) * K
        return (X, displacement(self.kin, u), rotation_output(self.kin, rot), d.Lam0, N, M)

    def unknowns(self):
        """Global number of unknowns."""
        return global_size(self.W)


def _value_at(history, t):
    """``float(history(t))``: through the history's compiled one-value path where it has one
    (:func:`~beamfx.scene.expr.compile_expression`'s ``at``, the same number)."""
    at = getattr(history, "at", None)
    return at(t) if at is not None else float(history(t))
