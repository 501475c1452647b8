"""The discretisation of a beam model that every formulation shares: mesh, named points,
section fields, reference frames and measures; everything but the unknowns and the energy.

:func:`discretise` builds it once from a :class:`~beamfx.spec.Model`. The full and
planar :class:`~beamfx.analyses.model.BeamModel` and the statically condensed
:class:`~beamfx.analyses.condensed.CondensedModel` compose one (``model.discretisation``), so a
scene gives the same mesh, frames and section data whichever formulation solves it. The
continuum beam (:mod:`beamfx.continuum.solve`) takes its mesh, end points and measures from it.

Section data per cell: the stiffnesses (EA, GA_y, GA_z, GJ, EI_y, EI_z) and inertias
(ρA, ρI_1, ρI_2, ρI_3) are DG_p fields where a section varies along a beam and DG0 otherwise;
the reference vector is DG0, the twist DG0 unless it varies along a beam (then DG_p). The measures integrate the shear and axial energy
with p Gauss points (``dx_shear``, exact to degree 2p − 1: the locking remedy) and the rest
with p + 1 (``dx``, exact to 2p).
"""

import weakref
from dataclasses import dataclass
from functools import partial
from typing import NamedTuple

import numpy as np
import ufl
from mpi4py import MPI

from ..geometry import BeamSpec, build_mesh
from ..geometry.frames import default_reference
from ..physics import coupled, energy
from ..physics.coupled import as_matrix6
from ..physics.kinematics import section_frame, tangent
from .checks import named_breaks
from .section_fields import SectionMatrices, dg_points, is_coupled, matrix_fields

#: mesh -> {(degree, size): weak reference to the DG space on it} (weak both ways: a space
#: refers to its mesh, and lives as long as a field on it)
_dg_spaces = weakref.WeakKeyDictionary()


def dg_space(mesh, degree, size):
    """The DG ``degree`` space (scalar if ``size`` is 1, else ``size`` components) on ``mesh``:
    one per mesh, element and size, shared by the cell fields on it (section fields, twist,
    tangent signs, indicators; each space costs a JIT look-up and a dofmap)."""
    from dolfinx import fem

    spaces = _dg_spaces.setdefault(mesh, {})
    known = spaces.get((degree, size))
    V = known() if known else None
    if V is None:
        cell = mesh.ufl_cell()
        if size == 1:
            element = ufl.FiniteElement("DG", cell, degree, variant="equispaced")
        else:
            element = ufl.VectorElement("DG", cell, degree, dim=size, variant="equispaced")
        V = fem.FunctionSpace(mesh, element)
        spaces[degree, size] = weakref.ref(V)
    return V


def cell_field(mesh, degree, values):
    """A DG ``degree`` Function with values (n_cells, points, size) at the interpolation points
    of each local cell (scalar if size is 1, and then values may be (n_cells, points)), on the
    mesh's shared space (:func:`dg_space`)."""
    from dolfinx import fem

    values = np.asarray(values, float)
    size = 1 if values.ndim == 2 else values.shape[2]
    V = dg_space(mesh, degree, size)
    f = fem.Function(V)
    n_points = values.shape[1]
    dofs = V.dofmap.list.array.reshape(-1, n_points)[: len(values)]
    f.x.array.reshape(-1, size)[dofs.ravel()] = values.reshape(-1, size)
    return f


def cell_function(mesh, values):
    """A DG0 Function (scalar or vector) with the given per-local-cell values."""
    values = np.asarray(values, float)
    return cell_field(mesh, 0, values[:, None])


def beam_cells(cell_beam, n_beams):
    """(i, local cells of beam i in ascending order) for every beam i that has local cells:
    one sort instead of a comparison of all cells per beam (O(N²) on a frame of 10⁵ members).
    Beams without local cells are left out."""
    cell_beam = np.asarray(cell_beam)
    order = np.argsort(cell_beam, kind="stable")
    bounds = np.searchsorted(cell_beam[order], np.arange(n_beams + 1))
    return [(i, order[bounds[i] : bounds[i + 1]]) for i in np.flatnonzero(np.diff(bounds)).tolist()]


