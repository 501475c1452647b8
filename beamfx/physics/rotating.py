r"""Inertia seen in a frame that rotates at a constant angular velocity Ω (notation: package doc).

The frame turns about an axis through the hub point H. In its axes a section at relative
position r = X + u − H, with relative velocity ṙ and relative angular velocity
w = axial(Λ̇ Λᵀ), has the kinetic energy (Géradin & Cardona 2001, §10.5; Simo & Vu-Quoc 1988)

.. math:: T = ½ ρA\,|\dot r + Ω × r|^2 + ½ (w + Ω)\cdot J (w + Ω), \qquad J = Λ\,J_0\,Λ^T

which splits by powers of the rates into T = T₂ + T₁ + T₀:

* T₂ = ½ ρA ṙ·ṙ + ½ w·J w: the mass form of :mod:`beamfx.physics.inertia`;
* T₁ = ρA ṙ·(Ω × r) + w·J Ω = a(q)·q̇: linear in the rates, its Lagrange terms are the
  gyroscopic (Coriolis) forces G q̇ with G = ∂a/∂q − (∂a/∂q)ᵀ, skew by construction;
* T₀ = ½ ρA |Ω × r|² + ½ Ω·J Ω: enters as the potential V_c = −T₀, whose derivative is the
  centrifugal load (ρA Ω × (Ω × r) on the centre line, −Ω × (JΩ) on the section) and whose
  second derivative is the spin softening, consistent with the load by construction.

Ω, r and J are in the global axes of the rotating frame. For quaternions w = spatial_rate(q, q̇)
is blind to the norm of q (as is J), so a and G see only the rotation q/|q|.

A section whose mass centre is off the reference line (first moment s = Λ S, global axes; a
matrix section) adds (ṙ + Ω × r)·((w + Ω) × s) to T: ṙ·(w × s) to T₂ (the mass matrix),
ṙ·(Ω × s) + (Ω × r)·(w × s) to T₁ and (Ω × r)·(Ω × s) to T₀; J is then about the reference
point.
"""

from .rotations import hat


def relative_position(X, u, hub):
    """Position r = X + u − H: current centre-line point relative to the hub (global axes)."""
    return X + u - hub


def centrifugal_potential(rho_A, J, omega, r, s=None):
    r"""V_c = −½ ρA |Ω × r|² − ½ Ω·J Ω per unit length; J is the spatial section inertia
    (and − (Ω × r)·(Ω × s) with the first moment ``s``)."""
    import ufl

    V = -0.5 * rho_A * ufl.dot(ufl.cross(omega, r), ufl.cross(omega, r)) - 0.5 * ufl.dot(
        omega, J * omega
    )
    if s is not None:
        V -= ufl.dot(ufl.cross(omega, r), ufl.cross(omega, s))
    return V


def gyroscopic_covector(rho_A, J, omega, r, v_u, v_theta, s=None):
    r"""a(q)·δq = ρA δu·(Ω × r) + δθ·J Ω: the coefficient of the rates in T₁, tested with the
    virtual displacement δu and the virtual spatial rotation δθ (global axes).

    G(δ, Δ) = ∂a/∂q[Δ]·δ − ∂a/∂q[δ]·Δ; for the centre line alone that is
    2 ρA δu·(Ω × Δu), the Coriolis force 2 ρA Ω × u̇. With the first moment ``s``:
    + δu·(Ω × s) + δθ·(s × (Ω × r)).
    """
    import ufl

    a = rho_A * ufl.dot(v_u, hat(omega) * r) + ufl.dot(v_theta, J * omega)
    if s is not None:
        a += ufl.dot(v_u, ufl.cross(omega, s)) + ufl.dot(v_theta, ufl.cross(s, ufl.cross(omega, r)))
    return a
