"""Nodal fields of the whole beam for plotting, gathered to rank 0.

Each owned cell contributes its k + 1 nodes at ξ = 0, 1/k, ..., 1 (k the degree), in order
along the cell; nodes are duplicated between cells, so the representation is discontinuous
and keeps the section force and moment of each cell (they jump at point loads and joints).
"""

import numpy as np

from ._sections import evaluate

POINT_ARRAYS = ("X", "u", "e1", "e2", "e3", "N", "M")


def nodal_fields(model, recover=True):
    """Centre line, displacement, section axes and stress resultants at the nodes. Collective.

    Args:
        model: :class:`~beamfx.analyses.model.BeamModel` (its current ``w``).
        recover: N and M extrapolated from each cell's Gauss points (default) rather than
            taken pointwise, see :func:`beamfx.io._sections.evaluate`.

    Returns:
        On rank 0 a dict of NumPy arrays over ``n = cells·(k+1)`` points, cells in input order
        (the same in serial and parallel): ``X`` reference position and ``u`` displacement
        (n, 3, global axes); ``e1, e2, e3`` current section axes R·Λ0 (n, 3, global axes);
        ``N`` and ``M`` section force and moment (n, 3, section axes); ``beam`` the beam
        index of each point (n,); ``cells`` the (cells·k, 2) line segments of the polyline.
        None on the other ranks.
    """
    model.sync()  # derived fields (the condensed model integrates its displacement)
    m = model.mesh.mesh
    k = model.degree
    xi = np.linspace(0.0, 1.0, k + 1)[:, None]
    n_owned = m.topology.index_map(m.topology.dim).size_local
    values = evaluate(model, xi, np.arange(n_owned, dtype=np.int32), recover)
    local = {
        "X": values["X"],
        "u": values["u"],
        "e1": values["axes"][..., 0],
        "e2": values["axes"][..., 1],
        "e3": values["axes"][..., 2],
        "N": values["N"],
        "M": values["M"],
        "beam": np.repeat(np.asarray(model.mesh.cell_beam[:n_owned], float)[:, None], k + 1, 1),
        "order": np.asarray(m.topology.original_cell_index[:n_owned]),
    }
    parts = model.comm.gather(local, root=0)
    if model.comm.rank != 0:
        return None
    order = np.argsort(np.concatenate([p["order"] for p in parts]), kind="stable")
    out = {}
    for name in (*POINT_ARRAYS, "beam"):
        a = np.concatenate([p[name] for p in parts])[order]  # (cells, k+1, ...)
        out[name] = a.reshape(-1, *a.shape[2:])
    n_cells = len(order)
    first = (k + 1) * np.arange(n_cells)[:, None] + np.arange(k)[None, :]
    out["cells"] = np.stack([first.ravel(), first.ravel() + 1], axis=1).astype(np.int64)
    return out
