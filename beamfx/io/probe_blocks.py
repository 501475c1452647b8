"""A transient's probe history kept raw per step and turned into values per block.

At every step only the compiled section expression is evaluated (the numbers of
:func:`~beamfx.io.probes.evaluate_points`, bitwise: the same expression, cells and points)
and the probes' X, u and rotation are copied into a preallocated block array: a copy of a
few numbers. Positions, displacements and the unwrapped rotations
(:func:`~beamfx.physics.rotations.unwrap_rotation_vector`'s choice of turns, the quaternion's
axis and angle formed for the whole block with NumPy) are made when the block is drained, at
the history's flushes: frames, checkpoints, a full block, the end. Draining is collective:
each rank holds the points whose vertex it owns, gathered on rank 0, which unwraps; the
last tracked values are then known on every rank (a checkpoint writes them).
"""

import math

import numpy as np

from ..physics.rotations import nearest_turn
from .probes import kinematics_plan

CAPACITY = 256  # steps per block (a full block is drained: memory does not grow with the run)
_X_AXIS = np.array([1.0, 0.0, 0.0])  # the axis of a rotation of angle 0


class ProbeBlocks:
    """The raw per-step kinematics of named points, drained into tracked values per block.

    Args:
        model: the model (its current ``w`` is read by :meth:`record`).
        points: the point names (unique), in the order of the drained table.
        comm: the run's communicator.
        previous: ``{point: {"rotation_vector_unwrapped": ...}}`` to track from (a
            checkpoint's), or None (from the undeformed state).
        keep: ``keep(values)`` with ``{point: tracked values}`` of each drained block's last
            step, on every rank (position, displacement, rotation_vector_unwrapped,
            angle_unwrapped).
        capacity: steps per block.
    """

    def __init__(self, model, points, comm, previous=None, keep=None, capacity=CAPACITY):
        self.model, self.points, self.comm = model, list(points), comm
        self.finite = model.kin.finite
        rows, cells, expr, buffer, _, (X, u, rot) = kinematics_plan(model, self.points, True)
        self.local = [self.points.index(n) for n, _ in rows]  # owned points' columns
        _check_found(self.points, self.local, comm)
        size = expr.X().shape[0] * expr.value_size  # a cell's row of the buffer
        parts = np.r_[np.arange(X.start, X.stop), np.arange(u.start, u.stop)]
        parts = np.r_[parts, np.arange(rot.start, rot.stop)]
        self.index = np.array(
            [i * size + node * expr.value_size + parts for i, (_, node) in enumerate(rows)],
            dtype=np.intp,
        ).reshape(len(rows), len(parts))
        # the compiled expression's eval into the values' buffer (and its flat view)
        self.eval, self.cells = expr.eval, cells
        self.buffer, self.flat = buffer, buffer.reshape(-1)
        self.raw = np.empty((capacity, len(rows), len(parts)))
        self.count, self.capacity = 0, capacity
        previous = previous or {}
        self.latest = {
            p: list(previous.get(p, {}).get("rotation_vector_unwrapped", (0.0, 0.0, 0.0)))
            for p in self.points
        }
        self.keep = keep or (lambda values: None)

    @property
    def full(self):
        """Whether the block is full (the same on every rank: one record per step)."""
        return self.count == self.capacity

    def record(self):
        """Keep the current state's raw kinematics (collective: the model's derived fields)."""
        self.model.sync()
        if len(self.index):
            self.eval(self.cells, self.buffer)
            self.raw[self.count] = self.flat[self.index]
        self.count += 1

    def drain(self):
        """The block as an (n, points, 9) array on rank 0 (position, displacement, unwrapped
        rotation vector per point; None on the other ranks) and empty the block; the last
        row's values on every rank to ``keep``. Collective."""
        n, self.count = self.count, 0
        if n == 0:
            return None
        raw = self._gathered(self.raw[:n])
        table = None
        if raw is not None:
            table = np.empty((n, len(self.points), 9))
            table[:, :, 0:3] = raw[:, :, 0:3] + raw[:, :, 3:6]
            table[:, :, 3:6] = raw[:, :, 3:6]
            for j, p in enumerate(self.points):
                table[:, j, 6:9] = self._unwrapped(raw[:, j, 6:], self.latest[p])
        last = table[-1] if table is not None else None
        if self.comm.size > 1:
            last = self.comm.bcast(last, root=0)
        self.latest = {p: last[j, 6:9].tolist() for j, p in enumerate(self.points)}
        self.keep({p: _values(last[j]) for j, p in enumerate(self.points)})
        return table

    def _gathered(self, raw):
        """The block of all points on rank 0 (the owner of each point's vertex), else None."""
        if self.comm.size == 1:
            return raw
        parts = self.comm.gather((self.local, raw), root=0)
        if parts is None:
            return None
        out = np.empty((len(raw), len(self.points), raw.shape[2]))
        for local, block in reversed(parts):  # the lowest rank's value, as evaluate_points
            out[:, local] = block
        return out

    def _unwrapped(self, rot, previous):
        """The unwrapped rotation vectors (n, 3) of a block of one point's rotations."""
        if not self.finite:  # linear kinematics: θ is already the field
            return rot
        axes, angles = _axes_angles(rot)
        out = np.empty((len(rot), 3))
        p = list(previous)
        for i, (n, angle) in enumerate(zip(axes.tolist(), angles.tolist())):
            p = out[i] = nearest_turn(n, angle, p)
        return out


def _check_found(points, local, comm):
    """Raise on every rank if a point's vertex is on no rank (as evaluate_points does)."""
    found = set(local) if comm.size == 1 else set().union(*comm.allgather(local))
    missing = [p for j, p in enumerate(points) if j not in found]
    if missing:
        raise RuntimeError(f"named points {missing} were found on no rank")


def _axes_angles(q):
    """Unit axes (n, 3) and angles in [0, 2π] (n,) of quaternions (n, 4) of any norm, per row
    the operations of the per-step path: the probe's ``quaternion`` (q / |q|,
    :func:`~beamfx.io.probes.evaluate_points`), then
    :func:`~beamfx.physics.rotations.unwrap_rotation_vector`'s first operations on it (which
    normalise it once more: not always the same bits)."""
    q = q / np.sqrt(_dots(q))[:, None]
    q = q / np.sqrt(_dots(q))[:, None]
    s = np.sqrt(_dots(q[:, 1:]))
    angles = 2 * np.arctan2(s, q[:, 0])
    ok = s > 1e-300
    if ok.all():  # (the usual case: no rotation of angle 0 to the last bit)
        return q[:, 1:] / s[:, None], angles
    axes = np.where(ok[:, None], q[:, 1:] / np.where(ok, s, 1.0)[:, None], _X_AXIS)
    return axes, angles


def _dots(a):
    """Row-wise a·a, summed left to right (as ``dot`` of a short vector)."""
    out = a[:, 0] * a[:, 0]
    for j in range(1, a.shape[1]):
        out = out + a[:, j] * a[:, j]
    return out


def _values(row):
    """The tracked values of one point from its drained row (9,)."""
    theta = row[6:9]
    return {
        "position": row[0:3].tolist(),
        "displacement": row[3:6].tolist(),
        "rotation_vector_unwrapped": theta.tolist(),
        "angle_unwrapped": math.sqrt(theta.dot(theta)),
    }


__all__ = ["CAPACITY", "ProbeBlocks"]
