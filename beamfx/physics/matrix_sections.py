r"""Sections as 6×6 stiffness and mass matrices (coupled sections, BeamDyn's kind of input).

Order and frame (beamfx): the sectional strains ε = (Γ1, Γ2, Γ3, K1, K2, K3) in the section
axes (x along the reference line, y and z in the section): extension, shear along y, shear
along z, torsion, bending about y, bending about z. The reference point is the section origin
on the beam's reference line. A diagonal matrix is (EA, GA_y, GA_z, GJ, EI_y, EI_z). The
strain energy per length is ½ εᵀ C ε; the kinetic energy per length is ½ vᵀ M v with
v = (Λᵀ u̇, Λᵀ ω) the velocity of the reference point and the angular velocity in section axes.

BeamDyn orders its matrices (ε1, ε2, ε3, κ1, κ2, κ3) with the axis along x3 (shear 1, shear 2,
extension, bending about x1, bending about x2, torsion). Its (x1, x2, x3) are beamfx's
(y, z, x) (a cyclic permutation: both right-handed), so index i of beamfx is index
:data:`BEAMDYN_INDEX` [i] of BeamDyn: (3, 1, 2, 6, 4, 5) counted from 1.

Offsets (the standard transformations, e.g. Hodges 2006, §4.4): the strain of a fibre at
ρ = (0, y, z) is ε(ρ) = T(ρ) ε with T(ρ) = [[I, −hat(ρ)], [0, I]] (Γ + K × ρ). The extension
and bending stiffnesses (EA, EI_y, EI_z) act at the tension (elastic) centre ρ_t, the shear and
torsion stiffnesses (GA_y, GA_z, GJ) at the shear centre ρ_s:
C = T(ρ_t)ᵀ diag(EA, 0, 0, 0, EI_y, EI_z) T(ρ_t) + T(ρ_s)ᵀ diag(0, GA_y, GA_z, GJ, 0, 0) T(ρ_s).
A mass m with its centre at ξ = (0, y_m, z_m) and inertia J_c about it (section axes) has
M = [[m I, −m hat(ξ)], [m hat(ξ), J_c + m (|ξ|² I − ξ ξᵀ)]] about the reference point.
"""

from dataclasses import dataclass

import numpy as np

#: beamfx index i is BeamDyn index BEAMDYN_INDEX[i] (0-based)
BEAMDYN_INDEX = (2, 0, 1, 5, 3, 4)


def from_beamdyn(matrix):
    """A 6×6 matrix in BeamDyn's order and axes, in beamfx's (see the module doc)."""
    p = list(BEAMDYN_INDEX)
    return np.asarray(matrix, float)[np.ix_(p, p)]


def to_beamdyn(matrix):
    """The inverse of :func:`from_beamdyn`."""
    p = np.argsort(BEAMDYN_INDEX)
    return np.asarray(matrix, float)[np.ix_(p, p)]


def hat(a):
    """The 3×3 skew matrix of ``a``, whose product with b is a × b."""
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def fibre_transform(y, z):
    """T(ρ) with ε(ρ) = T(ρ) ε: the strains of the fibre at (0, y, z) from the section's."""
    T = np.eye(6)
    T[:3, 3:] = -hat([0.0, y, z])
    return T


def offset_stiffness(EA, GA_y, GA_z, GJ, EI_y, EI_z, tension=(0.0, 0.0), shear=(0.0, 0.0)):
    """The coupled 6×6 stiffness about the reference point of a section whose extension and
    bending act at the tension centre ``tension`` = (y, z) and shear and torsion at the shear
    centre ``shear`` (module doc)."""
    Tt, Ts = fibre_transform(*tension), fibre_transform(*shear)
    return (
        Tt.T @ np.diag([EA, 0, 0, 0, EI_y, EI_z]) @ Tt
        + Ts.T @ np.diag([0, GA_y, GA_z, GJ, 0, 0]) @ Ts
    )


def offset_mass(m, inertia, centre=(0.0, 0.0)):
    """The 6×6 mass matrix about the reference point of a mass per length ``m`` with its centre
    at ``centre`` = (y, z) and ``inertia`` about that centre (3×3, or its diagonal: polar,
    about y, about z; section axes)."""
    J = np.asarray(inertia, float)
    J = np.diag(J) if J.shape == (3,) else J
    xi = np.array([0.0, *centre])
    M = np.zeros((6, 6))
    M[:3, :3] = m * np.eye(3)
    M[3:, :3] = m * hat(xi)
    M[:3, 3:] = -m * hat(xi)
    M[3:, 3:] = J + m * (xi @ xi * np.eye(3) - np.outer(xi, xi))
    return M


def check_stiffness(C):
    """Raise ValueError unless C is a finite, symmetric, positive definite 6×6 matrix."""
    C = _square(C)
    smallest = np.linalg.eigvalsh(C).min()
    if not smallest > 1e-12 * np.abs(C).max():
        raise ValueError(f"is not positive definite (smallest eigenvalue {smallest:.6g})")
    return C


