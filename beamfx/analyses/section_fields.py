"""Section fields of a model with matrix (6×6) sections.

A model with at least one :class:`~beamfx.physics.matrix_sections.MatrixSection` holds every
beam's section as 6×6 stiffness and mass matrices (a geometric section as its diagonal
matrices, ``Section.matrices``): DG_p fields of 36 components where a section varies along a
beam, DG0 otherwise, sampled at the DG interpolation points. The stiffness is checked positive
definite at those points and at the Gauss points of both quadrature rules of the model (the DG_p
interpolant of the station tables need not stay between the stations' values inside a cell
that spans a station).
"""

from typing import NamedTuple

import numpy as np
from mpi4py import MPI

from ..physics.matrix_sections import MatrixSection, section_matrices, with_limits


class SectionMatrices(NamedTuple):
    """The 6×6 section matrices of a model with a matrix section (UFL, section axes, the order
    of :mod:`~beamfx.physics.matrix_sections`)."""

    C: object  #: stiffness
    M: object  #: mass, about the reference line


def is_coupled(spec):
    """Whether the model ``spec`` has a matrix section (and so the coupled forms)."""
    return any(isinstance(b.section, MatrixSection) for b in spec.beams)


def dg_points(q):
    """Interpolation points of DG_q (equispaced) on [0, 1], in basix's order."""
    return np.r_[0.0, 1.0, np.arange(1, q) / q] if q else np.array([0.5])


def lagrange_matrix(nodes, points):
    """L[k, i]: the Lagrange polynomial of ``nodes[i]`` at ``points[k]``."""
    nodes, points = np.asarray(nodes, float), np.asarray(points, float)
    L = np.ones((len(points), len(nodes)))
    for i, xi in enumerate(nodes):
        for j, xj in enumerate(nodes):
            if j != i:
                L[:, i] *= (points - xj) / (xi - xj)
    return L


def gauss_points(n):
    """The n Gauss–Legendre points on [0, 1]."""
    return 0.5 * (np.polynomial.legendre.leggauss(n)[0] + 1.0)


def _check_definite(C, S, beam_of_cell, names, degree, comm):
    """Raise (on every rank) if a stiffness matrix is not positive definite at the DG points or
    at the Gauss points of the p- and (p+1)-point rules. Collective."""
    n_nodes = C.shape[1]
    nodes = dg_points(n_nodes - 1 if n_nodes > 1 else 0)
    points = np.r_[gauss_points(degree), gauss_points(degree + 1)]
    L = lagrange_matrix(nodes, points) if n_nodes > 1 else np.ones((len(points), 1))
    Cq = np.einsum("ki,ciab->ckab", L, C)
    Sq = np.einsum("ki,ci->ck", L, S) if n_nodes > 1 else np.repeat(S, len(points), 1)
    smallest = np.linalg.eigvalsh(Cq).min(axis=2) if len(Cq) else np.zeros((0, len(points)))
    scale = np.abs(Cq).max(axis=(2, 3)) if len(Cq) else smallest
    bad = np.argwhere(~(smallest > 1e-12 * scale))
    first = (bad[0][0], bad[0][1]) if len(bad) else None
    report = (
        (names[beam_of_cell[first[0]]], float(Sq[first]), float(smallest[first])) if first else None
    )
    reports = [r for r in comm.allgather(report) if r is not None]
    if reports:
        name, s, value = reports[0]
        raise ValueError(
            f"beams {name!r}: the section stiffness is not positive definite at s = {s:.6g} "
            f"(smallest eigenvalue {value:.6g}); with station tables, put a station where the "
            "matrices change fast or use more elements"
        )


def matrix_fields(spec, mesh, comm, cell_arc_lengths, cell_field):
    """(stiffness, inertia, raw_max, C, M) of a model with matrix sections.

    ``stiffness`` (6) and ``inertia`` (4: ρA and the diagonal of J) hold the diagonals that the
    rest of beamfx reads (support penalties, gravity, mass checks); ``C`` and ``M`` are the 36
    components of the 6×6 matrices; ``raw_max`` the largest diagonal of the force block before
    the shear-rigid/inextensible limits (all ranks). ``cell_arc_lengths(X)`` and
    ``cell_field(degree, values)`` are the discretisation's.
    """
    kin, beams, cb = spec.kinematics, spec.beams, mesh.cell_beam
    q = mesh.degree if any(b.section.varies for b in beams) else 0
    X = dg_points(q)
    S = cell_arc_lengths(X)
    C = np.zeros((len(cb), len(X), 6, 6))
    M = np.zeros((len(cb), len(X), 6, 6))
    raw_max = 0.0
    for i, b in enumerate(beams):
        sel = cb == i
        s = S[sel].ravel() if np.any(sel) else np.zeros(1)
        Ci, Mi = section_matrices(b.section, s)
        raw_max = max(raw_max, float(np.max(np.diagonal(Ci, axis1=1, axis2=2)[:, :3])))
        Ci = with_limits(Ci, not kin.shear, not kin.stretch, b.curve.length)
        n = np.count_nonzero(sel)
        C[sel] = Ci.reshape(-1, len(X), 6, 6)[:n]
        M[sel] = Mi.reshape(-1, len(X), 6, 6)[:n]
    if not (np.all(np.isfinite(C)) and np.all(np.isfinite(M))):
        raise ValueError("a section matrix is not finite somewhere along a beam")
    _check_definite(C, S, cb, [b.name for b in beams], mesh.degree, comm)
    diag_C = np.diagonal(C, axis1=2, axis2=3)
    diag_M = np.diagonal(M, axis1=2, axis2=3)[:, :, 2:]
    raw_max = comm.allreduce(raw_max, op=MPI.MAX)
    return (
        cell_field(q, diag_C),
        cell_field(q, diag_M),
        raw_max,
        cell_field(q, C.reshape(len(cb), len(X), 36)),
        cell_field(q, M.reshape(len(cb), len(X), 36)),
    )


def section_kinetic_energy(kin, rot, u_dot, rot_dot, d, rotary="full"):
    """Kinetic energy density of the sections of the discretisation ``d``: the diagonal
    :func:`~beamfx.physics.inertia.kinetic_energy`, or the coupled one with matrix sections."""
    from ..physics import coupled
    from ..physics.inertia import kinetic_energy

    if d.matrices is None:
        return kinetic_energy(kin, rot, u_dot, rot_dot, d.inertia, d.Lam0, rotary)
    return coupled.kinetic_energy(kin, rot, u_dot, rot_dot, d.matrices.M, d.Lam0, rotary)


def offset_inertia(model, rot, rotary):
    """(Λ J Λᵀ, Λ S) of a model with matrix sections: the rotary inertia about the reference
    line and the first moment of mass, global axes (``rotary`` must be "full")."""
    from ..physics import coupled

    d = model.discretisation
    if rotary != "full":
        raise ValueError(f"rotary inertia {rotary!r}: a matrix section needs 'full'")
    M = d.matrices.M
    return (
        coupled.spatial_rotary(model.kin, rot, d.Lam0, M),
        coupled.first_moment(model.kin, rot, d.Lam0, M),
    )
