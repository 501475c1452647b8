"""The solid of one beam: mesh, P2 displacement, clamped faces, end tractions; static solves
(load stepping through the project's SNES wrapper) and natural frequencies (SLEPc).

Linear solver: MUMPS below :data:`DIRECT_LIMIT` unknowns, else CG with smoothed-aggregation
AMG (GAMG) and the six rigid-body modes as the matrix's near-nullspace.
"""

import time
from dataclasses import dataclass, field

import ufl

from ..solvers.forms import compile_form
from . import model as forms
from .geometry import END, START, SolidMesh, build_solid, end_frame, start_frame

FACES = {"start": START, "end": END}
DIRECT_LIMIT = 60_000
ITERATIVE = {
    "ksp_type": "cg",
    "ksp_rtol": 1e-10,
    "ksp_max_it": 2000,
    "pc_type": "gamg",
    "pc_gamg_type": "agg",
    "pc_gamg_coarse_eq_limit": 1000,
    "pc_gamg_threshold": 0.02,
    "mg_levels_ksp_type": "chebyshev",
    "mg_levels_pc_type": "jacobi",
    "mg_levels_ksp_max_it": 3,
}


@dataclass(frozen=True)
class SolidSpec:
    """One beam as a solid: material (E, nu, rho), clamped faces ("start"/"end") and dead end
    loads {face: (force, moment)} in global axes; ``material`` one of
    :data:`beamfx.solid.model.MATERIALS`; ``solver`` "auto", "direct" or "iterative"."""

    beam: object
    E: float
    nu: float
    rho: float = 0.0
    clamped: tuple = ("start",)
    loads: dict = field(default_factory=dict)
    material: str = "linear"
    mesh: SolidMesh = field(default_factory=SolidMesh)
    degree: int = 2
    solver: str = "auto"


