"""BeamDyn's discretisation of the gravity cantilever, modelled in the plane: an estimate of
BeamDyn's own discretisation error (numpy and scipy only, no beamfx model).

BeamDyn (Wang et al. 2017, Wind Energy, doi:10.1002/we.2101) discretises a beam by Legendre spectral
elements: displacements and Wiener–Milenkovic rotation parameters c are interpolated by
Lagrange polynomials of order p through the p + 1 Gauss–Lobatto–Legendre points, the energy is
integrated by p + 1 Gauss points. The r-test case bd_static_cantilever_beam bends in the xz
plane, where c = 4 tan(θ/4) e_y: :func:`one_element` is that element for a planar
shear-deformable, extensible (Reissner) beam, its energy

    Π = ∫ ½ (EA ε² + GA γ² + EI θ'²) ds − ∫ q u_x ds,
    ε = x'·t − 1, γ = x'·d,  t = (sin θ, cos θ), d = (cos θ, −sin θ) in (x, z),

minimised by Newton's method in load steps (complex-step gradient, central-difference Hessian:
15 unknowns at p = 5). :func:`elastica` solves the same beam's equations exactly (boundary
value problem, scipy's ``solve_bvp``): N = q (L − s) along x, θ' = M/EI,
M' = −z' q (L − s), x' = (1 + ε) t + γ d.
"""

from typing import NamedTuple

import numpy as np
from numpy.polynomial import legendre

#: bd_static_cantilever_beam: L (m), gravity load q = m g (N/m), EI, EA, GA
BEAM = {"L": 10.0, "q": 9.806, "EI": 100.0, "EA": 1.0e4, "GA": 1.0e4}


class Tip(NamedTuple):
    """Tip displacement (x, z) and rotation θ about y (rad)."""

    ux: float
    uz: float
    ry: float


def gll(p):
    """The p + 1 Gauss–Lobatto–Legendre points on [−1, 1]."""
    inner = legendre.legroots(legendre.legder([0] * p + [1]))
    return np.r_[-1.0, np.sort(inner), 1.0]


def lagrange(nodes, x):
    """Values and derivatives (len(x), len(nodes)) of the Lagrange basis through ``nodes``."""
    n = len(nodes)
    coef = np.linalg.inv(np.vander(nodes, n, increasing=True))
    P = np.vander(x, n, increasing=True)
    dP = np.hstack([np.zeros((len(x), 1)), P[:, :-1] * np.arange(1, n)])
    return P @ coef, dP @ coef


def _energy(p, points, beam):
    """Π(A, λ) of one element of order ``p``, ``points`` Gauss points; A rows = states
    (u_x, u_z, c at the p free nodes; the root node is clamped)."""
    L, q = beam["L"], beam["q"]
    xg, wg = legendre.leggauss(points)
    N, dN = lagrange(gll(p), xg)
    dN = dN * 2 / L

    def energy(A, lam):
        B = A.reshape(len(A), 3, p)
        root = np.zeros((len(A), 1))
        ux, uz, c = (np.hstack([root, B[:, i]]) for i in range(3))
        cq = c @ N.T
        th, dth = 4 * np.arctan(cq / 4), (c @ dN.T) / (1 + cq**2 / 16)
        xp, zp = ux @ dN.T, 1 + uz @ dN.T
        eps = xp * np.sin(th) + zp * np.cos(th) - 1
        gam = xp * np.cos(th) - zp * np.sin(th)
        W = beam["EA"] * eps**2 + beam["GA"] * gam**2 + beam["EI"] * dth**2
        return ((0.5 * W - lam * q * (ux @ N.T)) * wg * L / 2).sum(axis=1)

    return energy


def one_element(p, points=None, steps=50, beam=BEAM):
    """The tip of one Legendre spectral element of order ``p`` with ``points`` Gauss points
    (default p + 1, BeamDyn's), ``steps`` equal load steps; raises if Newton fails."""
    energy, n = _energy(p, points or p + 1, beam), 3 * p
    E, h = np.eye(n), 1e-30

    def grad(A, lam):
        Z = (A[:, None, :] + 1j * h * E[None]).reshape(-1, n)
        return (energy(Z, lam).imag / h).reshape(len(A), n)

    a = np.zeros(n)
    for lam in np.linspace(1 / steps, 1, steps):
        for _ in range(60):
            G = grad(np.vstack([a + 1e-6 * E, a - 1e-6 * E]), lam)
            H = (G[:n] - G[n:]) / 2e-6
            step = np.linalg.solve(0.5 * (H + H.T), -grad(a[None], lam)[0])
            a += step
            if np.abs(step).max() < 1e-12:
                break
        else:
            raise RuntimeError(f"one_element({p}): Newton did not converge at load {lam:g}")
    ux, uz, c = a.reshape(3, p)[:, -1]
    return Tip(float(ux), float(uz), float(4 * np.arctan(c / 4)))


def elastica(beam=BEAM, tol=1e-10):
    """The exact tip of the planar beam (the module doc's equations, ``solve_bvp``)."""
    from scipy.integrate import solve_bvp

    L, q, EI = beam["L"], beam["q"], beam["EI"]

    def rhs(s, y):
        th, m = y[0], y[1]
        n = q * (L - s)
        eps, gam = n * np.sin(th) / beam["EA"], n * np.cos(th) / beam["GA"]
        xp = (1 + eps) * np.sin(th) + gam * np.cos(th)
        zp = (1 + eps) * np.cos(th) - gam * np.sin(th)
        return np.vstack([m / EI, -zp * n, xp, zp])

    s = np.linspace(0.0, L, 2001)
    guess = np.vstack([1.5 * s / L, 0 * s, 0 * s, s])

    def bc(root, tip):  # clamped root (θ, x, z), free tip (M)
        return np.array([root[0], tip[1], root[2], root[3]])

    sol = solve_bvp(rhs, bc, s, guess, tol=tol, max_nodes=100000)
    if sol.status != 0:
        raise RuntimeError(f"elastica: solve_bvp failed ({sol.message})")
    th, _, x, z = sol.y[:, -1]
    return Tip(float(x), float(z - L), float(th))
