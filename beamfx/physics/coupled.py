r"""Strain and kinetic energy of coupled (6×6 matrix) sections (notation: package doc).

The order of the 6×6 matrices is :mod:`~beamfx.physics.matrix_sections`'s: ε = (Γ, K) in
section axes, and v = (Λᵀ u̇, Λᵀ ω) for the mass. Blocks: C = [[A, B], [Bᵀ, D]],
M = [[m I, −hat(S)], [hat(S), J]] with S = m ξ the first moment of mass (section axes) and J
the inertia about the reference point.

The diagonal sections keep the forms of :mod:`.energy` and :mod:`.inertia` unchanged; these are
the forms of a model with at least one matrix section.
"""

from .inertia import section_frame_now
from .kinematics import displacement, spatial_virtual_rotation


def as_matrix6(f):
    """The 6×6 UFL matrix of a 36-component field (row by row)."""
    import ufl

    return ufl.as_matrix([[f[6 * i + j] for j in range(6)] for i in range(6)])


def blocks(C):
    """The 3×3 blocks (A, B, D) of a 6×6 UFL matrix [[A, B], [Bᵀ, D]]."""
    import ufl

    def block(r, c):
        return ufl.as_matrix([[C[r + i, c + j] for j in range(3)] for i in range(3)])

    return block(0, 0), block(0, 3), block(3, 3)


def strain_energy(Gamma, K, C, dx_shear, dx_bend):
    r"""Π = ½ εᵀ C ε with ε = (Γ, K), split at every point into two positive parts.

    .. math:: ½ (Γ + A^{-1}B K)·A (Γ + A^{-1}B K) + ½ K·(D − B^T A^{-1} B) K,

    the first (the section force N = AΓ + BK, through its compliance A⁻¹) integrated with
    ``dx_shear`` like the shear and axial energy of a diagonal section, the second (the
    Schur complement, the bending stiffness at zero section force) with ``dx_bend``. For
    B = 0 it is :func:`.energy.strain_energy`. The discrete energy stays positive whatever the
    quadrature, and the reduced rule relaxes the thin-beam constraint N/A ≈ 0 in its coupled
    form Γ + A⁻¹BK ≈ 0, which is what locks.
    """
    import ufl

    A, B, D = blocks(C)
    E = ufl.inv(A) * B
    g = Gamma + E * K
    return 0.5 * ufl.dot(g, A * g) * dx_shear + 0.5 * ufl.dot(K, (D - B.T * E) * K) * dx_bend


def strain_bilinear(Gamma_a, K_a, Gamma_b, K_b, C, dx_shear, dx_bend):
    """The symmetric bilinear form of :func:`strain_energy` (its value at a = b is twice the
    energy), split and integrated the same way."""
    import ufl

    A, B, D = blocks(C)
    E = ufl.inv(A) * B
    n = A * (Gamma_a + E * K_a)
    return ufl.dot(n, Gamma_b + E * K_b) * dx_shear + ufl.dot((D - B.T * E) * K_a, K_b) * dx_bend


def resultants(Gamma, K, C):
    """Section force N = AΓ + BK and moment M = BᵀΓ + DK (section axes)."""
    A, B, D = blocks(C)
    return A * Gamma + B * K, B.T * Gamma + D * K


def _section_vector(Lam, a, b):
    """The 6-vector (Λᵀ a, Λᵀ b)."""
    import ufl

    x, y = Lam.T * a, Lam.T * b
    return ufl.as_vector([x[0], x[1], x[2], y[0], y[1], y[2]])


def _check_rotary(rotary):
    if rotary != "full":
        raise ValueError(
            f"rotary inertia {rotary!r}: a matrix section's mass matrix is used whole "
            "(rotary inertia 'full')"
        )


def mass_form(kin, rot, v, dw, M, Lam0, dx, rotary="full"):
    """Mass bilinear form m(v, dw) = ∫ (Λᵀδu, Λᵀδθ)ᵀ M (Λᵀ Δu, Λᵀ Δθ) ds about the
    configuration with rotation ``rot`` (Λ = R Λ0; δθ the spatial virtual rotation), as
    :func:`.inertia.mass_form` with the 6×6 section mass matrix ``M`` (UFL)."""
    import ufl

    _check_rotary(rotary)
    (v_u, v_rot), (du, drot) = v, dw
    Lam = section_frame_now(kin, rot, Lam0)
    a = _section_vector(Lam, displacement(kin, v_u), spatial_virtual_rotation(kin, rot, v_rot))
    b = _section_vector(Lam, displacement(kin, du), spatial_virtual_rotation(kin, rot, drot))
    return ufl.dot(a, M * b) * dx


def kinetic_energy(kin, rot, u_dot, rot_dot, M, Lam0, rotary="full"):
    """Kinetic energy density T = ½ vᵀ M v, v = (Λᵀ u̇, Λᵀ ω) (as
    :func:`.inertia.kinetic_energy`, whose Lagrange equations it shares)."""
    import ufl

    _check_rotary(rotary)
    Lam = section_frame_now(kin, rot, Lam0)
    omega = spatial_virtual_rotation(kin, rot, rot_dot)
    v = _section_vector(Lam, displacement(kin, u_dot), omega)
    return 0.5 * ufl.dot(v, M * v)


def first_moment(kin, rot, Lam0, M):
    """The first moment of mass s = Λ S about the reference point, global axes (S read from
    M's block hat(S) in rows 4-6, columns 1-3)."""
    import ufl

    S = ufl.as_vector([M[5, 1], M[3, 2], M[4, 0]])
    return section_frame_now(kin, rot, Lam0) * S


def spatial_rotary(kin, rot, Lam0, M):
    """Λ J Λᵀ: the rotary inertia about the reference point in global axes (J rows and
    columns 4-6 of M)."""
    import ufl

    J = ufl.as_matrix([[M[3 + i, 3 + j] for j in range(3)] for i in range(3)])
    Lam = section_frame_now(kin, rot, Lam0)
    return Lam * J * Lam.T


def gravity_moment_work(kin, rot, v_rot, Lam0, M, g):
    """Virtual work of gravity ``g`` on the offset mass: g·(δθ × s), s = Λ S; with the
    centre-line term ρA g·δu, the work of m g on the mass centre."""
    import ufl

    s = first_moment(kin, rot, Lam0, M)
    return ufl.dot(g, ufl.cross(spatial_virtual_rotation(kin, rot, v_rot), s))
