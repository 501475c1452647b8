r"""Equilibrium along the span, as Howcroft et al. (2016, §4.4) verify their blade: at each
section, the internal moment from the constitutive law against the moment of the applied
distributed load beyond it.

The part of the beam beyond the arc length s carries the load f(σ) per unit reference length
(σ > s) and, at its cut, the moment −m(s) and force −n(s) of the inner part (m, n the stress
resultants in global axes: the section moment and force, rotated by the current section
axes). About the cut's current position x(s) its moment balance reads

    m(s) = ∫_s^L (x(σ) − x(s)) × f(σ) dσ,

with no other load beyond s (a free tip). Both sides are computed here from the solution
alone: m(s) from the recovered section moment at the cell ends, the integral by Gauss–Legendre
quadrature on every cell beyond s with the current centre line and section axes. The mismatch
is the discretisation error of the moment; it falls as the mesh is refined. Collective (the
cells of all ranks are gathered to rank 0 for the sums).
"""

import numpy as np

from ..io._sections import evaluate


def _derivative_matrix(nodes, x):
    """d/dξ of the Lagrange polynomials through ``nodes`` at ``x``: (len(x), len(nodes))."""
    D = np.zeros((len(x), len(nodes)))
    for j, xj in enumerate(nodes):
        for m, xm in enumerate(nodes):
            if m == j:
                continue
            term = np.full(len(x), 1.0 / (xj - xm))
            for i, xi in enumerate(nodes):
                if i not in (j, m):
                    term *= (x - xi) / (xj - xi)
            D[:, j] += term
    return D


def span_moments(model, force_local, profile, gauss=8):
    """Internal and applied moments at the start of every cell of a one-beam model loaded by
    one follower distributed force in section axes, ``force_local`` times ``profile(s)``.

    Returns:
        dict of arrays sorted by arc length: ``s`` (n,), ``internal`` and ``applied`` (n, 3)
        in the current section axes there (torsion about e1, bending about e2 and e3).
    """
    k = model.degree
    m = model.mesh.mesh
    cells = np.arange(m.topology.index_map(m.topology.dim).size_local, dtype=np.int32)
    nodes = np.linspace(0.0, 1.0, k + 1)
    xi, w = np.polynomial.legendre.leggauss(gauss)
    xi, w = (xi + 1) / 2, w / 2
    at_start = evaluate(model, [[0.0]], cells)
    at_nodes = evaluate(model, nodes[:, None], cells, recover=False)
    at_gauss = evaluate(model, xi[:, None], cells, recover=False)
    dX = np.einsum("gj,cji->cgi", _derivative_matrix(nodes, xi), at_nodes["X"])
    S = model.discretisation.cell_arc_lengths(xi)[cells]
    f = np.einsum("cgij,j->cgi", at_gauss["axes"], np.asarray(force_local, float))
    f *= (np.asarray(profile(S), float) * np.linalg.norm(dX, axis=2) * w)[..., None]
    local = (
        model.mesh.cell_span[cells, 0],
        (at_start["X"] + at_start["u"])[:, 0],
        at_start["axes"][:, 0],
        at_start["M"][:, 0],
        at_gauss["X"] + at_gauss["u"],
        f,
    )
    parts = model.comm.gather(local, root=0)
    result = None
    if model.comm.rank == 0:
        s0, x0, axes0, M0, xg, fg = (np.concatenate(p) for p in zip(*parts))
        order = np.argsort(s0)
        applied = []
        for n, c in enumerate(order):
            beyond = order[n:]
            total = np.cross(xg[beyond] - x0[c], fg[beyond]).sum(axis=(0, 1))
            applied.append(axes0[c].T @ total)
        result = {"s": s0[order], "internal": M0[order], "applied": np.array(applied)}
    return model.comm.bcast(result, root=0)


def mismatch(moments):
    """Largest |internal − applied| over the span, relative to the largest |applied|."""
    scale = np.abs(moments["applied"]).max()
    return float(np.abs(moments["internal"] - moments["applied"]).max() / scale)


__all__ = ["mismatch", "span_moments"]
