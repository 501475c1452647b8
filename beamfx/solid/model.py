r"""Forms of the 3D solid: strain energies, end-face tractions, mass, rigid-body modes.

Notation (reference configuration, total Lagrangian): u displacement, F = I + ∇u, C = FᵀF,
E = ½(C − I), J = det F, Lamé λ = Eν/((1+ν)(1−2ν)), μ = E/(2(1+ν)). Energies per unit
reference volume:

=============  ============================================  ===========================
name           ψ                                             reference
=============  ============================================  ===========================
linear         λ/2 (tr ε)² + μ ε:ε,  ε = sym ∇u              small strain
svk            λ/2 (tr E)² + μ E:E                           St Venant–Kirchhoff
neo-hookean    μ/2 (tr C − 3) − μ ln J + λ/2 (ln J)²         Ogden/Simo compressible form
=============  ============================================  ===========================

Residual and tangent follow by ``ufl.derivative`` of Π = ∫ψ dx − λ_load ∫ t·u ds(end).
"""

import numpy as np
import ufl

MATERIALS = ("linear", "svk", "neo-hookean")


def _vec(a):
    return ufl.as_vector([float(v) for v in a])


def lame(E, nu):
    """(λ, μ) of Young's modulus and Poisson's ratio."""
    return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))


def strain_energy(material, u, E, nu):
    """ψ(u) of the module table."""
    lmbda, mu = lame(E, nu)
    I = ufl.Identity(3)
    if material == "linear":
        eps = ufl.sym(ufl.grad(u))
        return lmbda / 2 * ufl.tr(eps) ** 2 + mu * ufl.inner(eps, eps)
    F = I + ufl.grad(u)
    C = F.T * F
    if material == "svk":
        Eg = (C - I) / 2
        return lmbda / 2 * ufl.tr(Eg) ** 2 + mu * ufl.inner(Eg, Eg)
    if material == "neo-hookean":
        lnJ = ufl.ln(ufl.det(F))
        return mu / 2 * (ufl.tr(C) - 3) - mu * lnJ + lmbda / 2 * lnJ**2
    raise ValueError(f"material {material!r} not allowed; allowed: {list(MATERIALS)}")


def face_geometry(mesh, ds, tag):
    """Area A, centroid c and second-moment tensor I2 = ∫ r rᵀ dA (r = x − c) of a face,
    integrated on the discrete face (so the tractions below have exact resultants)."""
    from dolfinx import fem

    x = ufl.SpatialCoordinate(mesh)
    comm = mesh.comm

    def integral(f):
        return comm.allreduce(fem.assemble_scalar(fem.form(f * ds(tag))))

    A = integral(1.0)
    c = np.array([integral(x[i]) for i in range(3)]) / A
    r = x - _vec(c)
    I2 = np.array([[integral(r[i] * r[j]) for j in range(3)] for i in range(3)])
    return A, c, I2


def end_traction(mesh, n, A, c, I2, force, moment):
    """Dead traction on a face with unit normal ``n`` whose resultant about the centroid is
    (force, moment): t = F/A + n (a·r) + (M·n)/I_p n × r, with a = I2⁺ (n × M), I_p = tr I2.

    The normal part is the linear bending stress (Navier: ∫ r × n (a·r) = (I2 a) × n), the
    in-plane part the linear torsional shear of a circle; both are linear in r.
    """
    x = ufl.SpatialCoordinate(mesh)
    r = x - _vec(c)
    n, M = np.asarray(n, float), np.asarray(moment, float)
    a = np.linalg.pinv(I2, rcond=1e-10) @ np.cross(n, M)
    Ip = float(np.trace(I2))
    return (
        _vec(np.asarray(force, float) / A)
        + _vec(n) * ufl.dot(_vec(a), r)
        + float(M @ n) / Ip * ufl.cross(_vec(n), r)
    )


def rigid_body_modes(V):
    """The six rigid-body motions of the vector space V as PETSc vectors, orthonormalised
    (the near-nullspace of elasticity for smoothed-aggregation AMG)."""
    from dolfinx import la

    index_map, bs = V.dofmap.index_map, V.dofmap.index_map_bs
    basis = [la.create_petsc_vector(index_map, bs) for _ in range(6)]
    x = V.tabulate_dof_coordinates()[: index_map.size_local]
    local = [b.array.reshape(-1, 3) for b in basis]  # owned entries, (nodes, 3) views
    for i in range(3):
        local[i][:, i] = 1.0
    local[3][:, 0], local[3][:, 1] = -x[:, 1], x[:, 0]
    local[4][:, 0], local[4][:, 2] = x[:, 2], -x[:, 0]
    local[5][:, 2], local[5][:, 1] = x[:, 1], -x[:, 2]
    la.orthonormalize(basis)
    return basis


def face_motion_forms(mesh, u, ds, tag, c):
    """Forms (compiled) for the motion of a face: ∫u, ∫ r × u and ∫ (r + u) ⊗ r over it."""
    from dolfinx import fem

    x = ufl.SpatialCoordinate(mesh)
    r = x - _vec(c)
    parts = [u[i] for i in range(3)] + [ufl.cross(r, u)[i] for i in range(3)]
    parts += [(r + u)[i] * r[j] for i in range(3) for j in range(3)]
    return [fem.form(p * ds(tag)) for p in parts]


def face_motion(forms, A, I2, comm):
    """Mean displacement ū, small rotation θ and best-fit finite rotation of a face.

    θ minimises ∫|u − ū − θ × r|² dA: θ = J⁻¹ ∫ r × u dA with J = I_p·1 − I2 (the face's
    polar tensor; r = x − c). The finite rotation R is the orthogonal polar factor of
    H = ∫ (r + u − ū) ⊗ r dA (least-squares rigid fit, Kabsch 1976), made proper along the
    face normal, which H does not see; returned as a rotation vector.
    """
    from dolfinx import fem
    from scipy.spatial.transform import Rotation

    v = np.array([comm.allreduce(fem.assemble_scalar(f)) for f in forms])
    u_mean = v[:3] / A
    J = np.trace(I2) * np.eye(3) - I2
    theta = np.linalg.solve(J, v[3:6])  # r ⊥ u_mean: the mean drops out of ∫ r × u
    H = v[6:].reshape(3, 3)  # ∫ ū ⊗ r = ū ⊗ ∫ r = 0
    U, _, Vt = np.linalg.svd(H)
    d = np.sign(np.linalg.det(U @ Vt))
    R = U @ np.diag([1.0, 1.0, d]) @ Vt
    return u_mean, theta, Rotation.from_matrix(R).as_rotvec()
