r"""Beams on a hub spinning at constant speed: steady state and vibration in the rotating frame.

The frame turns at Ω = speed · axis about an axis through the hub point; the kinetic energy of
:mod:`beamfx.physics.rotating` gives

* the steady state (relative equilibrium): stationary total potential Π + V_c, solved by
  :func:`~beamfx.analyses.static.solve_static` with V_c scaled by the model's load factor, so
  that the load steps are steps in Ω²;
* small motions about it: (λ² M + λ G + K_T) v = 0, K_T the tangent of Π + V_c (elastic,
  geometric and spin-softening stiffness), G the gyroscopic matrix from the rate-linear part of
  the kinetic energy, M the mass form about the steady state. A stable mode has λ = ±iω; a
  real λ > 0 is a divergence (the steady state is unstable).

Everything is in the axes of the rotating frame. The scene's other loads are fixed in that
frame and scaled with the same load factor. Rotary inertia is "full" or "none": the polar part
alone (the "polar" of :data:`beamfx.physics.inertia.ROTARY`) is no model of a spinning section, whose centrifugal
moment needs all three inertias (for a tilted section it is ρI_y, not ρI_polar, that acts).
"""

import time
from typing import NamedTuple

import numpy as np
import ufl

from ..physics.inertia import point_inertia, spatial_inertia
from ..physics.kinematics import displacement, spatial_virtual_rotation
from ..physics.rotating import centrifugal_potential, gyroscopic_covector, relative_position
from ..solvers.eigen_shell import solve_quadratic_massless
from ..solvers.forms import compile_form
from ..solvers.quadratic import solve_quadratic
from .dofs import owned_size, subspace_dofs
from .mixed import owned_force_dofs
from .modal import mass_ufl
from .rotating_path import solve_steady  # noqa: F401  (re-exported: its home is rotating_path)
from .section_fields import offset_inertia

ROTARY = ("full", "none")


class RotatingFrame:
    """The forms of a :class:`~beamfx.analyses.model.BeamModel` in a frame spinning about
    ``axis`` (global, any length) through ``hub`` (a point), at a speed set by
    :meth:`set_speed` (rad/s, positive counter-clockwise about ``axis``).

    Attributes: ``F``, ``J`` (residual and tangent with the centrifugal potential, scaled by
    the model's load factor), ``G`` (gyroscopic), ``M`` (mass), ``omega`` and ``hub``
    (``fem.Constant``). The scene's point masses take part like the sections (a point mass
    keeps its rotary inertia whatever ``rotary`` says, as in the mass form).
    """

    def __init__(self, model, axis=(0.0, 0.0, 1.0), hub=(0.0, 0.0, 0.0), rotary="full"):
        from dolfinx import fem
        from petsc4py import PETSc

        if not model.kin.finite:
            raise ValueError(
                "a rotating beam needs finite kinematics: the centrifugal stiffening is the "
                "geometric stiffness of the tension"
            )
        if rotary not in ROTARY:
            raise ValueError(f"rotary inertia {rotary!r} is not allowed; allowed: {ROTARY}")
        axis = np.asarray(axis, float)
        if not np.linalg.norm(axis) > 0:
            raise ValueError("the rotation axis must not be zero")
        self.model, self.rotary = model, rotary
        self.axis = axis / np.linalg.norm(axis)
        self.speed = 0.0
        m = model.mesh.mesh
        self.omega = fem.Constant(m, PETSc.ScalarType((0.0, 0.0, 0.0)))
        self.hub = fem.Constant(m, PETSc.ScalarType(tuple(float(x) for x in hub)))

        kin, w = model.kin, model.w
        test, trial = ufl.TestFunction(model.W), ufl.TrialFunction(model.W)
        (u, rot), (v_u, v_rot) = ufl.split(w)[:2], ufl.split(test)[:2]
        r = relative_position(ufl.SpatialCoordinate(m), displacement(kin, u), self.hub)
        d = model.discretisation
        rho_A = d.inertia[0]
        rho_I = [d.inertia[i] for i in (1, 2, 3)]
        J = spatial_inertia(kin, rot, d.Lam0, rho_I) if rotary == "full" else ufl.zero((3, 3))
        s = None  # first moment of an offset mass centre (matrix sections)
        if d.matrices is not None:
            J, s = offset_inertia(model, rot, rotary)
        v_u3, v_theta = displacement(kin, v_u), spatial_virtual_rotation(kin, rot, v_rot)

        def point_J(pm):
            return point_inertia(kin, rot, pm.inertia)

        V_c = centrifugal_potential(rho_A, J, self.omega, r, s) * d.dx
        V_c += d.point_mass_terms(
            lambda pm: centrifugal_potential(float(pm.mass), point_J(pm), self.omega, r)
        )
        self.F = model.F + model.load_factor * ufl.derivative(V_c, w, test)
        self.J = ufl.derivative(self.F, w, trial)
        a = gyroscopic_covector(rho_A, J, self.omega, r, v_u3, v_theta, s) * d.dx
        a += d.point_mass_terms(
            lambda pm: gyroscopic_covector(
                float(pm.mass), point_J(pm), self.omega, r, v_u3, v_theta
            )
        )
        A = ufl.derivative(a, w, trial)
        self.G = A - ufl.adjoint(A)
        self.M = mass_ufl(model, rotary)
        self._compiled = None
        self._newton = {}
        self._stretch = None

    def set_speed(self, speed):
        """Spin at ``speed`` rad/s about the axis."""
        self.speed = float(speed)
        self.omega.value[:] = self.speed * self.axis

    def compiled(self):
        """The compiled (K, G, M) forms (compiled once)."""
        if self._compiled is None:
            self._compiled = tuple(compile_form(f) for f in (self.J, self.G, self.M))
        return self._compiled

    def min_stretch(self):
        """Smallest axial stretch 1 + Γ₁ (current over reference length of the centre line) at
        p + 2 points of every element. Collective."""
        from dolfinx import fem
        from mpi4py import MPI

        from ..physics.kinematics import strains
        from ..solvers.forms import JIT_PARAMS

        model = self.model
        if self._stretch is None:
            u, rot = ufl.split(model.w)[:2]
            d = model.discretisation
            Gamma, _ = strains(model.kin, u, rot, d.t0, d.Lam0)
            points = np.linspace(0.0, 1.0, model.degree + 2)[:, None]
            self._stretch = fem.Expression(1 + Gamma[0], points, jit_params=JIT_PARAMS)
        n = model.mesh.mesh.topology.index_map(1).size_local
        values = self._stretch.eval(np.arange(n, dtype=np.int32))
        return model.comm.allreduce(float(np.min(values, initial=np.inf)), op=MPI.MIN)

    def destroy(self):
        """Free the PETSc objects of the Newton solvers."""
        for solver in self._newton.values():
            solver.destroy()
        self._newton = {}

    def newton(self, prefix, options=None):
        """A Newton solver on (F, J), one per prefix and options, kept for later speeds."""
        from ..solvers import NewtonSolver

        key = (prefix, tuple(sorted((options or {}).items())))
        if key not in self._newton:
            m = self.model
            self._newton[key] = NewtonSolver(self.F, self.J, m.w, m.bcs, prefix, options)
        return self._newton[key]


