"""Checkpoints of a transient run and ``beamfx run --restart``: what is written, what is checked.

A checkpoint (:mod:`beamfx.io.checkpoint`) carries the state at t_n, the energy balance, the
step controller (next step size and its growth counters) and the unwrapped rotation vectors
of the probes (the whole turns 2πk that a quaternion does not hold), with the fingerprints
of the scene and the mesh (:mod:`beamfx.io.fingerprint`). On a restart every rank reads its
file and the ranks agree: a missing or damaged file, another scene (its differences named)
or another mesh stop every rank with one message, before anything is solved.
"""

import numpy as np

from ..io.checkpoint import (
    CheckpointError,
    agree,
    checkpoint_path,
    checkpoint_ranks,
    read_checkpoints,
    write_checkpoint,
)
from ..io.fingerprint import mesh_differences, mesh_fingerprint, scene_differences
from ..io.fingerprint import scene_fingerprint as _scene_fingerprint
from .dofs import owned_size
from .dynamics import STATE_NAMES


def scene_fingerprint(ctx, settings):
    """The fingerprint of the run's scene: model, analysis settings and probes."""
    return _scene_fingerprint(ctx.spec, ctx.analysis, settings, ctx.probes)


def tracked_rotations(latest):
    """``{point: unwrapped rotation vector}`` of tracked probe values (:attr:`RunContext.latest`)."""
    return {p: list(v["rotation_vector_unwrapped"]) for p, v in (latest or {}).items()}


def checkpoint_writer(ctx, settings, model, history):
    """``write(header, arrays)`` for :func:`~beamfx.analyses.transient.solve_transient`: the
    history flushed first (its rows up to the checkpoint are on disk), then this rank's file
    with the probes' rotations and the fingerprints."""
    scene = scene_fingerprint(ctx, settings)
    mesh = mesh_fingerprint(model)
    path = checkpoint_path(ctx.folder, ctx.comm.size, ctx.comm.rank)

    def write(header, arrays):
        history.flush()
        probes = tracked_rotations(ctx.latest)
        full = {**header, "probes": probes, "scene": scene, "mesh": mesh}
        write_checkpoint(path, {**full, "ranks": ctx.comm.size, "rank": ctx.comm.rank}, arrays)

    return write


def refuse_other_ranks(folder, comm):
    """Refuse (on every rank) a ``--restart`` in ``folder`` whose checkpoints were all
    written by runs on another number of ranks: a run from t = 0 would replace that run's
    files. Called before the folder is claimed or any file written (collective).

    Raises:
        CheckpointError: naming the folder, the ranks the checkpoints are for and what to do.
    """
    found = checkpoint_ranks(folder) if comm.rank == 0 else None
    found = comm.bcast(found) if comm.size > 1 else found
    if not found or comm.size in found:
        return
    raise CheckpointError(_other_ranks_message(folder, found, comm.size))


def _ranks(n):
    return f"{n} rank{'s' if n > 1 else ''}"


def _other_ranks_message(folder, found, size):
    """The refusal of :func:`refuse_other_ranks`: ``found`` {ranks: file names}."""
    counts = sorted(found)
    names = [name for n in counts for name in found[n]]
    files = ", ".join(names[:3]) + (", ..." if len(names) > 3 else "")
    how = " or ".join(
        "one rank (beamfx run ... --restart, without mpirun)"
        if n == 1
        else f"{n} ranks (mpirun -n {n} beamfx run ... --restart)"
        for n in counts
    )
    return (
        f"{folder}: cannot --restart on {_ranks(size)}: its checkpoints were written by a run "
        f"on {' or '.join(_ranks(n) for n in counts)} ({files}). Restart on {how} to go on "
        "from them, or run without --restart to start afresh (which replaces that run's "
        "files). Nothing in the folder was changed."
    )


def load_restart(ctx, settings, model):
    """The checkpoint to go on from, checked against this run (collective), or None if there
    is none for this number of ranks; the probes' tracked rotations are put back into ``ctx``.

    Raises:
        CheckpointError: on every rank, naming what is missing, damaged or different.
    """
    saved = read_checkpoints(ctx.folder, ctx.comm)
    if saved is None:
        return None
    header, arrays = saved
    problems = scene_differences(header["scene"], scene_fingerprint(ctx, settings))
    if problems:
        problems = [f"{ctx.folder}: the checkpoint is for another scene: " + "; ".join(problems)]
    else:
        mesh = mesh_differences(header["mesh"], mesh_fingerprint(model))
        problems = [f"{ctx.folder}: the checkpoint is for another mesh: {p}" for p in mesh]
    if not problems:
        problems = [f"{ctx.folder}: {p}" for p in _state_problems(header, arrays, model)]
    agree(problems, ctx.comm)
    ctx.latest = {p: {"rotation_vector_unwrapped": v} for p, v in header["probes"].items()}
    return saved


def _numbers(x, n=None):
    ok = isinstance(x, list) and all(
        isinstance(v, (int, float)) and not isinstance(v, bool) and np.isfinite(v) for v in x
    )
    return ok and (n is None or len(x) == n)


def _state_problems(header, arrays, model):
    """What in a checkpoint's contents does not fit this model (sizes and kinds)."""
    local, owned = len(model.w.x.array), owned_size(model.W)
    for k in STATE_NAMES:
        if k not in arrays or arrays[k].size != local:
            yield f"state {k!r}: {arrays[k].size if k in arrays else 'missing'}, not {local} values"
    b = header["balance"]
    if not isinstance(b, dict) or not isinstance(b.get("values"), dict):
        yield "balance: not a table of values"
        return
    if not _numbers(list(b["values"].values())):
        yield "balance.values: not all finite numbers"
    for key in ("initial", "power", "loads", "reaction"):
        value = b.get(key)
        name = f"balance_{key}"
        if value == "array" and key in ("loads", "reaction"):
            if name not in arrays or arrays[name].size != owned:
                yield f"{name}: not {owned} values"
        elif value is not None and not _numbers([value]):
            yield f"balance.{key}: {value!r} is not a number"
    c = header["controller"]
    if not _numbers([c.get("size")]) or not isinstance(c.get("state", {}), dict):
        yield "controller: no step size"
    elif not _numbers(list(c.get("state", {}).values())):
        yield "controller.state: not all numbers"
    bad = [p for p, v in header["probes"].items() if not _numbers(v, 3)]
    if bad:
        yield f"probes {bad}: not rotation vectors of 3 numbers"
