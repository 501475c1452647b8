"""Reference frames and strain measures of the Simo–Reissner beam (notation: package doc)."""

from dataclasses import dataclass

from .rotations import body_rate, rotation


@dataclass(frozen=True)
class Kinematics:
    """What a model includes; the scene builder picks it, nothing else branches on physics.

    ``finite``: total-Lagrangian quaternion rotations, any angle; otherwise small rotations
    (linear Timoshenko) with a rotation-vector field. ``shear`` and ``stretch`` False replace
    the corresponding stiffness by a penalty (shear-rigid, inextensible limits). ``plane``
    ("xy", "yz" or "xz") is the planar model: two in-plane displacements and one rotation angle
    about the plane's normal (plane rotations commute, so one angle is exact at any size).
    """

    finite: bool = True
    shear: bool = True
    stretch: bool = True
    plane: str | None = None

    @property
    def rotation_size(self):
        """Components of the rotation field: quaternion (4), rotation vector (3), angle (1)."""
        return 1 if self.plane else 4 if self.finite else 3

    @property
    def displacement_size(self):
        """Displacement components at a node: 2 in a plane, else 3."""
        return 2 if self.plane else 3

    @property
    def output_rotation_size(self):
        """Components of :func:`rotation_output`: a quaternion for finite rotations, else θ."""
        return 4 if self.finite else 3

    def dofs(self):
        """(global dof name, subspace, component) of each unknown scalar at a node."""
        if not self.plane:
            return [(n, 0, i) for i, n in enumerate(("ux", "uy", "uz"))] + [
                (n, 1, i) for i, n in enumerate(("rx", "ry", "rz")[: self.rotation_size])
            ]
        a, b, n = PLANES[self.plane]
        names = "xyz"
        return [(f"u{names[a]}", 0, 0), (f"u{names[b]}", 0, 1), (f"r{names[n]}", 1, 0)]


#: plane -> (axis of in-plane component 0, of component 1, normal); (a, b, normal) right-handed
PLANES = {"xy": (0, 1, 2), "yz": (1, 2, 0), "xz": (2, 0, 1)}


def plane_normal(kin):
    """Unit normal of the plane of a planar model (global axes)."""
    import ufl

    return ufl.as_vector([1.0 if i == PLANES[kin.plane][2] else 0.0 for i in range(3)])


def displacement(kin, u):
    """The displacement field (or a test function of it) as a 3-vector in global axes."""
    import ufl

    if not kin.plane:
        return u
    a, b, _ = PLANES[kin.plane]
    comps = [0.0, 0.0, 0.0]
    comps[a], comps[b] = u[0], u[1]
    return ufl.as_vector(comps)


def tangent(mesh):
    """Unit tangent t0 = J/|J| of the (curved, P_k) reference centre line."""
    import ufl

    J = ufl.Jacobian(mesh)[:, 0]
    return J / ufl.sqrt(ufl.dot(J, J))


def d_ds(f, t0):
    """Derivative along the centre line: the tangential gradient contracted with t0."""
    import ufl

    return ufl.dot(ufl.grad(f), t0)


def section_frame(t0, reference, twist):
    """Reference frame Λ0 with columns (t0, e2, e3).

    e3 is ``reference`` made normal to t0 (the section's local z, the direction of a rectangle's
    h), e2 = e3 × t0, both then turned by ``twist`` (radians) about t0.
    """
    import ufl

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
    import ufl

    return Lam0.T * (d_ds(u, t0) + ufl.cross(t0, theta)), Lam0.T * d_ds(theta, t0)


def planar_strains(kin, u, angle, t0, Lam0):
    r"""Plane model: Γ as in :func:`finite_strains` (or :func:`linear_strains`) with R the
    rotation by ``angle`` about the normal n, and K = Λ0ᵀ n φ' (exact: R n = n)."""
    import ufl

    n = plane_normal(kin)
    u3 = displacement(kin, u)
    if kin.finite:
        Gamma = Lam0.T * (section_rotation(kin, angle).T * (t0 + d_ds(u3, t0)) - t0)
    else:
        Gamma = Lam0.T * (d_ds(u3, t0) + angle[0] * ufl.cross(t0, n))
    return Gamma, Lam0.T * n * d_ds(angle[0], t0)


def strains(kin, u, rot, t0, Lam0):
    """Strains of the chosen kinematics."""
    if kin.plane:
        return planar_strains(kin, u, rot, t0, Lam0)
    return (finite_strains if kin.finite else linear_strains)(u, rot, t0, Lam0)


def spatial_virtual_rotation(kin, rot, drot):
    """Virtual rotation δθ in global axes: axial(δR Rᵀ) for quaternions, δθ for small rotations."""
    from .rotations import spatial_rate

    if kin.plane:
        return drot[0] * plane_normal(kin)
    return spatial_rate(rot, drot) if kin.finite else drot


def body_virtual_rotation(kin, rot, drot):
    """Virtual rotation in the rotated (body) axes: axial(Rᵀ δR)."""
    if kin.plane:
        return drot[0] * plane_normal(kin)
    return body_rate(rot, drot) if kin.finite else drot


def section_rotation(kin, rot):
    """Rotation R taking reference section axes to current ones (identity + hat θ if linear)."""
    import ufl

    from .rotations import hat

    if kin.plane:
        N = hat(plane_normal(kin))
        if not kin.finite:
            return ufl.Identity(3) + rot[0] * N
        return ufl.Identity(3) + ufl.sin(rot[0]) * N + (1 - ufl.cos(rot[0])) * N * N
    return rotation(rot) if kin.finite else ufl.Identity(3) + hat(rot)


def rotation_vector(kin, rot):
    """The rotation vector ψ (global axes; |ψ| ≤ 2π for quaternions), θ if linear."""
    from .rotations import quaternion_rotation_vector

    if kin.plane:
        return rot[0] * plane_normal(kin)
    return quaternion_rotation_vector(rot) if kin.finite else rot


def rotation_output(kin, rot):
    """The rotation as post-processing reads it: a quaternion (finite) or θ (linear)."""
    import ufl

    if not kin.plane:
        return rot
    n = plane_normal(kin)
    if not kin.finite:
        return rot[0] * n
    half = rot[0] / 2
    return ufl.as_vector([ufl.cos(half), *(ufl.sin(half) * n[i] for i in range(3))])