def cell_arc_lengths(spec, mesh, X):
    """Arc length of the reference points ``X`` (in [0, 1]) of each local cell of ``mesh`` (a
    :class:`~beamfx.geometry.BeamMesh` of the beams of ``spec``): (n_cells, len(X))."""
    m, spans = mesh.mesh, mesh.cell_span
    n = len(spans)
    nodes = m.geometry.dofmap.array.reshape(-1, mesh.degree + 1)[:n]
    x0 = m.geometry.x[nodes[:, 0]]
    flipped = np.zeros(n, bool)  # DOLFINx may reverse a cell: its vertex 0 is then at s_b
    for i, sel in beam_cells(mesh.cell_beam[:n], len(spec.beams)):
        b = spec.beams[i]
        if len(sel):
            at_a = np.linalg.norm(x0[sel] - b.curve.points(spans[sel, 0]), axis=1)
            at_b = np.linalg.norm(x0[sel] - b.curve.points(spans[sel, 1]), axis=1)
            flipped[sel] = at_b < at_a
    s0 = np.where(flipped, spans[:, 1], spans[:, 0])
    s1 = np.where(flipped, spans[:, 0], spans[:, 1])
    return s0[:, None] + np.asarray(X)[None, :] * (s1 - s0)[:, None]


def _section_fields(spec, mesh, comm):
    """Stiffness (EA, GA_y, GA_z, GJ, EI_y, EI_z) and inertia (rho_A, rho_I) fields, the
    shear-rigid/inextensible limits of ``spec.kinematics`` applied; and the largest EA or GA
    before the limits (over all ranks). The inertia field as a :class:`Deferred` (its values
    computed, its space made at first use)."""
    kin, beams, cb = spec.kinematics, spec.beams, mesh.cell_beam
    varies = any(b.section.varies for b in beams)
    q = mesh.degree if varies else 0
    X = np.r_[0.0, 1.0, np.arange(1, q) / q] if q else np.array([0.5])  # basix DG order
    S = cell_arc_lengths(spec, mesh, X)
    stiff = np.zeros((len(cb), len(X), 6))
    mass = np.zeros((len(cb), len(X), 4))
    raw_max, rows = 0.0, _section_rows(kin)
    local = dict(beam_cells(cb, len(beams)))
    for i, b in enumerate(beams):
        sel = local.get(i)
        samples = b.section.along(S[sel].ravel() if sel is not None else [0.0])
        distinct = {id(x): x for x in samples}.values()
        raw_max = max(raw_max, max(max(x.EA, x.GA_y, x.GA_z) for x in distinct))
        if sel is None:
            continue
        k, m = zip(*(rows(x, b.curve.length) for x in samples))
        stiff[sel] = np.array(k).reshape(-1, len(X), 6)[: len(sel)]
        mass[sel] = np.array(m).reshape(-1, len(X), 4)[: len(sel)]
    if np.any(stiff <= 0):
        raise ValueError("a section stiffness is not positive somewhere along a beam")
    raw_max = comm.allreduce(raw_max, op=MPI.MAX)
    m = mesh.mesh
    return cell_field(m, q, stiff), Deferred(partial(cell_field, m, q, mass)), raw_max


def _section_rows(kin):
    """``rows(section, length)``: the section's stiffnesses with the limits of ``kin`` (for a
    beam of that length) and its inertias, computed once per section and length (a frame's
    members share a few section objects; each section is kept, so its id is not reused)."""
    known = {}

    def rows(x, length):
        key = (id(x), length)
        if key not in known:
            limited = x.with_limits(not kin.shear, not kin.stretch, length)
            known[key] = (x, limited.stiffnesses(), x.inertias())
        return known[key][1:]

    return rows


def _twist_field(spec, mesh):
    """The twist (radians): DG0 if every beam's is a number, else DG_p at the interpolation
    points (a twist varying along a beam, sampled pointwise like the sections)."""
    twists = [b.twist_deg for b in spec.beams]
    cb, m = mesh.cell_beam, mesh.mesh
    if not any(callable(t) for t in twists):
        return cell_function(m, np.deg2rad([twists[b] for b in cb]))
    return cell_field(m, mesh.degree, np.deg2rad(along_beams(spec, mesh, twists)))


