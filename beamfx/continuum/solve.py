"""The continuum beam of one straight rectangular beam: mesh, P_k fields (r, d2, d3), clamp,
end loads; static solves (load stepping through the project's SNES wrapper) and free
vibration (SLEPc shift-and-invert), with modes classified by their kinetic energy.

The unknowns are the increments from the reference, w = (u, d2 − e2, d3 − e3), one blocked
P_k vector field of size 9, so w = 0 is the reference and a clamp is w = 0 at the start.
"""

import time
from dataclasses import dataclass, field

import numpy as np
import ufl

from ..analyses.discretisation import discretise
from ..geometry import Line
from ..geometry.frames import frame_from_tangent
from ..physics.kinematics import d_ds
from ..physics.sections import rectangle
from ..solvers.forms import compile_form
from ..spec import Beam, Model
from . import model as forms

KINDS = ("axial", "bending", "torsion", "section")


@dataclass(frozen=True)
class ContinuumSpec:
    """A straight beam from ``start`` to ``end`` with a rectangular section (``h`` along the
    section axis e3, ``w`` along e2, beamfx's convention; e3 is global z made normal to the
    axis, as in :func:`beamfx.geometry.frames.default_reference`).

    ``clamped``: clamp the start (r, d2, d3 fixed). ``force``, ``moment``: end load in global
    axes; ``follower``: the couple turns with the end section (else it acts in the reference
    section axes, the linear/dead case). ``variant`` one of :data:`model.VARIANTS`.
    """

    E: float
    nu: float
    rho: float
    h: float
    w: float
    start: tuple = (0.0, 0.0, 0.0)
    end: tuple = (1.0, 0.0, 0.0)
    elements: int = 4
    degree: int = 3
    variant: str = "corrected"
    clamped: bool = True
    force: tuple = (0.0, 0.0, 0.0)
    moment: tuple = (0.0, 0.0, 0.0)
    follower: bool = False
    axis_quadrature: str = "reduced"  # the axis energy with degree 2p − 1 ("reduced") or 2p
    options: dict = field(default_factory=dict)  # PETSc options for Newton (no prefix)


def beam_model(spec):
    """The :class:`~beamfx.spec.Model` of the same beam for the shared
    discretisation (:func:`~beamfx.analyses.discretisation.discretise`): one beam "b" along
    the line with the rectangle's section and the spec's elements and degree."""
    line = Line(tuple(spec.start), tuple(spec.end))
    G = spec.E / (2 * (1 + spec.nu))
    section = rectangle(spec.E, G, spec.rho, spec.h, spec.w, nu=spec.nu)
    return Model(beams=(Beam("b", line, section, spec.elements, spec.degree),))


def reference_frame(start, end):
    """(t0, e2, e3) of a straight beam: e3 = global z made normal to t0 (x if t0 is along z),
    e2 = e3 × t0 (:func:`beamfx.geometry.frames.frame_from_tangent`, no twist)."""
    t0 = np.subtract(end, start) / np.linalg.norm(np.subtract(end, start))
    return tuple(np.ascontiguousarray(frame_from_tangent(t0).T))


