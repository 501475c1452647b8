"""Cross-section stiffness and inertia.

Section axes: x along the centre line, y and z the principal axes. A rectangle's ``h`` is its
size along z and ``w`` along y, so ``I_y = w h³/12`` (bending about y) and ``I_z = h w³/12``,
the convention of the reference files.
"""

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np


@dataclass(frozen=True)
class Section:
    """Stiffness and inertia of a section (section axes).

    ``EA, GA_y, GA_z`` form C_N, ``GJ, EI_y, EI_z`` form C_M (Simo 1985, eq. 2.12);
    ``rho_A`` is mass per length and ``rho_I`` the diagonal of the section inertia per length
    (polar, about y, about z).
    """

    EA: float
    GA_y: float
    GA_z: float
    GJ: float
    EI_y: float
    EI_z: float
    rho_A: float = 0.0
    rho_I: tuple[float, float, float] = (0.0, 0.0, 0.0)
    shape: tuple = ()  # ("rectangle", h, w), ("tube", d, d_inner); () if only stiffnesses

    @property
    def C_N(self):
        """Force stiffnesses (EA, GA_y, GA_z), section axes."""
        return np.array([self.EA, self.GA_y, self.GA_z])

    @property
    def C_M(self):
        """Moment stiffnesses (GJ, EI_y, EI_z), section axes."""
        return np.array([self.GJ, self.EI_y, self.EI_z])

    def stiffnesses(self):
        """The six stiffnesses in the order (EA, GA_y, GA_z, GJ, EI_y, EI_z)."""
        return np.r_[self.C_N, self.C_M]

    def inertias(self):
        """Mass per length and the section inertia diagonal: (rho_A, rho_I...)."""
        return np.r_[self.rho_A, self.rho_I]

    def matrices(self):
        """(C, M): the 6×6 stiffness diag(EA, GA_y, GA_z, GJ, EI_y, EI_z) and mass
        diag(ρA, ρA, ρA, ρI...) in the order of :mod:`~beamfx.physics.matrix_sections`."""
        return np.diag(self.stiffnesses()), np.diag(np.r_[[self.rho_A] * 3, self.rho_I])

    varies = False

    def along(self, s):
        """The section at arc lengths ``s`` (a prismatic beam: the same everywhere)."""
        return [self] * len(s)

    def with_limits(self, shear_rigid=False, inextensible=False, length=1.0, factor=1e8):
        """Section whose shear and/or axial stiffness is raised to a penalty value.

        The penalty is ``factor · max(EI) / length²``: the relative error it leaves in a
        bending-dominated deflection is about ``3 / factor``.
        """
        big = factor * max(self.EI_y, self.EI_z, self.GJ) / length**2
        s = self
        if shear_rigid:
            s = replace(s, GA_y=max(big, s.GA_y), GA_z=max(big, s.GA_z))
        if inextensible:
            s = replace(s, EA=max(big, s.EA))
        return s


def saint_venant_rectangle(a, b, terms=50):
    """Saint-Venant torsion constant of an a × b rectangle (a ≥ b).

    J = a b³/3 [1 - (192/π⁵)(b/a) Σ_{n odd} tanh(nπa/2b)/n⁵] (Timoshenko & Goodier, §109).
    """
    a, b = max(a, b), min(a, b)
    n = np.arange(1, 2 * terms, 2)
    series = np.sum(np.tanh(n * np.pi * a / (2 * b)) / n**5)
    return a * b**3 / 3 * (1 - 192 / np.pi**5 * (b / a) * series)


def cowper_rectangle(nu):
    """Cowper (1966) shear correction factor of a rectangle."""
    return 10 * (1 + nu) / (12 + 11 * nu)


def cowper_tube(nu, m):
    """Cowper (1966) shear factor of a hollow circle with radius ratio m = r_i/r_o (m=0: solid)."""
    return 6 * (1 + nu) * (1 + m**2) ** 2 / ((7 + 6 * nu) * (1 + m**2) ** 2 + (20 + 12 * nu) * m**2)


def _from_geometry(E, G, rho, A, I_y, I_z, J, k_y, k_z, shape):
    return Section(
        shape=shape,
        EA=E * A,
        GA_y=k_y * G * A,
        GA_z=k_z * G * A,
        GJ=G * J,
        EI_y=E * I_y,
        EI_z=E * I_z,
        rho_A=rho * A,
        rho_I=(rho * (I_y + I_z), rho * I_y, rho * I_z),
    )


def rectangle(E, G, rho, h, w, torsion="saint-venant", shear_factor=None, nu=None):
    """Solid rectangle, ``h`` along section z and ``w`` along y.

    ``torsion`` is "saint-venant" (series), "thin-strip" (J = h w³/3, the reference files' S_t
    for w < h) or a number J. The shear factor defaults to Cowper's.
    """
    A, I_y, I_z = w * h, w * h**3 / 12, h * w**3 / 12
    if torsion == "saint-venant":
        J = saint_venant_rectangle(h, w)
    elif torsion == "thin-strip":
        J = max(h, w) * min(h, w) ** 3 / 3
    else:
        J = float(torsion)
    k = (
        shear_factor
        if shear_factor is not None
        else cowper_rectangle(E / (2 * G) - 1 if nu is None else nu)
    )
    return _from_geometry(E, G, rho, A, I_y, I_z, J, k, k, ("rectangle", h, w))


def tube(E, G, rho, d, d_inner=0.0, shear_factor=None, nu=None):
    """Circle (``d_inner = 0``) or tube; J is the polar moment π(d⁴ - d_i⁴)/32."""
    A = math.pi * (d**2 - d_inner**2) / 4
    I = math.pi * (d**4 - d_inner**4) / 64
    nu = E / (2 * G) - 1 if nu is None else nu
    k = shear_factor if shear_factor is not None else cowper_tube(nu, d_inner / d)
    return _from_geometry(E, G, rho, A, I, I, 2 * I, k, k, ("tube", d, d_inner))


@dataclass(frozen=True)
class SectionAlong:
    """A section whose properties vary along the beam (non-prismatic beams).

    ``make(**values)`` builds the :class:`Section` (e.g. :func:`rectangle` with its material
    bound); each of ``params`` is a number or a function of the arc length s (from the beam's
    start). The model samples it at the interpolation points of its section fields.
    """

    make: Callable
    params: dict = field(default_factory=dict)

    varies = True

    def along(self, s):
        """The :class:`Section` at each arc length of ``s``."""

        def value(v, si):
            return float(v(si)) if callable(v) else v

        return [self.make(**{k: value(v, si) for k, v in self.params.items()}) for si in s]