def along_beams(spec, mesh, per_beam):
    """Values at the DG_p interpolation points of each local cell: ``per_beam[i]`` (a number,
    or a vectorised function of the arc length s along beam i) on the cells of beam i."""
    S = cell_arc_lengths(spec, mesh, dg_points(mesh.degree))
    values = np.zeros_like(S)
    for i, sel in beam_cells(mesh.cell_beam[: len(S)], len(per_beam)):
        t = per_beam[i]
        values[sel] = np.asarray(t(S[sel]), float) if callable(t) else t
    return values


def _cell_tangents(mesh):
    """Unit chord of each local cell, from its vertex 0 to its vertex 1."""
    m = mesh.mesh
    nodes = m.geometry.dofmap.array.reshape(-1, mesh.degree + 1)[: len(mesh.cell_beam)]
    d = m.geometry.x[nodes[:, 1]] - m.geometry.x[nodes[:, 0]]
    return d / np.maximum(np.linalg.norm(d, axis=1)[:, None], 1e-300)


def _beam_mesh(spec, comm, degree, extra_points):
    """Named points (every 'at' of supports, loads, springs, masses and ``extra_points``) as
    {at: (beam, s, xyz)} and the mesh with a vertex at each of them and at T-joints."""
    named, breaks = named_breaks(spec, extra_points)
    specs = [
        BeamSpec(b.name, b.curve, b.elements, tuple(breaks[i])) for i, b in enumerate(spec.beams)
    ]
    points = {at: xyz for at, (_, _, xyz) in named.items()}
    return named, build_mesh(comm, specs, degree, points)


def discretise(spec, comm=MPI.COMM_WORLD, extra_points=()):
    """The :class:`Discretisation` of the model ``spec``. Collective.

    Args:
        spec: :class:`~beamfx.spec.Model`; its kinematics' ``shear`` and ``stretch``
            decide the section limits (the other kinematic options do not enter).
        comm: MPI communicator.
        extra_points: names (``beam:where``) that must be mesh vertices too (probes).
    """
    from ..solvers.forms import remember_loaded_modules

    # before the first space of the process: each element's JIT look-up lists the cache folder
    remember_loaded_modules()
    # one DOLFINx mesh holds one element type: every beam gets the highest degree asked for
    p = max(b.degree for b in spec.beams)
    named, mesh = _beam_mesh(spec, comm, p, extra_points)
    m, cb = mesh.mesh, mesh.cell_beam
    matrices = None
    if is_coupled(spec):
        *fields, C6, M6 = matrix_fields(
            spec,
            mesh,
            comm,
            lambda X: cell_arc_lengths(spec, mesh, X),
            lambda q, values: cell_field(m, q, values),
        )
        stiffness, inertia, raw_max = fields
        matrices = SectionMatrices(as_matrix6(C6), as_matrix6(M6))
    else:
        stiffness, inertia, raw_max = _section_fields(spec, mesh, comm)
    ref = default_reference(_cell_tangents(mesh))
    for i, sel in beam_cells(cb[: len(ref)], len(spec.beams)):
        if spec.beams[i].orientation is not None:
            ref[sel] = spec.beams[i].orientation
    reference = cell_function(m, ref)
    twist = _twist_field(spec, mesh)
    t0 = tangent(m)
    C = stiffness
    return Discretisation(
        spec=spec,
        comm=comm,
        mesh=mesh,
        degree=p,
        raised_degree=[b.name for b in spec.beams if b.degree < p],
        named=named,
        stiffness=stiffness,
        mass=inertia,
        stiffness_scale=raw_max,
        reference=reference,
        twist=twist,
        t0=t0,
        Lam0=section_frame(t0, reference, twist),
        C_N=ufl.diag(ufl.as_vector([C[0], C[1], C[2]])),
        C_M=ufl.diag(ufl.as_vector([C[3], C[4], C[5]])),
        dx_shear=ufl.dx(domain=m, metadata={"quadrature_degree": 2 * p - 1}),
        dx=ufl.dx(domain=m, metadata={"quadrature_degree": 2 * p}),
        matrices=matrices,
    )


class Deferred(NamedTuple):
    """A field made when first read: ``make()`` returns it (collective)."""

    make: object


