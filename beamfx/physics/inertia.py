r"""Inertia of the beam: the mass form linearised about a configuration (notation: package doc).

The kinetic energy of a section is :math:`T = ½ ρA\,\dot u\cdot\dot u + ½ ω\cdot Λ J Λ^T ω`
(Simo & Vu-Quoc 1988, eq. 2.10) with ω the spatial angular velocity, Λ = R Λ0 the current section
frame and J = diag(ρI_polar, ρI_y, ρI_z) the section inertia (section axes). About a
configuration (u, q) a small motion has ω = axial(δR Rᵀ)˙, so the mass form is

.. math:: m(δw, Δw) = ∫ ρA\,δu\cdot Δu + δθ\cdot Λ J Λ^T Δθ \, ds,
   \qquad δθ = \mathrm{axial}(δR\,R^T)

For quaternions δθ = 2 Im(δq q̄)/|q|² vanishes for δq ∥ q: the norm direction of q carries no
mass, and the penalty on |q| is its only stiffness, so it sits at infinite frequency (a massless
dof is condensed out by the eigen solver) and never among the lowest modes.

A rigid body at a point (mass m, rotary inertia J0 about the point in global axes of the
reference state) adds T = ½ m u̇·u̇ + ½ ω·R J0 Rᵀ ω there: it turns with the section.
"""

import numpy as np

from .kinematics import displacement, section_rotation, spatial_virtual_rotation

#: rotary inertia kept, as weights on (polar, about y, about z): "polar" keeps only the
#: torsional inertia (the Euler-Bernoulli model of bending), "none" drops it all
ROTARY = {"full": (1.0, 1.0, 1.0), "polar": (1.0, 0.0, 0.0), "none": (0.0, 0.0, 0.0)}


def section_frame_now(kin, rot, Lam0):
    """Current section frame Λ = R Λ0 (Λ0 for the linear kinematics, linearised about it)."""
    return section_rotation(kin, rot) * Lam0 if kin.finite else Lam0


def spatial_inertia(kin, rot, Lam0, rho_I, rotary="full"):
    """Rotary inertia in global axes, Λ diag(ρI) Λᵀ, with the weights of :data:`ROTARY`."""
    import ufl

    c = ROTARY[rotary]
    J = ufl.diag(ufl.as_vector([c[i] * rho_I[i] for i in range(3)]))
    Lam = section_frame_now(kin, rot, Lam0)
    return Lam * J * Lam.T


def mass_form(kin, rot, v, dw, inertia, Lam0, dx, rotary="full"):
    """Mass bilinear form m(v, dw) about the configuration with rotation field ``rot``.

    Args:
        kin: the kinematics options of the model.
        rot: rotation field of the configuration.
        v: (displacement, rotation) pair of the test functions.
        dw: (displacement, rotation) pair of the trial functions.
        inertia: (ρA, ρI_polar, ρI_y, ρI_z) per point, section axes.
        Lam0: reference section frame Λ0 (columns: section axes in global axes).
        dx: integration measure along the centre line.
        rotary: one of :data:`ROTARY`.
    """
    import ufl

    (v_u, v_rot), (du, drot) = v, dw
    m = inertia[0] * ufl.dot(displacement(kin, du), displacement(kin, v_u))
    if rotary != "none":
        J = spatial_inertia(kin, rot, Lam0, [inertia[1], inertia[2], inertia[3]], rotary)
        th_v = spatial_virtual_rotation(kin, rot, v_rot)
        th_d = spatial_virtual_rotation(kin, rot, drot)
        m += ufl.dot(th_v, J * th_d)
    return m * dx


def angular_velocity(kin, rot, rot_dot):
    """Spatial angular velocity ω = axial(Ṙ Rᵀ) (global axes) of the rotation field at the rate
    ``rot_dot``: 2 Im(q̇ q̄)/|q|² for quaternions, θ̇ (linear), φ̇ n (planar)."""
    return spatial_virtual_rotation(kin, rot, rot_dot)


def kinetic_energy(kin, rot, u_dot, rot_dot, inertia, Lam0, rotary="full"):
    r"""Kinetic energy density T = ½ ρA |u̇|² + ½ ω·Λ J Λᵀ ω (Simo & Vu-Quoc 1988, eq. 2.10).

    Written in the generalized coordinates (u, q) and their rates, so that the Lagrange
    equations d/dt ∂T/∂q̇ − ∂T/∂q contain the gyroscopic term ω × Jω consistently with the
    quaternion parametrisation (its norm direction carries no kinetic energy: ω does not see
    q̇ ∥ q). ``inertia`` and ``rotary`` as in :func:`mass_form`.
    """
    import ufl

    u3 = displacement(kin, u_dot)
    T = 0.5 * inertia[0] * ufl.dot(u3, u3)
    if rotary != "none":
        J = spatial_inertia(kin, rot, Lam0, [inertia[1], inertia[2], inertia[3]], rotary)
        omega = angular_velocity(kin, rot, rot_dot)
        T += 0.5 * ufl.dot(omega, J * omega)
    return T


def _inertia_matrix(inertia):
    """J0 as a 3x3 NumPy array from a 3x3 nested sequence or a diagonal of three."""
    J0 = np.asarray(inertia, dtype=float)
    return np.diag(J0) if J0.shape == (3,) else J0


def point_inertia(kin, rot, inertia):
    """Rotary inertia of a point mass in global axes, R J0 Rᵀ: ``inertia`` J0 (3x3, or its
    diagonal; global axes in the reference state) turns with the section (J0 itself for the
    linear kinematics)."""
    import ufl

    J0 = ufl.as_matrix(_inertia_matrix(inertia).tolist())
    if not kin.finite:
        return J0
    R = section_rotation(kin, rot)
    return R * J0 * R.T


def point_mass_form(kin, rot, v, dw, mass, inertia):
    """Integrand of the mass form of a rigid body at a point, about the current rotation:
    m δu·Δu + δθ·(R J0 Rᵀ) Δθ with δθ = axial(δR Rᵀ) (the point form of :func:`mass_form`).

    Args:
        kin: the kinematics options of the model.
        rot: rotation field of the current configuration.
        v: (displacement, rotation) pair of the test functions.
        dw: (displacement, rotation) pair of the trial functions.
        mass: m.
        inertia: J0 about the point (3x3, global axes in the reference state).
    """
    import ufl

    (v_u, v_rot), (du, drot) = v, dw
    m = float(mass) * ufl.dot(displacement(kin, du), displacement(kin, v_u))
    if np.any(_inertia_matrix(inertia)):
        th_v = spatial_virtual_rotation(kin, rot, v_rot)
        th_d = spatial_virtual_rotation(kin, rot, drot)
        m += ufl.dot(th_v, point_inertia(kin, rot, inertia) * th_d)
    return m


def point_kinetic_energy(kin, rot, u_dot3, omega, mass, inertia):
    r"""Kinetic energy of a rigid body at a point: T = ½ m |u̇|² + ½ ω·(R J0 Rᵀ) ω.

    Args:
        kin: the kinematics options of the model.
        rot: rotation field of the current configuration.
        u_dot3: velocity of the point (3-vector, global axes).
        omega: spatial angular velocity ω = axial(Ṙ Rᵀ) (3-vector, global axes).
        mass: m.
        inertia: J0 about the point (3x3, global axes in the reference state).
    """
    import ufl

    T = 0.5 * float(mass) * ufl.dot(u_dot3, u_dot3)
    if np.any(_inertia_matrix(inertia)):
        T += 0.5 * ufl.dot(omega, point_inertia(kin, rot, inertia) * omega)
    return T
