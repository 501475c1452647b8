"""Nodal fields of the beam for plotting: per rank (:func:`local_fields`) or gathered to rank 0.

Each owned cell contributes its k + 1 nodes at ξ = 0, 1/k, ..., 1 (k the degree), in order
along the cell; nodes are duplicated between cells, so the representation is discontinuous
and keeps the section force and moment of each cell (they jump at point loads and joints).
"""

import weakref

import numpy as np

from ._sections import cell_nodes, evaluate, shared_evaluation

_owned = weakref.WeakKeyDictionary()  # model -> (cells, input indices, beams)

POINT_ARRAYS = ("X", "u", "e1", "e2", "e3", "N", "M")


def local_fields(model, recover=True):
    """The nodal fields of the cells this rank owns, in input order. Collective the first
    time (the section expression is compiled), then local.

    Args:
        model: :class:`~beamfx.analyses.model.BeamModel` (its current ``w``).
        recover: N and M extrapolated from each cell's Gauss points (default) rather than
            taken pointwise, see :func:`beamfx.io._sections.evaluate`.

    Returns:
        dict of NumPy arrays over the ``n = cells·(k+1)`` points of the owned cells, sorted by
        their input (original) cell index: ``X`` reference position and ``u`` displacement
        (n, 3, global axes); ``e1, e2, e3`` current section axes R·Λ0 (n, 3, global axes);
        ``N`` and ``M`` section force and moment (n, 3, section axes); per cell ``cell`` its
        input index and ``beam`` its beam index (cells,).
    """
    model.sync()  # derived fields (the condensed model integrates its displacement)
    cells, cell, beam = _owned_cells(model)
    values = evaluate(model, cell_nodes(model.degree), cells, recover)
    axes = values["axes"]
    out = {"X": values["X"], "u": values["u"], "N": values["N"], "M": values["M"]}
    out.update(e1=axes[..., 0], e2=axes[..., 1], e3=axes[..., 2])
    out = {name: np.ascontiguousarray(out[name]).reshape(-1, 3) for name in POINT_ARRAYS}
    out["cell"], out["beam"] = cell.copy(), beam.copy()
    return out


def shared_fields(model):
    """A context (:func:`~beamfx.io._sections.shared_evaluation`) within which the section
    quantities of the owned cells are evaluated once at the model's current state and read
    by :func:`local_fields` and by the probes and reactions at points of owned cells: what a
    step that writes a frame evaluates. The state must not change inside it."""
    return shared_evaluation(model, _owned_cells(model)[0])


def _owned_cells(model):
    """(local cells, their input indices, their beams) of the cells this rank owns, in input
    order; cached per model (a frame writer asks at every frame; its mesh does not change)."""
    mesh = model.mesh
    if model not in _owned:
        m = mesh.mesh
        n_owned = m.topology.index_map(m.topology.dim).size_local
        original = np.asarray(m.topology.original_cell_index[:n_owned], dtype=np.int64)
        order = np.argsort(original, kind="stable")
        cells = np.arange(n_owned, dtype=np.int32)[order]
        beam = np.asarray(mesh.cell_beam[:n_owned], dtype=np.int64)[order]
        _owned[model] = (cells, original[order], beam)
    return _owned[model]


def nodal_fields(model, recover=True):
    """Centre line, displacement, section axes and stress resultants at the nodes, gathered
    to rank 0. Collective.

    Args:
        model: :class:`~beamfx.analyses.model.BeamModel` (its current ``w``).
        recover: as in :func:`local_fields`.

    Returns:
        On rank 0 the arrays of :func:`local_fields` of all cells in input order (the same in
        serial and parallel), except that ``beam`` is per point (n,), plus ``cells`` the
        (cells·k, 2) line segments of the polyline through the nodes. None on the other ranks.
    """
    k = model.degree
    parts = model.comm.gather(local_fields(model, recover), root=0)
    if model.comm.rank != 0:
        return None
    order = np.argsort(np.concatenate([p["cell"] for p in parts]), kind="stable")
    per_cell = (len(order), k + 1)
    out = {}
    for name in POINT_ARRAYS:
        a = np.concatenate([p[name].reshape(-1, k + 1, 3) for p in parts])[order]
        out[name] = a.reshape(-1, 3)
    beam = np.concatenate([p["beam"] for p in parts])[order]
    out["beam"] = np.broadcast_to(beam[:, None], per_cell).astype(float).ravel()
    first = (k + 1) * np.arange(len(order))[:, None] + np.arange(k)[None, :]
    out["cells"] = np.stack([first.ravel(), first.ravel() + 1], axis=1).astype(np.int64)
    return out
