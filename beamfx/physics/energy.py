"""Strain energy and the virtual work of loads (notation: package doc)."""

from .kinematics import (
    body_virtual_rotation,
    displacement,
    rotation_vector,
    section_rotation,
    spatial_virtual_rotation,
)


def strain_energy(Gamma, K, C_N, C_M, dx_shear, dx_bend):
    r"""Π = ½ Γ·C_N Γ + ½ K·C_M K (Simo 1985, eq. 2.12).

    The shear/axial part is integrated with one Gauss point fewer (``dx_shear``, exact to
    degree 2p−1): with full integration the quadratic element locks in thin-beam bending.
    """
    import ufl

    return 0.5 * ufl.dot(Gamma, C_N * Gamma) * dx_shear + 0.5 * ufl.dot(K, C_M * K) * dx_bend


def quaternion_penalty(q, k_p, dx):
    r"""½ k_p (|q|² − 1)²: fixes the norm of q, which R(q) and K do not see."""
    import ufl

    return 0.5 * k_p * (ufl.dot(q, q) - 1) ** 2 * dx


def nodal_rule(element):
    """(points, weights) on the reference interval whose points are the nodes of the Lagrange
    ``element`` (a UFL element on an interval, vector or scalar) and whose weights are the
    integrals of its basis functions: the interpolatory rule on the nodes (Simpson's for P2;
    Gauss–Lobatto–Legendre, exact to degree 2k − 1, for DOLFINx's default GLL-warped P_k).

    A penalty integrated with it sees the field only at its nodes: one condition per node,
    which fixes the nodal norms and never reaches the direction field between them (``dx``'s
    Gauss rule has k + 1 points per element where the element has k nodes of its own)."""
    import basix
    from ffcx.element_interface import convert_element

    if element.num_sub_elements():
        element = element.sub_elements()[0]
    basis = convert_element(element).element
    x, w = basix.make_quadrature(basix.CellType.interval, 2 * basis.degree)
    weights = basis.tabulate(0, x)[0, :, :, 0].T @ w
    return tuple((float(p),) for p in basis.points[:, 0]), tuple(float(v) for v in weights)


def nodal_measure(mesh, element):
    """The cell measure of :func:`nodal_rule` (a custom FFCx quadrature) on ``mesh``."""
    import ufl

    points, weights = nodal_rule(element)
    metadata = {
        "quadrature_rule": "custom",
        "quadrature_degree": 2 * element.degree() - 1,
        "quadrature_points": points,
        "quadrature_weights": weights,
    }
    return ufl.dx(domain=mesh, metadata=metadata)


def force_work(kin, rot, v_u, force, follower):
    """Virtual work of a force (global axes); a follower force is R·force (turns with the section)."""
    import ufl

    f = section_rotation(kin, rot) * force if follower else force
    return ufl.dot(f, displacement(kin, v_u))


def moment_work(kin, rot, v_rot, moment, kind, arm=None):
    """Virtual work of a moment of ``kind``, one of the three below.

    * "dead": M·δθ, fixed in space (global axes). Not conservative for finite 3D rotations;
      its tangent is unsymmetric and the solvers use LU, which does not mind.
    * "follower": M0·axial(Rᵀδθ), turns with the section (body axes).
    * "semitangential": M0·δψ, work-conjugate to the rotation vector ψ (Argyris et al. 1979):
      conservative, with potential −M0·ψ; to first order the moment vector turns by half the
      rotation, M ≈ M0 + ½ ψ × M0.
    * "quasitangential": the couple of two dead forces ±F at the ends of a rigid arm ``arm``
      (a, global axes in the reference state, normal to M0) that turns with the section
      (Argyris et al. 1979; Ziegler 1977): M = (R a) × F with F = M0 × a/|a|², potential
      −F·(R a), conservative. To first order M ≈ M0 + |M0| â (ψ·F̂): the moment turns only
      with the rotation about the force direction F̂. The two couples with arms â and F̂ have
      the mean potential −M0·ψ + O(ψ³), the semitangential moment.
    """
    import ufl

    if kind == "follower":
        return ufl.dot(moment, body_virtual_rotation(kin, rot, v_rot))
    if kind == "semitangential":
        return _work_of_potential(
            kin, rot, v_rot, lambda r: ufl.dot(moment, rotation_vector(kin, r))
        )
    if kind == "quasitangential":
        if arm is None:
            raise ValueError("a quasitangential moment needs the direction of its arm")
        a = ufl.as_vector([float(c) for c in arm])
        force = ufl.cross(moment, a) / ufl.dot(a, a)
        return _work_of_potential(
            kin, rot, v_rot, lambda r: ufl.dot(force, section_rotation(kin, r) * a)
        )
    return ufl.dot(moment, spatial_virtual_rotation(kin, rot, v_rot))


def _work_of_potential(kin, rot, v_rot, work):
    """δ(work(rot)) in the direction ``v_rot``; the planar model's single angle is
    differentiated as a UFL variable (``ufl.derivative`` needs matching vector shapes)."""
    import ufl

    if kin.plane:
        angle = ufl.variable(rot[0])
        return ufl.diff(work(ufl.as_vector([angle])), angle) * v_rot[0]
    return ufl.derivative(work(rot), rot, v_rot)


def spring_energy(u, k):
    """½ u·diag(k) u of a translational spring to ground (k per global axis)."""
    import ufl

    return 0.5 * ufl.dot(u, ufl.diag(ufl.as_vector(k)) * u)


def rotational_spring_energy(kin, rot, k):
    """½ ψ·diag(k) ψ of a rotational spring to ground (ψ the rotation vector, global axes)."""
    return spring_energy(rotation_vector(kin, rot), k)


def constraint_penalty(values, targets, k):
    """½ k Σ (value_i − target_i)²: a stiff spring holding scalar ``values`` at ``targets``."""
    return 0.5 * k * sum((v - t) ** 2 for v, t in zip(values, targets))


def load_work(kin, rot, v_u, v_rot, force, moment, kind, arm=None):
    """Virtual work of a force and a moment; ``kind`` and ``arm`` as in :func:`moment_work` (a
    force of kind "semitangential" or "quasitangential" is dead)."""
    return force_work(kin, rot, v_u, force, kind == "follower") + moment_work(
        kin, rot, v_rot, moment, kind, arm
    )


def strain_rate_dissipation(Gamma_dot, K_dot, C_N, C_M, eta, dx_shear, dx_bend):
    r"""Rayleigh dissipation potential of stiffness-proportional damping,
    D = ½ η (Γ̇·C_N Γ̇ + K̇·C_M K̇): the viscous stresses η C Γ̇ of a Kelvin–Voigt material with
    relaxation time η. Built on strain rates, it is objective: a rigid motion dissipates
    nothing (unlike η K_T q̇, which damps a spinning beam)."""
    return strain_energy(Gamma_dot, K_dot, eta * C_N, eta * C_M, dx_shear, dx_bend)
