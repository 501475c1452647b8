"""The reactions' files of a run, written as it goes (rank 0): ``reactions.csv``, a row per
step (:class:`ReactionCsv`: a transient's output steps, a static or arc-length run's accepted
steps), and the grid of a frame of ``reactions.pvd`` (:func:`reaction_grid`, written by
:class:`~beamfx.io.output.FrameWriter` beside the other frames of the step). The reactions
themselves are :mod:`beamfx.analyses.reactions` and :mod:`beamfx.analyses.transient_reactions`.
"""

from functools import lru_cache

import numpy as np

AXES = ("x", "y", "z")


def columns(points, transient=True):
    """The header of ``reactions.csv``: step, time (a static run's load factor); per point the
    force, the moment about it and its position; the applied (and a transient's inertia)
    resultants about the origin; the balance (and a transient's free residual)."""
    cols = ["step", "time" if transient else "load_factor"]
    for at in points:
        cols += [f"{at}_{k}{c}" for k in ("f", "m") for c in AXES]
        cols += [f"{at}_{c}" for c in AXES]
    kinds = ("applied_f", "applied_m") + (("inertia_f", "inertia_m") if transient else ())
    cols += [f"{k}_{c}" for k in kinds for c in AXES]
    return cols + ["balance_force", "balance_moment"] + (["free_residual"] if transient else [])


def static_row(step, load_factor, entry):
    """The row of :func:`columns` (``transient=False``) of a static or arc-length step from its
    results.json ``entry`` (:func:`~beamfx.analyses.reactions.entries`, the statically
    condensed model's too)."""
    row = [step, load_factor]
    for r in entry["reactions"].values():
        row += [*r["force"], *r["moment"], *r["position"]]
    b = entry["reaction_balance"]
    return row + [*b["applied_force"], *b["applied_moment"], b["force"], b["moment"]]


class ReactionCsv:
    """``reactions.csv`` of any analysis: the header, then one row per call appended to the
    file kept open and flushed (rank 0), a constant cost per row; a restart cuts away the
    rows after its checkpoint.

    Args:
        path: the file.
        comm: the run's communicator (rank 0 writes).
    """

    def __init__(self, path, comm):
        self.path, self.comm, self.file = path, comm, None

    def start(self, header, t_restart=None):
        """Start the file with ``header`` (a list of names), or on a restart (``t_restart``:
        the checkpoint's time) keep its rows up to that time. Returns the kept rows' cells
        (on every rank). Collective."""
        self.close()
        self.row_format = ",".join(["{:.12g}"] * len(header)) + "\n"
        line = ",".join(header)
        kept = self._kept(line, t_restart) if t_restart is not None else []
        kept = self.comm.bcast(kept if self.comm.rank == 0 else None)
        if self.comm.rank == 0:
            if t_restart is None:
                self.path.write_text(line + "\n")
            self.file = self.path.open("a")
        return kept

    def _kept(self, header, t_restart):
        """Rows up to the checkpoint (rank 0): the file rewritten with them; their cells."""
        if self.comm.rank != 0:
            return []
        rows = self.path.read_text().splitlines()[1:] if self.path.exists() else []
        t_max, n = t_restart * (1 + 1e-12), header.count(",") + 1
        kept = [r.split(",") for r in rows if len(r.split(",")) == n]
        kept = [c for c in kept if float(c[1]) <= t_max]
        self.path.write_text("".join(",".join(c) + "\n" for c in [header.split(","), *kept]))
        return kept

    def write(self, row):
        """Append ``row`` (numbers, as the header) and flush it (rank 0; the others return)."""
        if self.file:  # flushed: a row costs little beside the frame of the same step
            self.file.write(self.row_format.format(*row))
            self.file.flush()

    def close(self):
        """Close the file (rank 0)."""
        if self.file:
            self.file.close()
        self.file = None


def reaction_grid(reactions, build=None):
    """The grid of the reactions: a vertex per point at its ``position``, point arrays
    ``force`` and ``moment`` ((n, 3), global axes); made by ``build`` (a
    :class:`~beamfx.io.vtkfiles.GridBuffer`, else a new grid)."""
    from .vtkfiles import VTK_VERTEX, unstructured_grid

    rows = list(reactions.values())
    n = len(rows)
    data = {
        key: np.array([r[key] for r in rows], float).reshape(n, 3) for key in ("force", "moment")
    }
    points = np.array([r["position"] for r in rows], float).reshape(n, 3)
    return (build or unstructured_grid)(points, *_vertex_cells(n, VTK_VERTEX), data)


@lru_cache(maxsize=8)
def _vertex_cells(n, vertex):
    """(connectivity, offsets, types) of ``n`` vertex cells, read only and cached: a series
    finds the same arrays at every frame (a :class:`~beamfx.io.vtkfiles.GridBuffer` then
    compares nothing)."""
    cells = (np.arange(n), np.arange(n + 1), np.full(n, vertex))
    for a in cells:
        a.flags.writeable = False
    return cells


__all__ = ["AXES", "ReactionCsv", "columns", "reaction_grid", "static_row"]