class RotatingModes(NamedTuple):
    """Complex modes about a steady rotating state: eigenvalues, frequencies (rad/s, Hz), growth."""

    eigenvalues: np.ndarray  # λ (1/s) with Im λ ≥ 0, lowest |Im λ| first
    omega: np.ndarray  # rad/s, |Im λ|: the frequency seen in the rotating frame
    hz: np.ndarray
    growth: np.ndarray  # Re λ (1/s): > 0 grows (divergence if ω = 0, flutter otherwise)
    vectors: tuple  # complex NumPy arrays (locally owned dofs of model.W)
    residuals: np.ndarray
    seconds: dict


def assemble_mass(frame):
    """M about the current state, zero on the constrained rows (for MAC and energies)."""
    import dolfinx.fem.petsc as fp

    M = fp.assemble_matrix(frame.compiled()[2], bcs=frame.model.bcs, diagonal=0.0)
    M.assemble()
    return M


def assemble_operators(frame):
    """K (identity on constrained rows), G and M (zero there), about the current state."""
    import dolfinx.fem.petsc as fp

    K_form, G_form, M_form = frame.compiled()
    bcs = frame.model.bcs
    K = fp.assemble_matrix(K_form, bcs=bcs, diagonal=1.0)
    K.assemble()
    G = fp.assemble_matrix(G_form, bcs=bcs, diagonal=0.0)
    G.assemble()
    M = fp.assemble_matrix(M_form, bcs=bcs, diagonal=0.0)
    M.assemble()
    return K, G, M


def solve_quadratic_of(model, K, G, M, nev, prefix, options=None):
    """(λ² M + λ G + K) x = 0 nearest 0 for ``model``: SLEPc's TOAR in the displacement
    form; in the mixed form the companion form with the force unknowns kept out of the Krylov
    space (:mod:`beamfx.solvers.eigen_shell`: TOAR misses frequencies there by up to 4e-1,
    its Krylov space holding the nearly defective infinite eigenvalues of the forces)."""
    massless = owned_force_dofs(model)
    if massless is None:
        return solve_quadratic(K, G, M, nev, 0.0, prefix, options)
    return solve_quadratic_massless(K, G, M, nev, prefix, massless, options)