class Solid:
    """Mesh, space, forms and boundary conditions of a :class:`SolidSpec` (collective)."""

    def __init__(self, spec, comm=None):
        from dolfinx import fem
        from mpi4py import MPI
        from petsc4py import PETSc

        self.spec, self.comm = spec, comm or MPI.COMM_WORLD
        t0 = time.perf_counter()
        self.mesh, _, self.facets, self.mesh_info = build_solid(self.comm, spec.beam, spec.mesh)
        self.seconds = {"mesh": time.perf_counter() - t0}
        m = self.mesh
        self.V = fem.VectorFunctionSpace(m, ("Lagrange", spec.degree), dim=3)
        self.u = fem.Function(self.V, name="displacement")
        self.ds = ufl.Measure("ds", m, subdomain_data=self.facets)
        self.dx = ufl.Measure("dx", m, metadata={"quadrature_degree": 2 * spec.degree})
        self.load_factor = fem.Constant(m, PETSc.ScalarType(0.0))
        zero = fem.Function(self.V)
        fdim = m.topology.dim - 1
        self.bcs = [
            fem.dirichletbc(
                zero, fem.locate_dofs_topological(self.V, fdim, self.facets.find(FACES[f]))
            )
            for f in spec.clamped
        ]
        self.faces = {}
        for name, tag in FACES.items():
            A, c, I2 = forms.face_geometry(m, self.ds, tag)
            frame = (start_frame if name == "start" else end_frame)(spec.beam)
            self.faces[name] = {"tag": tag, "A": A, "c": c, "I2": I2, "frame": frame}

    def unknowns(self):
        """Global number of unknowns."""
        return self.V.dofmap.index_map.size_global * self.V.dofmap.index_map_bs

    def energy(self, material=None):
        """Π(u) = ∫ψ dx − λ ∫ t·u ds (dead tractions on the loaded faces)."""
        s = self.spec
        psi = forms.strain_energy(material or s.material, self.u, s.E, s.nu)
        return psi * self.dx - self.load_factor * self.load_work()

    def load_work(self):
        """∫ t·u ds over the loaded faces at load factor 1."""
        s, work = self.spec, 0
        for name, (force, moment) in s.loads.items():
            f = self.faces[name]
            n = f["frame"].t0 * (1 if name == "end" else -1)  # outward normal
            t = forms.end_traction(self.mesh, n, f["A"], f["c"], f["I2"], force, moment)
            q = {"quadrature_degree": 2 * s.degree + 1}
            work += ufl.dot(t, self.u) * self.ds(f["tag"], metadata=q)
        return work

    def load_norm(self):
        """‖f‖ of the load vector at load factor 1 (for an absolute Newton tolerance)."""
        import dolfinx.fem.petsc as fp
        from petsc4py import PETSc

        if not self.spec.loads:
            return 0.0
        f = fp.assemble_vector(compile_form(ufl.derivative(self.load_work(), self.u)))
        f.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        fp.set_bc(f, self.bcs, scale=0.0)
        norm = f.norm()
        f.destroy()
        return norm

    def iterative(self):
        """Whether to use the iterative solver (asked, or ``auto`` above :data:`DIRECT_LIMIT`)."""
        return self.spec.solver == "iterative" or (
            self.spec.solver == "auto" and self.unknowns() > DIRECT_LIMIT
        )

    def solve_static(self, steps=1, log=None):
        """Equilibrium at load factor 1 (one step if linear). Returns a dict of the solve."""
        from petsc4py import PETSc

        from ..solvers import NewtonSolver, step_load

        v, du = ufl.TestFunction(self.V), ufl.TrialFunction(self.V)
        F = ufl.derivative(self.energy(), self.u, v)
        J = ufl.derivative(F, self.u, du)
        options = dict(ITERATIVE) if self.iterative() else {}
        # the residual floor of a stiff solid is ~1e-12 of the stiffness: stop at 1e-8 of the load
        # (or once the Newton step is below 1e-10 of the displacement, whichever comes first)
        options.update(
            {"snes_rtol": 1e-10, "snes_atol": 1e-8 * self.load_norm(), "snes_stol": 1e-10}
        )
        if self.spec.material == "linear":
            options["snes_type"] = "ksponly"
        t0 = time.perf_counter()
        solver = NewtonSolver(F, J, self.u, self.bcs, "beamfx_solid_", options)
        if self.iterative():
            basis = forms.rigid_body_modes(self.V)
            solver.A.setNearNullSpace(PETSc.NullSpace().create(vectors=basis))
        self.seconds["compile"] = time.perf_counter() - t0
        ksp_its = []

        def solve_at(lam):
            self.load_factor.value = lam
            report = solver.solve()
            ksp_its.append(solver.snes.getLinearSolveIterations())
            return report

        class State:
            saved = self.u.x.array.copy()

            def save(s):
                s.saved[:] = self.u.x.array

            def restore(s):
                self.u.x.array[:] = s.saved
                self.u.x.scatter_forward()

        t1 = time.perf_counter()
        n = 1 if self.spec.material == "linear" else steps
        history = step_load(solve_at, State(), steps=n, easy_iterations=6, log=log)
        self.seconds["solve"] = time.perf_counter() - t1
        nonzeros = int(solver.A.getInfo(PETSc.Mat.InfoType.GLOBAL_SUM)["nz_used"])
        direct = "mumps" if solver.P is None else "dense LU"  # a tiny serial model: dense
        solver.destroy()
        return {
            "matrix_nonzeros": nonzeros,
            "load_steps": len(history),
            "newton_iterations": int(sum(h.iterations for h in history)),
            "krylov_iterations": int(sum(ksp_its)),
            "linear_solver": "cg+gamg" if self.iterative() else direct,
        }

    def modes(self, targets, per_target=4):
        """Natural frequencies ω (rad/s) by kind, each the mode of that kind nearest its target.

        ``targets`` {name: (kind, ω_target)} with kind "axial", "torsion" or "bending"; the
        kind of a mode is read from where its kinetic energy lies (:func:`mode_kind`).
        Shift-and-invert at each target with MUMPS (:func:`beamfx.solvers.eigen.frequencies_by_kind`).
        """
        import dolfinx.fem.petsc as fp

        from ..solvers.eigen import frequencies_by_kind
        from ..solvers.forms import compile_form

        v, du = ufl.TestFunction(self.V), ufl.TrialFunction(self.V)
        psi = forms.strain_energy("linear", self.u, self.spec.E, self.spec.nu)
        K_ufl = ufl.derivative(ufl.derivative(psi * self.dx, self.u, v), self.u, du)
        K = fp.assemble_matrix(compile_form(K_ufl), bcs=self.bcs, diagonal=1.0)
        M = fp.assemble_matrix(
            compile_form(self.spec.rho * ufl.dot(du, v) * self.dx), bcs=self.bcs, diagonal=0.0
        )
        K.assemble()
        M.assemble()
        kinds = self._kind_forms()
        out = frequencies_by_kind(
            K,
            M,
            self.u,
            targets,
            lambda: mode_kind(kinds, self.comm),
            per_target,
            "beamfx_solid_eigen_",
        )
        K.destroy()
        M.destroy()
        return out

    def _kind_forms(self):
        """∫u_t², ∫(u·(t0 × r)/|r|)² and ∫|u|² over the volume (straight beams: t0 fixed)."""
        from dolfinx import fem

        f = self.faces["start"]
        t0 = forms._vec(f["frame"].t0)
        x = ufl.SpatialCoordinate(self.mesh)
        r = x - forms._vec(f["c"])
        r = r - ufl.dot(r, t0) * t0
        twist = ufl.dot(self.u, ufl.cross(t0, r)) ** 2 / (ufl.dot(r, r) + 1e-30)
        return [
            fem.form(e * self.dx)
            for e in (ufl.dot(self.u, t0) ** 2, twist, ufl.dot(self.u, self.u))
        ]

    def face_values(self, name):
        """Mean displacement, small rotation (LS fit) and finite rotation vector of a face."""
        f = self.faces[name]
        if "forms" not in f:
            f["forms"] = forms.face_motion_forms(self.mesh, self.u, self.ds, f["tag"], f["c"])
        u, theta, rotvec = forms.face_motion(f["forms"], f["A"], f["I2"], self.comm)
        return {
            "displacement": u.tolist(),
            "position": (f["c"] + u).tolist(),
            "rotation_vector": (theta if self.spec.material == "linear" else rotvec).tolist(),
        }

    def write(self, path):
        """Displacement on the (quadratic) solid mesh for ParaView (.pvd + .vtu)."""
        from dolfinx.io import VTKFile

        with VTKFile(self.comm, str(path), "w") as f:
            f.write_mesh(self.mesh)
            f.write_function(self.u, 0.0)


def mode_kind(kind_forms, comm):
    """Mode kind: "axial" if most of ∫|u|² is along the axis, "torsion" if most is the twist
    about it, else "bending"."""
    from dolfinx import fem

    axial, twist, total = (comm.allreduce(fem.assemble_scalar(f)) for f in kind_forms)
    if axial > 0.5 * total:
        return "axial"
    return "torsion" if twist > 0.5 * total else "bending"
