r"""Forms of the continuum-based (ANCF-style) beam: kinematics, section-integrated St Venant–
Kirchhoff energy in three variants, end loads, mass.

Notation (straight reference centre line, total Lagrangian). s arc length along the unit
tangent t0; (e2, e3) the section axes (beamfx's section frame: e3 along a rectangle's h, e2
along its w); (η, ζ) section coordinates along (e2, e3). Unknown fields along s: the centre
line r(s) = X(s) + u(s) and two section vectors d2(s), d3(s) (reference e2, e3): nine per node.
A material point is at

    x(s, η, ζ) = r(s) + η d2(s) + ζ d3(s),   reference  X + η e2 + ζ e3,

so sections stay plane but may stretch and shear in their plane; the cross-section field is
linear in (η, ζ) (the fully parameterised ANCF kinematics, here with Lagrange P_k fields along
s: Shabana & Yakoub 2001; Nachbagauer, Pechstein, Irschik & Gerstmayr 2011). The reference
Jacobian [X_s | X_η | X_ζ] = [t0 | e2 | e3] is orthonormal, so with G = [x_s | d2 | d3],
x_s = r' + η d2' + ζ d3', the Green–Lagrange strain in the section basis is

    E = ½ (Gᵀ G − I),    E_11 = ½(x_s·x_s − 1),  E_12 = ½ x_s·d2,  E_22 = ½(d2·d2 − 1), …

E is quadratic in (η, ζ) and the energies below quartic, so a 3 × 3 Gauss–Legendre rule on
the rectangle integrates them exactly (:func:`section_rule`).

Variants (``VARIANTS``), per unit reference length:

==============  ================================================================================
full            ∫_A ψ(E) dA, ψ = λ/2 (tr E)² + μ E:E (St Venant–Kirchhoff). Poisson (thickness)
                locking: E_22, E_33 are constant over the section, so the linear-in-ζ bending
                strain acts with the constrained modulus λ + 2μ instead of E; transverse shear
                with k = 1; torsion G I_p (no warping).
poisson_free    ∫_A ψ₀(E) dA + A ψ_ν(E|axis): ψ₀ = E/2 Σ E_ii² + 2G Σ_{i<j} E_ij² has no
                Poisson coupling; the coupling ψ_ν = λ/2 (tr E)² + μ Σ E_ii² − E/2 Σ E_ii² is
                taken at the beam axis only (η = ζ = 0). Bending then sees E, while a uniform
                axial strain still contracts the section (uniaxial stress). This is the
                "enhanced continuum mechanics" split of Nachbagauer, Gruber & Gerstmayr (2013,
                J. Comput. Nonlinear Dyn. 8:021004) as Project Chrono's ChMaterialBeamANCF
                implements it (D0 over the volume, the Poisson block D_v on the axis). Setting
                ν = 0 everywhere (Sopanen & Mikkola 2003) removes the locking too but makes
                G = E/2.
corrected       poisson_free plus Cowper's shear factor k on the transverse shear: the section
                mean Ē_1α = E_1α|axis of E_12, E_13 gets 2G k Ē² instead of 2G Ē², i.e.
                + 2G (k−1) A Ē²; the linear-in-section remainder (torsion among it) keeps G.
                (Chrono puts k on the whole E_12, E_13, which scales the torsion too.)
                k = 10(1+ν)/(12+11ν) (:func:`beamfx.physics.sections.cowper_rectangle`), the
                factor of the Reissner beam's rectangle.
==============  ================================================================================

Since E_1α is linear in (η, ζ) and the section symmetric, ∫_A E_1α² dA = A Ē_1α² + ∫_A (E_1α −
Ē_1α)² dA exactly, so the shear correction touches only the transverse shear.
"""

import numpy as np
import ufl

from ..physics.sections import cowper_rectangle

VARIANTS = ("full", "poisson_free", "corrected")
SECTION_POINTS = 3  # Gauss points per section direction: exact up to degree 5 ≥ 4 (ψ quartic)


def lame(E, nu):
    """(λ, μ) of Young's modulus and Poisson's ratio."""
    return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))


def section_rule(h, w, points=SECTION_POINTS):
    """Tensor Gauss–Legendre rule on the rectangle η ∈ [−w/2, w/2], ζ ∈ [−h/2, h/2]:
    a list of (η, ζ, weight); the weights sum to A = w h."""
    x, a = np.polynomial.legendre.leggauss(points)
    return [
        (w / 2 * xi, h / 2 * xj, w * h / 4 * ai * aj)
        for xi, ai in zip(x, a)
        for xj, aj in zip(x, a)
    ]


def section_moments(h, w):
    """A, I_y = ∫ζ² dA (bending about e2) and I_z = ∫η² dA (about e3) of the rectangle."""
    return w * h, w * h**3 / 12, h * w**3 / 12


def green_lagrange(r_s, d2, d3, d2_s, d3_s, eta, zeta):
    """E = ½(GᵀG − I), G = [r' + η d2' + ζ d3' | d2 | d3] (section basis, straight reference)."""
    x_s = r_s + eta * d2_s + zeta * d3_s
    G = ufl.as_matrix([[x_s[i], d2[i], d3[i]] for i in range(3)])
    return (G.T * G - ufl.Identity(3)) / 2


# The densities below index E and use plain arithmetic, so they take a UFL matrix or a
# numpy array alike (the numpy path gives the uniform-bending reference of the roll-up).