def solve_rotating_modes(frame, n_modes=6, options=None, prefix="beamfx_rotating_"):
    """The ``n_modes`` lowest-frequency modes about the current (steady) state at the frame's
    speed: (λ² M + λ G + K_T) v = 0 by SLEPc PEP (TOAR, shift-and-invert at 0), or in the
    mixed form by :func:`solve_quadratic_of`.

    Each mode is reported once, as its λ with Im λ ≥ 0 (the conjugate is dropped); of a real
    pair ±σ the positive one. The model must be at load factor 1 (:func:`solve_steady`).
    """
    t0 = time.perf_counter()
    if frame.speed != 0.0 and abs(float(frame.model.load_factor.value) - 1.0) > 1e-9:
        raise ValueError("solve the steady state first (the model is not at load factor 1)")
    frame.compiled()
    t1 = time.perf_counter()
    K, G, M = assemble_operators(frame)
    t2 = time.perf_counter()
    pairs = solve_quadratic_of(frame.model, K, G, M, 2 * n_modes + 2, prefix, options)
    for A in (K, G, M):
        A.destroy()
    keep = []
    for i, lam in enumerate(pairs.values):
        real = abs(lam.imag) <= 1e-8 * abs(lam)
        if (real and lam.real >= 0) or (not real and lam.imag > 0):
            keep.append(i)
    keep.sort(key=lambda i: (abs(pairs.values[i].imag), -pairs.values[i].real))
    keep = keep[:n_modes]
    if len(keep) < n_modes:
        from ..solvers.snes import SolveFailed

        raise SolveFailed(
            f"eigen solve ({prefix}): only {len(keep)} of {n_modes} modes found among "
            f"{len(pairs.values)} eigenvalues; cause: eigen solve; remedy: ask for fewer modes",
            cause="eigen solve",
            remedy="ask for fewer modes ([analysis] modes)",
            details={"requested": n_modes, "converged": len(keep)},
        )
    lam = pairs.values[keep]
    omega = np.abs(lam.imag)
    return RotatingModes(
        lam,
        omega,
        omega / (2 * np.pi),
        lam.real,
        tuple(pairs.vectors[i][0] + 1j * pairs.vectors[i][1] for i in keep),
        pairs.residuals[keep],
        {"compile": t1 - t0, "assemble": t2 - t1, "solve": pairs.seconds},
    )


def mac_matrix(M, first, second):
    r"""MAC_ij = |a_iᴴ M b_j|² / ((a_iᴴ M a_i)(b_jᴴ M b_j)) of two lists of complex vectors
    (locally owned parts), with the PETSc matrix M. Collective."""
    comm = M.getComm().tompi4py()
    x, y = M.createVecs()

    def times_M(v):
        out = []
        for part in (v.real, v.imag):
            x.setArray(part)
            M.mult(x, y)
            out.append(y.getArray().copy())
        return out[0] + 1j * out[1]

    Mb = [times_M(b) for b in second]
    Ma = [times_M(a) for a in first]
    x.destroy()
    y.destroy()
    cross = np.array([[np.vdot(a, mb) for mb in Mb] for a in first])
    na = np.array([np.vdot(a, ma).real for a, ma in zip(first, Ma)])
    nb = np.array([np.vdot(b, mb).real for b, mb in zip(second, Mb)])
    cross, na, nb = (comm.allreduce(v) for v in (cross, na, nb))
    return np.abs(cross) ** 2 / np.outer(na, nb)


def axis_fraction(model, vector, axis):
    """Share of a mode's displacement amplitude along ``axis``: Σ|u·e|² / Σ|u|² over the
    displacement nodes (1: out of the rotation plane, 0: in it). Collective."""
    n_owned = owned_size(model.W)
    comps = []
    for i in range(model.kin.displacement_size):
        dofs = subspace_dofs(model.W, 0, i)
        comps.append(vector[dofs[dofs < n_owned]])
    if model.kin.plane:
        from ..physics.kinematics import PLANES

        a, b, _ = PLANES[model.kin.plane]
        u = np.zeros((len(comps[0]), 3), complex)
        u[:, a], u[:, b] = comps
    else:
        u = np.stack(comps, axis=1)
    along = float(np.sum(np.abs(u @ axis) ** 2))
    total = float(np.sum(np.abs(u) ** 2))
    comm = model.comm
    along, total = comm.allreduce(along), comm.allreduce(total)
    return along / total if total > 0 else 0.0
