"""A transient's probes kept raw per step and made into values per block
(:class:`~beamfx.io.probe_blocks.ProbeBlocks`) give the numbers of the per-step path:
evaluate_points and track_rotations (issue 15)."""

import math
from types import SimpleNamespace

import numpy as np
import pytest
from scenekit import comm, rollup_model

from beamfx.io import evaluate_points, track_rotations
from beamfx.io.probe_blocks import ProbeBlocks
from beamfx.physics.rotations import unwrap_rotation_vector


def _path(n, rng):
    """Quaternions (n, 4) of any norm along a path that turns several times about a wobbling
    axis (steps below π), with a few zero and tiny vector parts."""
    angle = np.cumsum(rng.uniform(0.0, 2.5, n)) * rng.choice([-1.0, 1.0])
    axis = np.array([0.3, -0.2, 1.0]) + 0.2 * np.cumsum(rng.normal(size=(n, 3)) * 0.05, axis=0)
    axis /= np.linalg.norm(axis, axis=1)[:, None]
    q = np.c_[np.cos(angle / 2), np.sin(angle / 2)[:, None] * axis]
    q *= 10 ** rng.uniform(-3, 3, n)[:, None]
    q[::17, 1:] *= 1e-9
    q[::29, 1:] = 0.0
    return q


def _one_point_blocks(finite):
    """A ProbeBlocks of one point without a model (only its unwrap is used)."""
    blocks = ProbeBlocks.__new__(ProbeBlocks)
    blocks.finite = finite
    return blocks


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_block_unwrap_is_bitwise_the_per_step_unwrap(seed):
    """The block's axes, angles and turns: bitwise those of the per-step path (the unit
    quaternion of evaluate_points, then unwrap_rotation_vector) step by step, from the undeformed state and from a checkpoint's value several turns away."""
    rng = np.random.default_rng(seed)
    q = _path(500, rng)
    if seed == 2:  # no zero vector part (no axis of a rotation of angle 0 to choose)
        q = np.delete(q, np.s_[::29], axis=0)
    for start in ([0.0, 0.0, 0.0], (4 * np.pi * np.array([0.6, 0.0, 0.8])).tolist()):
        want, theta = [], start
        for row in q.tolist():  # the probe's unit quaternion, as evaluate_points gives it
            norm = math.sqrt(np.dot(row, row))
            theta = unwrap_rotation_vector([c / norm for c in row], theta)
            want.append(theta)
        got = _one_point_blocks(True)._unwrapped(q, start)
        assert got.tobytes() == np.array(want).tobytes()


def _states(model, n):
    """n states of the model's unknowns: the solved roll-up's displacements scaled and its
    rotations' angles about their axes scaled (up to 6 × the quarter turn: 1.5 turns), the
    quaternions' norms too."""
    _, dofs = model.W.sub(1).collapse()
    dofs = np.asarray(dofs).reshape(-1, 4)  # the quaternions' rows (4 components per node)
    base = model.w.x.array.copy()
    q = base[dofs]
    half = np.arctan2(np.linalg.norm(q[:, 1:], axis=1), q[:, 0])
    axes = q[:, 1:] / np.maximum(np.linalg.norm(q[:, 1:], axis=1), 1e-300)[:, None]
    for s in np.linspace(0.1, 6.0, n):
        model.w.x.array[:] = s * base
        q = np.c_[np.cos(s * half), np.sin(s * half)[:, None] * axes]
        model.w.x.array[dofs] = (1.0 + 0.3 * s) * q  # not of unit norm (rotations all the same)
        model.w.x.scatter_forward()
        yield


@pytest.mark.mpi
def test_blocks_give_the_values_of_the_per_step_path():
    """Blocks of several sizes (a full one among them) over states turning beyond π: the table
    and the last values kept are bitwise evaluate_points(full=False) + track_rotations, on
    every rank (the points gathered from their owners on several ranks)."""
    from beamfx.solvers import NewtonSolver

    model, _ = rollup_model(0.25)
    model.set_load_factor(1.0)
    solver = NewtonSolver(model.F, model.J, model.w, model.bcs, "test_probe_blocks_")
    assert solver.solve().converged
    solver.destroy()
    names = list(model.mesh.points)
    kept = SimpleNamespace(values=None)
    blocks = ProbeBlocks(model, names, comm, None, lambda v: setattr(kept, "values", v), 7)
    latest, got, want = None, [], []
    for i, _ in enumerate(_states(model, 20)):
        latest = track_rotations(latest, evaluate_points(model, names, full=False))
        row = [
            [*v["position"], *v["displacement"], *v["rotation_vector_unwrapped"]]
            for v in latest.values()
        ]
        want.append(row)
        blocks.record()
        if blocks.full or i % 5 == 3:
            got.append(blocks.drain())
            assert {p: kept.values[p]["rotation_vector_unwrapped"] for p in names} == {
                p: latest[p]["rotation_vector_unwrapped"] for p in names
            }
    got.append(blocks.drain())
    assert blocks.drain() is None  # an empty block
    angles = [math.sqrt(sum(x * x for x in p[6:9])) for r in want for p in r]
    assert max(angles) > 2 * np.pi  # the states turn the tip beyond a turn
    if comm.rank == 0:
        assert np.concatenate(got).tobytes() == np.array(want).tobytes()
    else:
        assert all(g is None for g in got[:-1])
    for p in names:
        assert kept.values[p]["position"] == latest[p]["position"]
        assert kept.values[p]["angle_unwrapped"] == latest[p]["angle_unwrapped"]
