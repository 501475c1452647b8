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
"""

import ufl

from .kinematics import displacement, section_rotation, spatial_virtual_rotation

#: rotary inertia kept, as weights on (polar, about y, about z): "polar" keeps only the
#: torsional inertia (the Euler-Bernoulli model of bending), "none" drops it all
ROTARY = {"full": (1.0, 1.0, 1.0), "polar": (1.0, 0.0, 0.0), "none": (0.0, 0.0, 0.0)}


def section_frame_now(kin, rot, Lam0):
    """Current section frame Λ = R Λ0 (Λ0 for the linear kinematics, linearised about it)."""
    return section_rotation(kin, rot) * Lam0 if kin.finite else Lam0


def spatial_inertia(kin, rot, Lam0, rho_I, rotary="full"):
    """Rotary inertia in global axes, Λ diag(ρI) Λᵀ, with the weights of :data:`ROTARY`."""
    c = ROTARY[rotary]
    J = ufl.diag(ufl.as_vector([c[i] * rho_I[i] for i in range(3)]))
    Lam = section_frame_now(kin, rot, Lam0)
    return Lam * J * Lam.T


def mass_form(kin, rot, v, dw, inertia, Lam0, dx, rotary="full"):
    """Mass bilinear form m(v, dw) about the configuration with rotation field ``rot``.

    Args:
        v, dw: (displacement, rotation) pairs of the test and trial functions.
        inertia: (ρA, ρI_polar, ρI_y, ρI_z) per point, section axes.
        rotary: one of :data:`ROTARY`.
    """
    (v_u, v_rot), (du, drot) = v, dw
    m = inertia[0] * ufl.dot(displacement(kin, du), displacement(kin, v_u))
    if rotary != "none":
        J = spatial_inertia(kin, rot, Lam0, [inertia[1], inertia[2], inertia[3]], rotary)
        th_v = spatial_virtual_rotation(kin, rot, v_rot)
        th_d = spatial_virtual_rotation(kin, rot, drot)
        m += ufl.dot(th_v, J * th_d)
    return m * dx
