"""Reference frames and strain measures of the Simo–Reissner beam (notation: package doc)."""

from dataclasses import dataclass

import ufl

from .rotations import body_rate, rotation


@dataclass(frozen=True)
class Kinematics:
    """What a model includes; the scene builder picks it, nothing else branches on physics.

    ``finite``: total-Lagrangian quaternion rotations, any angle; otherwise small rotations
    (linear Timoshenko) with a rotation-vector field. ``shear`` and ``stretch`` False replace
    the corresponding stiffness by a penalty (shear-rigid, inextensible limits).
    """

    finite: bool = True
    shear: bool = True
    stretch: bool = True

    @property
    def rotation_size(self):
        """Components of the rotation field: quaternion (4) or rotation vector (3)."""
        return 4 if self.finite else 3


def tangent(mesh):
    """Unit tangent t0 = J/|J| of the (curved, P_k) reference centre line."""
    J = ufl.Jacobian(mesh)[:, 0]
    return J / ufl.sqrt(ufl.dot(J, J))


def d_ds(f, t0):
    """Derivative along the centre line: the tangential gradient contracted with t0."""
    return ufl.dot(ufl.grad(f), t0)


def section_frame(t0, reference, twist):
    """Reference frame Λ0 with columns (t0, e2, e3).

    e3 is ``reference`` made normal to t0 (the section's local z, the direction of a rectangle's
    h), e2 = e3 × t0, both then turned by ``twist`` (radians) about t0.
    """
    e3 = reference - ufl.dot(reference, t0) * t0
    e3 = e3 / ufl.sqrt(ufl.dot(e3, e3))
    e2 = ufl.cross(e3, t0)
    c, s = ufl.cos(twist), ufl.sin(twist)
    e2, e3 = c * e2 + s * e3, -s * e2 + c * e3
    return ufl.as_matrix([[t0[i], e2[i], e3[i]] for i in range(3)])


def finite_strains(u, q, t0, Lam0):
    r"""Γ = Λ0ᵀ(Rᵀ(t0 + u') − t0) and K = Λ0ᵀ axial(Rᵀ R') (Simo 1985, eq. 2.6), section axes."""
    R = rotation(q)
    Gamma = Lam0.T * (R.T * (t0 + d_ds(u, t0)) - t0)
    K = Lam0.T * body_rate(q, d_ds(q, t0))
    return Gamma, K


def linear_strains(u, theta, t0, Lam0):
    r"""Small-rotation limit: Γ = Λ0ᵀ(u' + t0 × θ), K = Λ0ᵀ θ' (linear Timoshenko), section axes."""
    return Lam0.T * (d_ds(u, t0) + ufl.cross(t0, theta)), Lam0.T * d_ds(theta, t0)


def strains(kin, u, rot, t0, Lam0):
    """Strains of the chosen kinematics."""
    return (finite_strains if kin.finite else linear_strains)(u, rot, t0, Lam0)


def spatial_virtual_rotation(kin, rot, drot):
    """Virtual rotation δθ in global axes: axial(δR Rᵀ) for quaternions, δθ for small rotations."""
    from .rotations import spatial_rate

    return spatial_rate(rot, drot) if kin.finite else drot


def body_virtual_rotation(kin, rot, drot):
    """Virtual rotation in the rotated (body) axes: axial(Rᵀ δR)."""
    return body_rate(rot, drot) if kin.finite else drot


def section_rotation(kin, rot):
    """Rotation R taking reference section axes to current ones (identity + hat θ if linear)."""
    from .rotations import hat

    return rotation(rot) if kin.finite else ufl.Identity(3) + hat(rot)