@dataclass(frozen=True, eq=False)
class Discretisation:
    """Mesh, named points, section fields, frames and measures of a model (:func:`discretise`).

    UFL members are expressions of the reference configuration; vectors are in global axes
    and Λ0 maps section axes to global ones (columns t0, e2, e3).
    """

    spec: object  #: the :class:`~beamfx.spec.Model` discretised
    comm: object  #: MPI communicator
    mesh: object  #: :class:`~beamfx.geometry.BeamMesh` (P_degree geometry, named point tags)
    degree: int  #: polynomial degree of the geometry and of every field on it
    raised_degree: list  #: names of the beams raised to ``degree`` (one degree per mesh)
    named: dict  #: {point name: (beam index, arc length, xyz)} of every vertex-named point
    stiffness: object  #: DG Function (EA, GA_y, GA_z, GJ, EI_y, EI_z), limits applied
    mass: object  #: the :attr:`inertia` Function, or a :class:`Deferred` that makes it
    stiffness_scale: float  #: largest EA, GA_y or GA_z before the limits (all ranks)
    reference: object  #: DG0 Function: orientation vector of each cell (global axes)
    twist: object  #: DG0 Function: twist of each cell (radians); DG_p if it varies along a beam
    t0: object  #: UFL unit tangent of the reference centre line
    Lam0: object  #: UFL reference section frame Λ0 (columns t0, e2, e3)
    C_N: object  #: UFL diag(EA, GA_y, GA_z)
    C_M: object  #: UFL diag(GJ, EI_y, EI_z)
    dx_shear: object  #: measure of the shear and axial energy (degree 2p − 1)
    dx: object  #: measure of everything else (degree 2p)
    matrices: object = None  #: :class:`SectionMatrices`, or None: every section is diagonal

    @property
    def inertia(self):
        """DG Function (ρA, ρI_1, ρI_2, ρI_3), made at first use where deferred (a static
        analysis reads no inertia, and its space costs a JIT look-up and a dofmap). Collective
        at that first use, which every rank makes (mass checks, mass forms, gravity)."""
        if isinstance(self.mass, Deferred):
            object.__setattr__(self, "mass", self.mass.make())
        return self.mass

    def strain_energy(self, Gamma, K, scale=None, dx=None):
        """The strain energy of the sections (times ``scale``, e.g. a damping time, if given):
        :func:`~beamfx.physics.energy.strain_energy` with C_N, C_M for diagonal sections, the
        coupled form :func:`~beamfx.physics.coupled.strain_energy` with a matrix section.
        ``dx``: one measure for both parts (else ``dx_shear`` and ``dx``)."""
        dx_shear, dx_bend = (self.dx_shear, self.dx) if dx is None else (dx, dx)
        if self.matrices is None:
            if scale is None:
                return energy.strain_energy(Gamma, K, self.C_N, self.C_M, dx_shear, dx_bend)
            return energy.strain_rate_dissipation(
                Gamma, K, self.C_N, self.C_M, scale, dx_shear, dx_bend
            )
        C = self.matrices.C if scale is None else scale * self.matrices.C
        return coupled.strain_energy(Gamma, K, C, dx_shear, dx_bend)

    def resultants(self, Gamma, K):
        """Section force and moment (N, M) of the strains (Γ, K), section axes."""
        if self.matrices is None:
            return self.C_N * Gamma, self.C_M * K
        return coupled.resultants(Gamma, K, self.matrices.C)

    def cell_arc_lengths(self, X):
        """Arc length of the reference points ``X`` (in [0, 1]) of each local cell."""
        return cell_arc_lengths(self.spec, self.mesh, X)

    def cell_function(self, values):
        """A DG0 Function with the given per-local-cell values (:func:`cell_function`)."""
        return cell_function(self.mesh.mesh, values)

    def beam_indicator(self, beam_index):
        """DG0 Function: 1 on the cells of one beam, 0 elsewhere."""
        per_beam = [1.0 if i == beam_index else 0.0 for i in range(len(self.spec.beams))]
        return self.cell_function(np.asarray(per_beam, float)[self.mesh.cell_beam])

    def beam_profile(self, beam_index, f):
        """DG_p Function: f(s) at the interpolation points of the cells of one beam (s the arc
        length along it), 0 elsewhere."""
        per_beam = [f if i == beam_index else 0.0 for i in range(len(self.spec.beams))]
        values = along_beams(self.spec, self.mesh, per_beam)
        return cell_field(self.mesh.mesh, self.mesh.degree, values)

    def min_cell_length(self):
        """Shortest cell, in arc length (all ranks). Collective."""
        return self.comm.allreduce(np.min(np.diff(self.mesh.cell_span, axis=1)), op=MPI.MIN)

    def point_measure(self, at):
        """``ds`` at an end vertex, ``dS`` (with '+' restriction) at an inner vertex: the
        measure of the named point ``at`` and its restriction (None or "+"). Collective.

        Raises:
            ValueError: if more than two elements meet at the point.
        """
        tag, m = self.mesh.points[at][0], self.mesh.mesh
        n = self.elements_at(at)
        if n > 2:
            raise ValueError(
                f"{at!r} joins {n} elements: only dead forces (and moments of linear or planar "
                "kinematics) can act there, no springs, masses or other loads"
            )
        if n == 2:
            return ufl.dS(domain=m, subdomain_data=self.mesh.point_tags)(tag), "+"
        return ufl.ds(domain=m, subdomain_data=self.mesh.point_tags)(tag), None

    def elements_at(self, at):
        """Number of elements that meet at the named point ``at`` (all ranks). Collective."""
        m = self.mesh.mesh
        m.topology.create_connectivity(0, 1)
        c = m.topology.connectivity(0, 1)
        vertices = self.mesh.point_tags.find(self.mesh.points[at][0])
        return self.comm.allreduce(max([len(c.links(v)) for v in vertices], default=0), MPI.MAX)

    def at_point(self, at, integrand, cell_exact=False):
        """``integrand`` integrated at the named point (restricted there if it is inside).

        ``cell_exact``: the integrand is linear in the test function with coefficients that
        are constant on a cell (a dead force); where more than two elements meet (a joint of a
        frame, where no facet measure reaches) it is then integrated exactly on one of them,
        weighted by the density of :func:`~beamfx.analyses.joints.joint_density`.
        """
        if cell_exact and self.elements_at(at) > 2:
            from .joints import joint_density

            psi = cell_field(self.mesh.mesh, self.degree, joint_density(self, at))
            return integrand * psi * self.dx
        dP, side = self.point_measure(at)
        return (integrand(side) if side else integrand) * dP

    def joint_load_density(self, loads):
        """One DG_p vector field ψ-weighted sum of the point values at joints: Σ_i ψ_i(x) f_i,
        ψ_i the density of :func:`~beamfx.analyses.joints.joint_density` at ``loads[i] = (at,
        f)`` (f a 3-vector). ``(ψ_i f_i)·v dx`` summed in one field is the same work as the
        terms one by one, up to round-off (the sum of the nodal values), but costs one field
        and one form term instead of one per load (O(loads × cells) in build and assembly)."""
        from .joints import joint_cells

        m, p = self.mesh.mesh, self.degree
        n_cells = m.topology.index_map(1).size_local + m.topology.index_map(1).num_ghosts
        values = np.zeros((n_cells, p + 1, 3))
        for at, f in loads:
            for c, row in joint_cells(self, at):
                values[c] += np.outer(row, np.asarray(f, float))
        return cell_field(m, p, values)

    def point_mass_terms(self, integrand):
        """Σ over the scene's point masses of ``integrand(point_mass)`` (UFL) at its point; 0 if
        there are none. E.g. the mass form with :func:`~beamfx.physics.inertia.point_mass_form`,
        or the kinetic energy with :func:`~beamfx.physics.inertia.point_kinetic_energy`."""
        return sum((self.at_point(pm.at, integrand(pm)) for pm in self.spec.point_masses), start=0)


class Discretised:
    """The shorthands of :class:`~beamfx.analyses.formulation.Formulation` for a class with a
    ``discretisation``: ``comm``, ``mesh`` and ``degree`` are the discretisation's."""

    discretisation: Discretisation

    @property
    def comm(self):
        """MPI communicator (``discretisation.comm``)."""
        return self.discretisation.comm

    @property
    def mesh(self):
        """:class:`~beamfx.geometry.BeamMesh` (``discretisation.mesh``)."""
        return self.discretisation.mesh

    @property
    def degree(self):
        """Polynomial degree of the fields (``discretisation.degree``)."""
        return self.discretisation.degree
