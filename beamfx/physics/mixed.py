r"""The Hellinger–Reissner (mixed) strain energy: the section force is an unknown field.

.. math:: Π_{HR} = ∫ \big[ n·Γ − ½\, n·C_N^{-1} n \big] ds + ∫ ½\, K·C_M K\, ds

with ``n`` (section axes) a discontinuous field of degree p − 1, integrated with the reduced
rule ``dx_shear`` (p Gauss points, the points of a DG_{p−1} interpolation): stationarity in
``n`` gives n = C_N Γ at each of them, so the mixed model has the equilibria and the
frequencies of the displacement model with its reduced shear/axial integration. Where a
stiffness is infinite (the shear-rigid and inextensible limits) its compliance is 0 and ``n``
is the multiplier of the exact constraint Γ_i = 0 at those points: no penalty, and a tangent
whose entries do not grow with EA, GA.

A coupled (6×6) section C = [[A, B], [Bᵀ, D]] has the same form with the split of
:func:`.coupled.strain_energy`: n·(Γ + A⁻¹BK) − ½ n·A⁻¹n + ½ K·(D − BᵀA⁻¹B) K, stationary
at n = AΓ + BK (the section force).
"""

from .coupled import blocks
from .kinematics import displacement


def section_force(kin, n, Lam0):
    """The section force in section axes from the unknown ``n``: itself in space; in a plane
    the two in-plane global components, turned into section axes (the out-of-plane one is 0)."""
    return Lam0.T * displacement(kin, n) if kin.plane else n


def compliance(kin, stiffness):
    """diag(1/EA, 1/GA_y, 1/GA_z) of the stiffness field (EA, GA_y, GA_z, ...), 0 for the
    components that ``kin`` makes rigid (shear-rigid: GA; inextensible: EA)."""
    import ufl

    free = (kin.stretch, kin.shear, kin.shear)
    return ufl.diag(ufl.as_vector([1 / stiffness[i] if free[i] else 0.0 for i in range(3)]))


def _parts(Gamma, K, S_N, C_M, C):
    """(g, compliance, bending stiffness) of a diagonal (C None) or coupled section."""
    import ufl

    if C is None:
        return Gamma, S_N, C_M
    A, B, D = blocks(C)
    A_inv = ufl.inv(A)
    E = A_inv * B
    return Gamma + E * K, A_inv, D - B.T * E


def strain_energy(n, Gamma, K, S_N, C_M, dx_shear, dx_bend, C=None):
    r"""Π_HR of the section force ``n`` (section axes) and the strains (Γ, K): the module's
    form, with compliance ``S_N`` and bending stiffness ``C_M`` (UFL), or the coupled 6×6
    section ``C`` when given."""
    import ufl

    g, S, C_K = _parts(Gamma, K, S_N, C_M, C)
    return (ufl.dot(n, g) - 0.5 * ufl.dot(n, S * n)) * dx_shear + 0.5 * ufl.dot(
        K, C_K * K
    ) * dx_bend


def stress_work(n_dot, K_dot, Gamma, K, C_M, dx_shear, dx_bend, C=None):
    r"""∫ ṅ·Γ + (C_M K̇)·K ds (coupled: ṅ·(Γ + A⁻¹BK) + ((D − BᵀA⁻¹B) K̇)·K): its second
    variation in (Γ, K) is the stress stiffness of the section force rate ``n_dot`` (an
    unknown of the path) and the moment rate."""
    import ufl

    g, _, C_K = _parts(Gamma, K, None, C_M, C)
    return ufl.dot(n_dot, g) * dx_shear + ufl.dot(C_K * K_dot, K) * dx_bend