def _normal_sq(E):
    return E[0, 0] ** 2 + E[1, 1] ** 2 + E[2, 2] ** 2


def _shear_sq(E):
    return E[0, 1] ** 2 + E[0, 2] ** 2 + E[1, 2] ** 2


def svk(E, young, nu):
    """ψ = λ/2 (tr E)² + μ E:E."""
    lmbda, mu = lame(young, nu)
    trace = E[0, 0] + E[1, 1] + E[2, 2]
    return lmbda / 2 * trace**2 + mu * (_normal_sq(E) + 2 * _shear_sq(E))


def uncoupled(E, young, nu):
    """ψ₀ = E/2 Σ E_ii² + 2G Σ_{i<j} E_ij²: no Poisson coupling (diagonal Voigt stiffness)."""
    G = young / (2 * (1 + nu))
    return young / 2 * _normal_sq(E) + 2 * G * _shear_sq(E)


def poisson_coupling(E, young, nu):
    """ψ_ν = ψ − ψ₀ = λ/2 (tr E)² + (μ − E/2) Σ E_ii² (normal strains only)."""
    lmbda, mu = lame(young, nu)
    trace = E[0, 0] + E[1, 1] + E[2, 2]
    return lmbda / 2 * trace**2 + (mu - young / 2) * _normal_sq(E)


def section_energy(variant, strain_at, young, nu, h, w, shear_factor=None):
    """Strain energy per unit reference length of the module table, split as
    (axis part, rest): the axis part A ψ_v(E|axis) is the variant's density at η = ζ = 0
    (centre-line stretch and shear, section stretch and shear, Poisson coupling, shear
    correction), the rest ∫_A ψ_b(E) dA − A ψ_b(E|axis) the part that varies over the section
    (bending, torsion, their higher-order coupling to the axis strains), ψ_b = ψ (full) or ψ₀.
    Their sum is the variant's energy; the split lets the axis part take a reduced quadrature
    along s (the membrane/shear locking remedy). ``strain_at(η, ζ)`` gives E (UFL);
    ``shear_factor`` defaults to Cowper's rectangle factor (used by "corrected" only).
    """
    if variant not in VARIANTS:
        raise ValueError(f"variant {variant!r} not allowed; allowed: {list(VARIANTS)}")
    A = w * h
    axis = strain_at(0.0, 0.0)
    base = svk if variant == "full" else uncoupled
    rest = sum(a * base(strain_at(eta, zeta), young, nu) for eta, zeta, a in section_rule(h, w))
    rest -= A * base(axis, young, nu)
    density = base(axis, young, nu)
    if variant != "full":
        density += poisson_coupling(axis, young, nu)
    if variant == "corrected":
        k = cowper_rectangle(nu) if shear_factor is None else shear_factor
        G = young / (2 * (1 + nu))
        density += 2 * G * (k - 1) * (axis[0, 1] ** 2 + axis[0, 2] ** 2)
    return A * density, rest


def mass_form(rho, h, w, v, dw):
    """Consistent mass ∫ρ ∫_A (δr + η δd2 + ζ δd3)·(Δr + η Δd2 + ζ Δd3) dA
    = ρ (A δr·Δr + I_z δd2·Δd2 + I_y δd3·Δd3) per unit length (∫η = ∫ζ = ∫ηζ = 0).
    ``v``, ``dw``: (r, d2, d3) triples of test and trial vectors."""
    A, I_y, I_z = section_moments(h, w)
    return rho * (
        A * ufl.dot(v[0], dw[0]) + I_z * ufl.dot(v[1], dw[1]) + I_y * ufl.dot(v[2], dw[2])
    )


def _unit(a):
    return a / ufl.sqrt(ufl.dot(a, a))


def end_couple_work(moment, h, w, d2, d3, v_d2, v_d3):
    r"""Virtual work of a couple on an end section, ``moment`` = (M_1, M_2, M_3) in the
    section axes given by ``d2``, ``d3`` (the reference e2, e3: dead; the current d2, d3:
    follower).

    The couple is a traction on the section, linear in (η, ζ), that moves with it: the axial
    stress σ n (n = d2 × d3 normalised) with σ = M_2 ζ/(I_y |d3|) − M_3 η/(I_z |d2|), whose
    moment about the centroid of the (stretched) section is exactly (M_2, M_3), and the
    torsional shear τ = M_1/I_p (η d̂3 − ζ d̂2). Its work on δx = δr + η δd2 + ζ δd3 is

        δW = M_2 n·δd3/|d3| − M_3 n·δd2/|d2| + M_1/I_p (I_z d̂3·δd2 − I_y d̂2·δd3),

    which for a rigid section (δd_i = δθ × d_i) is M·δθ: the couple does the work of a moment.
    In planar bending about e2 (d2 = e2 fixed) it is M_2 δφ, with φ the section's angle, i.e.
    a conservative moment about a fixed axis, the same load as beamfx's dead end moment.
    """
    _, I_y, I_z = section_moments(h, w)
    M1, M2, M3 = moment[0], moment[1], moment[2]
    n = _unit(ufl.cross(d2, d3))
    l2, l3 = ufl.sqrt(ufl.dot(d2, d2)), ufl.sqrt(ufl.dot(d3, d3))
    work = M2 * ufl.dot(n, v_d3) / l3 - M3 * ufl.dot(n, v_d2) / l2
    work += M1 / (I_y + I_z) * (I_z * ufl.dot(d3 / l3, v_d2) - I_y * ufl.dot(d2 / l2, v_d3))
    return work