def check_mass(M):
    """Raise ValueError unless M is a finite, symmetric, positive semi-definite 6×6 matrix
    with the translational block m I and a skew translation–rotation block (a rigid section's
    mass, module doc)."""
    M = _square(M)
    scale = max(np.abs(M).max(), 1e-300)
    m = M[0, 0]
    if np.abs(M[:3, :3] - m * np.eye(3)).max() > 1e-9 * scale:
        raise ValueError("has a translational block (rows and columns 1-3) that is not m·I")
    if np.abs(M[:3, 3:] + M[:3, 3:].T).max() > 1e-9 * scale:
        raise ValueError(
            "has a translation-rotation block (rows 1-3, columns 4-6) that is not skew"
        )
    smallest = np.linalg.eigvalsh(M).min()
    if smallest < -1e-10 * scale:
        raise ValueError(f"is not positive semi-definite (smallest eigenvalue {smallest:.6g})")
    return M


def _square(A):
    A = np.asarray(A, float)
    if A.shape != (6, 6):
        raise ValueError(f"must be 6×6, got the shape {A.shape}")
    if not np.all(np.isfinite(A)):
        raise ValueError("has an entry that is not finite")
    if np.abs(A - A.T).max() > 1e-9 * np.abs(A).max():
        i, j = np.unravel_index(np.argmax(np.abs(A - A.T)), A.shape)
        raise ValueError(
            f"is not symmetric: entry ({i + 1}, {j + 1}) differs from ({j + 1}, {i + 1})"
        )
    return 0.5 * (A + A.T)


@dataclass(frozen=True, eq=False)
class MatrixSection:
    """A section given by its 6×6 stiffness and mass matrices (beamfx order, module doc).

    ``stations`` are fractions s/L of the beam length (increasing, from 0 to 1) with one
    matrix each in ``stiffness`` and ``mass`` (n, 6, 6); between stations the matrices are
    interpolated linearly, entry by entry (a convex combination of positive definite matrices
    is positive definite, so the interpolant is too). One station: a prismatic beam.
    ``vertices_at_stations``: the mesh gets a vertex at each inner station, so that the
    degree-p section fields hold the piecewise linear table exactly.
    """

    stiffness: np.ndarray
    mass: np.ndarray
    stations: tuple = (0.0,)
    length: float = 1.0
    vertices_at_stations: bool = False

    def station_breaks(self):
        """Arc lengths of the inner stations where the mesh needs vertices (none unless
        ``vertices_at_stations``)."""
        if not self.vertices_at_stations:
            return []
        return [x * self.length for x in self.stations[1:-1]]

    def __post_init__(self):
        for name in ("stiffness", "mass"):
            object.__setattr__(self, name, np.asarray(getattr(self, name), float).reshape(-1, 6, 6))
        if len(self.stiffness) != len(self.stations) or len(self.mass) != len(self.stations):
            raise ValueError("one stiffness and one mass matrix per station")

    shape = ()  # no geometric shape (pictures and the solid need one)

    def along(self, s):
        """The section at arc lengths ``s`` (itself: :meth:`matrices_at` gives the values)."""
        return [self] * len(s)

    @property
    def varies(self):
        """Whether the matrices vary along the beam (more than one station)."""
        return len(self.stations) > 1

    def matrices_at(self, s):
        """(C, M): the stiffness and mass matrices at arc lengths ``s``, (len(s), 6, 6) each."""
        x = np.clip(np.asarray(s, float) / self.length, 0.0, 1.0)
        if not self.varies:
            return (np.repeat(self.stiffness, len(x), 0), np.repeat(self.mass, len(x), 0))
        st = np.asarray(self.stations)
        i = np.clip(np.searchsorted(st, x, side="right") - 1, 0, len(st) - 2)
        a = ((x - st[i]) / (st[i + 1] - st[i]))[:, None, None]
        return tuple((1 - a) * A[i] + a * A[i + 1] for A in (self.stiffness, self.mass))


def section_matrices(section, s):
    """(C, M) of any section (:class:`MatrixSection`, ``Section``, ``SectionAlong``) at arc
    lengths ``s``: (len(s), 6, 6) each."""
    if isinstance(section, MatrixSection):
        return section.matrices_at(s)
    pairs = [x.matrices() for x in section.along(np.asarray(s, float))]
    return np.array([p[0] for p in pairs]), np.array([p[1] for p in pairs])


def with_limits(C, shear_rigid=False, inextensible=False, length=1.0, factor=1e8):
    """The stiffness matrices C (n, 6, 6) with the shear and/or axial diagonal raised to the
    penalty of ``Section.with_limits`` (factor · largest bending or torsion stiffness / L²)."""
    C = np.array(C, float)
    big = factor * np.max(np.diagonal(C, axis1=1, axis2=2)[:, 3:], axis=1) / length**2
    for i in [1, 2] * shear_rigid + [0] * inextensible:
        C[:, i, i] = np.maximum(C[:, i, i], big)
    return C
