"""Strain energy and the virtual work of loads (notation: package doc)."""

import ufl

from .kinematics import body_virtual_rotation, section_rotation, spatial_virtual_rotation


def strain_energy(Gamma, K, C_N, C_M, dx_shear, dx_bend):
    r"""Π = ½ Γ·C_N Γ + ½ K·C_M K (Simo 1985, eq. 2.12).

    The shear/axial part is integrated with one Gauss point fewer (``dx_shear``, exact to
    degree 2p−1): with full integration the quadratic element locks in thin-beam bending.
    """
    return 0.5 * ufl.dot(Gamma, C_N * Gamma) * dx_shear + 0.5 * ufl.dot(K, C_M * K) * dx_bend


def quaternion_penalty(q, k_p, dx):
    r"""½ k_p (|q|² − 1)²: fixes the norm of q, which R(q) and K do not see."""
    return 0.5 * k_p * (ufl.dot(q, q) - 1) ** 2 * dx


def force_work(kin, rot, v_u, force, follower):
    """Virtual work of a force (global axes); a follower force is R·force (turns with the section)."""
    f = section_rotation(kin, rot) * force if follower else force
    return ufl.dot(f, v_u)


def moment_work(kin, rot, v_rot, moment, follower):
    """Virtual work of a moment: M·δθ (fixed in space, global axes) or M0·Rᵀδθ (follower).

    The fixed-axis moment is not conservative for finite 3D rotations; its tangent is
    unsymmetric and the solvers use LU, which does not mind.
    """
    if follower:
        return ufl.dot(moment, body_virtual_rotation(kin, rot, v_rot))
    return ufl.dot(moment, spatial_virtual_rotation(kin, rot, v_rot))


def spring_energy(u, k):
    """½ u·diag(k) u of a translational spring to ground (k per global axis)."""
    return 0.5 * ufl.dot(u, ufl.diag(ufl.as_vector(k)) * u)


def load_work(kin, rot, v_u, v_rot, force, moment, follower):
    """Virtual work of a force and a moment, both dead or both follower."""
    return force_work(kin, rot, v_u, force, follower) + moment_work(
        kin, rot, v_rot, moment, follower
    )