class ContinuumBeam:
    """Mesh, space, forms and clamp of a :class:`ContinuumSpec` (collective)."""

    def __init__(self, spec, comm=None):
        from dolfinx import fem
        from mpi4py import MPI
        from petsc4py import PETSc

        if spec.variant not in forms.VARIANTS:
            raise ValueError(f"variant {spec.variant!r} not allowed; allowed: {forms.VARIANTS}")
        if spec.axis_quadrature not in ("reduced", "full"):
            raise ValueError(f"axis_quadrature {spec.axis_quadrature!r}: 'reduced' or 'full'")
        self.spec, self.comm = spec, comm or MPI.COMM_WORLD
        # the Reissner beam's discretisation of the same beam: mesh, end points, measures
        self.discretisation = d = discretise(beam_model(spec), self.comm, ("b:start", "b:end"))
        self.mesh, p = d.mesh, spec.degree
        m = self.mesh.mesh
        # the exact frame of the straight reference (constants, not the mesh's Λ0)
        self.frame = reference_frame(spec.start, spec.end)
        self.V = fem.VectorFunctionSpace(m, ("Lagrange", p), dim=9)
        self.w = fem.Function(self.V, name="increments")
        # p + 1 Gauss points (exact to 2p) along s; the axis energy with p points if reduced,
        # as the Reissner beam integrates its shear and axial energy (notes §11)
        self.dx = d.dx
        self.dx_axis = d.dx_shear if spec.axis_quadrature == "reduced" else d.dx
        self.load_factor = fem.Constant(m, PETSc.ScalarType(0.0))

        # data as constants: one compiled form per (variant, degree, axis rule, follower)
        def constant(value):
            return fem.Constant(m, np.asarray(value, dtype=PETSc.ScalarType))

        self.data = {k: constant(getattr(spec, k)) for k in ("E", "nu", "rho", "h", "w")}
        self.frame_ufl = [constant(a) for a in self.frame]
        self.force = constant(spec.force)
        self.couple = constant([np.dot(spec.moment, a) for a in self.frame])  # section axes
        self.bcs = []
        if spec.clamped:
            verts = self.mesh.point_tags.find(self.mesh.points["b:start"][0])
            dofs = fem.locate_dofs_topological(self.V, 0, verts)
            self.bcs = [fem.dirichletbc(fem.Function(self.V), dofs)]
        self.F, self.J = self._forms()

    # --- forms -------------------------------------------------------------------------------

    def fields(self, w):
        """(r_s, d2, d3, d2_s, d3_s) of increments ``w`` (UFL), straight reference."""
        t0, e2, e3 = self.frame_ufl
        u, a2, a3 = split(w)
        return t0 + d_ds(u, t0), e2 + a2, e3 + a3, d_ds(a2, t0), d_ds(a3, t0)

    def energy(self):
        """Π_int = ∫ ψ̂ ds, ψ̂ the section-integrated energy of the variant (axis part with
        ``dx_axis``)."""
        d = self.data
        r_s, d2, d3, d2_s, d3_s = self.fields(self.w)

        def strain_at(eta, zeta):
            return forms.green_lagrange(r_s, d2, d3, d2_s, d3_s, eta, zeta)

        axis, rest = forms.section_energy(
            self.spec.variant, strain_at, d["E"], d["nu"], d["h"], d["w"]
        )
        return axis * self.dx_axis + rest * self.dx

    def load_work(self, v):
        """Virtual work of the end load on the test function ``v`` at load factor 1 (a force on
        r and a couple on d2, d3: :func:`model.end_couple_work`; dead: in the reference axes)."""
        _, d2, d3, _, _ = self.fields(self.w)
        if not self.spec.follower:
            d2, d3 = self.frame_ufl[1:]
        v_r, v_d2, v_d3 = split(v)
        h, w = self.data["h"], self.data["w"]
        work = ufl.dot(self.force, v_r)
        work += forms.end_couple_work(self.couple, h, w, d2, d3, v_d2, v_d3)
        return work * self.discretisation.point_measure("b:end")[0]

    def _forms(self):
        v = ufl.TestFunction(self.V)
        F = ufl.derivative(self.energy(), self.w, v) - self.load_factor * self.load_work(v)
        return F, ufl.derivative(F, self.w, ufl.TrialFunction(self.V))

    def mass(self):
        """Consistent mass form of the section kinematics (:func:`model.mass_form`)."""
        d = self.data
        v, dw = ufl.TestFunction(self.V), ufl.TrialFunction(self.V)
        return forms.mass_form(d["rho"], d["h"], d["w"], split(v), split(dw)) * self.dx

    def unknowns(self):
        """Global number of unknowns."""
        return self.V.dofmap.index_map.size_global * self.V.dofmap.index_map_bs

    # --- results -----------------------------------------------------------------------------

    def end_values(self):
        """Position and displacement of the end centroid, the least-squares small rotation of
        its section (θ = J⁻¹∫ρ × (ηΔd2 + ζΔd3) dA, the solid's definition: θ_1 = (I_z Δd2·e3 −
        I_y Δd3·e2)/I_p, θ_2 = Δd3·t0, θ_3 = −Δd2·t0) and the section vectors. Collective."""
        from dolfinx import fem

        if not hasattr(self, "_end_forms"):
            dP = self.discretisation.point_measure("b:end")[0]
            self._end_forms = [compile_form(self.w[i] * dP) for i in range(9)]
        v = np.array([self.comm.allreduce(fem.assemble_scalar(f)) for f in self._end_forms])
        u, a2, a3 = v[:3], v[3:6], v[6:]
        t0, e2, e3 = self.frame
        _, I_y, I_z = forms.section_moments(self.spec.h, self.spec.w)
        theta_local = [(I_z * a2 @ e3 - I_y * a3 @ e2) / (I_y + I_z), a3 @ t0, -(a2 @ t0)]
        theta = theta_local[0] * t0 + theta_local[1] * e2 + theta_local[2] * e3
        X = np.asarray(self.spec.end, float)
        return {
            "position": (X + u).tolist(),
            "displacement": u.tolist(),
            "rotation_vector": theta.tolist(),
            "d2": (e2 + a2).tolist(),
            "d3": (e3 + a3).tolist(),
        }

    # --- solves ------------------------------------------------------------------------------

    def solve_static(self, steps=1, linear=False, log=None):
        """Equilibrium at load factor 1 from the reference; ``linear``: one Newton step at the
        reference (the linear answer: SVK Hessian at w = 0 and the dead load). Returns a dict
        (load steps, Newton iterations, seconds)."""
        from ..solvers import LoadStep, NewtonSolver, SolveFailed, step_load
        from ..solvers.stepping import SavedState

        if linear and self.spec.follower:
            raise ValueError("a linear solve takes the load in the reference axes: follower=False")
        t0 = time.perf_counter()
        # a linearised rotation stretches the section vectors (|d + Δφ t|² = 1 + Δφ²), which
        # the section stiffness EA answers: Newton leaves its quadratic range after large
        # steps and needs 10-25 iterations (docs/continuum.md)
        options = {"snes_atol": 1e-9 * self._load_scale(), "snes_max_it": 50, **self.spec.options}
        if linear:
            options["snes_type"] = "ksponly"
        solver = NewtonSolver(self.F, self.J, self.w, self.bcs, "beamfx_continuum_", options)
        compile_s = time.perf_counter() - t0

        def solve_at(lam):
            self.load_factor.value = lam
            return solver.solve()

        t1 = time.perf_counter()
        if linear:  # one step from w = 0: the residual at the new w is not zero, by design
            report = solve_at(1.0)
            if report.reason != "CONVERGED_ITS":
                raise SolveFailed(f"linear solve failed: {report.reason}")
            history = [LoadStep(1, 1.0, 1, report.residuals, 0)]
        else:
            # no predictor: a secant extrapolation of the section vectors stretches them like
            # a linearised rotation (roll-up: 23 -> 26-36 Newton iterations per step of 45°)
            history = step_load(solve_at, SavedState(self.w), steps=steps, log=log)
        solve_s = time.perf_counter() - t1
        solver.destroy()
        return {
            "load_steps": len(history),
            "newton_iterations": int(sum(h.iterations for h in history)),
            "compile_s": compile_s,
            "solve_s": solve_s,
        }

    def _load_scale(self):
        """A force scale for the absolute residual tolerance: |F| + |M|/√(I_p/A)."""
        s = self.spec
        A, I_y, I_z = forms.section_moments(s.h, s.w)
        return float(np.linalg.norm(s.force) + np.linalg.norm(s.moment) / np.sqrt((I_y + I_z) / A))

    def modes(self, targets, per_target=6):
        """Free vibration about the reference: for each name → (kind, ω_target), the mode of
        that kind (:data:`KINDS`) among the ``per_target`` nearest ω_target² (shift-and-invert
        there, so rigid-body modes at 0 are never reached). Returns ({name: ω}, seconds)."""
        from ..analyses.modal import assemble_pair
        from ..solvers.eigen import frequencies_by_kind

        t = time.perf_counter()
        self.load_factor.value = 0.0
        self.w.x.array[:] = 0.0
        K, M = assemble_pair(compile_form(self.J), compile_form(self.mass()), self.bcs)
        setup_s = time.perf_counter() - t
        kind_forms = self._kind_forms()
        out = frequencies_by_kind(
            K,
            M,
            self.w,
            targets,
            lambda: self._kind(kind_forms),
            per_target,
            "beamfx_continuum_eigen_",
        )
        K.destroy()
        M.destroy()
        return out, {"setup_s": setup_s, "solve_s": time.perf_counter() - t - setup_s}

    def _kind_forms(self):
        """Kinetic-energy shares of a mode w (per unit ρω²/2): axial ρA (u·t0)², bending
        ρA |u_⊥|² + rotary ρ(I_z (Δd2·t0)² + I_y (Δd3·t0)²), torsion ρ I_p θ_1² with
        θ_1 = (I_z Δd2·e3 − I_y Δd3·e2)/I_p, section: the rest of ρ(I_z|Δd2|² + I_y|Δd3|²)."""
        A, I_y, I_z = forms.section_moments(self.data["h"], self.data["w"])
        t0, e2, e3 = self.frame_ufl
        u, a2, a3 = split(self.w)
        ua = ufl.dot(u, t0)
        rotary = I_z * ufl.dot(a2, t0) ** 2 + I_y * ufl.dot(a3, t0) ** 2
        theta1 = (I_z * ufl.dot(a2, e3) - I_y * ufl.dot(a3, e2)) / (I_y + I_z)
        section_total = I_z * ufl.dot(a2, a2) + I_y * ufl.dot(a3, a3)
        parts = {
            "axial": A * ua**2,
            "bending": A * (ufl.dot(u, u) - ua**2) + rotary,
            "torsion": (I_y + I_z) * theta1**2,
            "section": section_total - rotary - (I_y + I_z) * theta1**2,
        }
        return {k: compile_form(e * self.dx) for k, e in parts.items()}

    def _kind(self, kind_forms):
        from dolfinx import fem

        share = {k: self.comm.allreduce(fem.assemble_scalar(f)) for k, f in kind_forms.items()}
        return max(share, key=share.get)


def split(w):
    """(r, d2, d3) parts of a 9-vector field (increments, test or trial function)."""
    return [ufl.as_vector([w[3 * i + j] for j in range(3)]) for i in range(3)]
