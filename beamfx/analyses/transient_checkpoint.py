"""Checkpoints of a transient run: the state to go on from, its restore, and their cadence
(see :mod:`beamfx.io.checkpoint` for the file, :mod:`beamfx.analyses.restart` for the writer)."""

import time

import numpy as np

CHECKPOINT_STEPS = 50  # the default checkpoints: every this many steps,
CHECKPOINT_SECONDS = 10.0  # and this much wall time after the last one (or the start)


def control_state(control):
    """The step controller's state: the next step size and the growth policy's counters."""
    from dataclasses import fields

    growth = control.growth
    private = {f.name: getattr(growth, f.name) for f in fields(growth) if f.name.startswith("_")}
    return {"size": float(control.size), "growth": type(growth).__name__, "state": private}


def restore_control(control, state):
    """Put a saved :func:`control_state` back into ``control`` (same policy)."""
    control.size = float(state["size"])
    if state.get("growth") == type(control.growth).__name__:
        for k, v in state.get("state", {}).items():
            if k.startswith("_") and hasattr(control.growth, k):
                setattr(control.growth, k, v)


def checkpoint_state(dyn, balance, control, t, step):
    """(header, arrays) of the state to go on from ``t``: the state at t_n, the energy
    balance, the step controller (see :mod:`beamfx.io.checkpoint` for the file)."""
    arrays = dyn.state()
    if dyn.extrapolation:
        arrays |= dyn.extrapolation.arrays()
    previous = balance.previous or {}
    saved = {"values": dict(balance.values), "initial": balance.initial}
    saved["power"] = previous.get("power")
    saved["penalty"] = previous.get("penalty")
    for key in ("loads", "reaction"):
        value = previous.get(key)
        if isinstance(value, np.ndarray):
            arrays[f"balance_{key}"], value = value, "array"
        saved[key] = value
    header = {"t": float(t), "step": int(step), "size": float(control.size)}
    return {**header, "controller": control_state(control), "balance": saved}, arrays


def restore_state(saved, dyn, balance, control):
    """Put a checkpoint's (header, arrays) back: state, energy balance and step controller;
    returns (t, step)."""
    header, arrays = saved
    dyn.set_state(arrays)
    if dyn.extrapolation:
        dyn.extrapolation.restore(arrays)
    b = header["balance"]
    previous = None
    if b["power"] is not None:
        previous = {"power": b["power"], "penalty": b.get("penalty")}
        for key in ("loads", "reaction"):
            value = b.get(key)
            previous[key] = arrays[f"balance_{key}"] if value == "array" else (value or 0.0)
    balance.set({"values": b["values"], "initial": b["initial"], "previous": previous})
    restore_control(control, header["controller"])
    return header["t"], header["step"]


def checkpoint_due(every, step, saved_at, comm):
    """Whether accepted step ``step`` gets a checkpoint: every ``every`` steps (0: never); by
    default (None) every :data:`CHECKPOINT_STEPS` steps once :data:`CHECKPOINT_SECONDS` of
    wall time have passed since ``saved_at[0]`` (rank 0's clock decides: collective then).
    A short run then writes its checkpoint at the end only, a long one loses at most about
    that much work to a killed process."""
    if every is not None:
        return bool(every) and step % every == 0
    if step % CHECKPOINT_STEPS:
        return False
    due = time.perf_counter() - saved_at[0] >= CHECKPOINT_SECONDS
    return comm.bcast(due) if comm.size > 1 else due
