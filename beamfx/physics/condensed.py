r"""The statically condensed beam: the rotation field is the only unknown.

In a cantilever under point forces the section force n(s) is the sum of the forces beyond s;
the strains follow from it, Γ = C_N⁻¹ Λ0ᵀ Rᵀ n, and the centre line from the rotations,
x' = R (t0 + Λ0 Γ). Eliminating Γ from the Simo–Reissner energy leaves the bending energy and a
load potential in the rotations alone (:func:`load_potential`): three unknowns per node instead
of seven (3 displacements and a quaternion), the same answer. With the compliance C_N⁻¹ set to
zero it is the inextensible, shear-rigid Kirchhoff rod.

The rotation is parametrised by the rotation vector ψ, R = exp(ψ̂) through the quaternion
(cos(θ/2), sin(θ/2) ψ/θ), θ = |ψ| (a series near θ = 0): a plane bending field is linear in
s, so polynomials represent a roll-up well; valid for angles below 2π, where the map from ψ
to R is singular (:data:`~beamfx.analyses.condensed.MAX_ANGLE`).

In a plane problem the rotation is R(θ) about the plane's normal n (:func:`plane_rotation`)
and the angle θ(s) is the only unknown, one per node, valid at any angle: the curvature is
K = Λ0ᵀ n θ' (:func:`plane_curvature`), linear in θ, so a pure end moment (n = 0) leaves the
quadratic energy ½ EI θ'² − M θ(L), whose Galerkin solution on P_k (k ≥ 1) is the exact
θ = M s / EI. The functions below take the rotation matrix R, so that both parametrisations
share them.
"""

from .kinematics import d_ds
from .rotations import body_rate, spatial_rate


def rotation_quaternion(psi):
    """Unit quaternion (cos(θ/2), sin(θ/2) ψ/θ) of the rotation vector ψ, θ = |ψ|; the Taylor
    series of both factors below θ² = 1e-6 (error O(θ⁶), no 0/0)."""
    import ufl

    tt = ufl.dot(psi, psi)
    theta = ufl.sqrt(tt + 1e-300)
    small = ufl.lt(tt, 1e-6)
    c = ufl.conditional(small, 1 - tt / 8 + tt**2 / 384, ufl.cos(theta / 2))
    s = ufl.conditional(small, 0.5 - tt / 48 + tt**2 / 3840, ufl.sin(theta / 2) / theta)
    return ufl.as_vector([c, s * psi[0], s * psi[1], s * psi[2]])


def curvature(g, t0, Lam0):
    """K = Λ0ᵀ axial(Rᵀ R') (section axes), as :func:`~beamfx.physics.kinematics.finite_strains`."""
    import ufl

    q = rotation_quaternion(g)
    dq = ufl.as_vector([d_ds(q[i], t0) for i in range(4)])
    return Lam0.T * body_rate(q, dq)


def virtual_rotation(g, dg, spatial=True):
    """δθ of a variation ``dg``: axial(δR Rᵀ) (global axes) or axial(Rᵀ δR) (body axes)."""
    import ufl

    q = rotation_quaternion(g)
    dq = ufl.derivative(q, g, dg)
    return spatial_rate(q, dq) if spatial else body_rate(q, dq)


def plane_rotation(theta, normal):
    """R(θ) = I + sin θ N + (1 − cos θ) N², N = hat(normal): the rotation by the angle θ about
    the plane's unit normal (global axes), valid at any angle (no 2π limit)."""
    import ufl

    from .rotations import hat

    N = hat(normal)
    return ufl.Identity(3) + ufl.sin(theta) * N + (1 - ufl.cos(theta)) * N * N


def plane_curvature(theta, normal, t0, Lam0):
    """K = Λ0ᵀ n θ' (section axes): axial(RᵀR') = n θ' for a rotation about a fixed n."""
    return Lam0.T * normal * d_ds(theta, t0)


def section_strains(R, n, Lam0, compliance):
    """Γ = C_N⁻¹ Λ0ᵀ Rᵀ n: the strains that the section force n (global axes) causes in the
    section rotated by R."""
    return compliance * (Lam0.T * (R.T * n))


def position_rate(R, n, t0, Lam0, compliance):
    """Centre-line tangent x' = R (t0 + Λ0 Γ) with Γ from the section force ``n``."""
    return R * (t0 + Lam0 * section_strains(R, n, Lam0, compliance))


def load_potential(R, n, t0, Lam0, compliance, dx):
    r"""∫ n·(R − I) t0 ds + ½ ∫ Γ·C_N Γ ds with Γ = C_N⁻¹ Λ0ᵀ Rᵀ n; ``R`` the rotation field
    (UFL matrix, of the rotation vector or of the plane angle).

    For a statically determinate beam (a cantilever under point forces) n(s) is the sum of
    the forces beyond s. The Simo–Reissner energy ½ K·C_M K + ½ Γ·C_N Γ − Σ F·u(s_a), with
    u(s_a) = ∫₀^{s_a} (R(t0 + Λ0 Γ) − t0) ds, is stationary in Γ at C_N Γ = Λ0ᵀ Rᵀ n; putting
    that Γ back leaves ½ K·C_M K minus this potential: the same equilibrium with the
    rotations as the only unknowns (exact, not an approximation: shear and stretch are kept).
    With the compliance zero it is the Kirchhoff rod's −Σ F·u(s_a).
    """
    import ufl

    Gamma = section_strains(R, n, Lam0, compliance)
    return (ufl.dot(n, (R - ufl.Identity(3)) * t0) + 0.5 * ufl.dot(Gamma, Lam0.T * (R.T * n))) * dx


def bending_energy(K, C_M, dx):
    """½ K·C_M K of the curvature K (section axes): the whole strain energy of the Kirchhoff
    rod."""
    import ufl

    return 0.5 * ufl.dot(K, C_M * K) * dx
