"""Checkpoints of a run: plain arrays plus a JSON header, one file per rank, never a pickle.

A checkpoint is an ``.npz`` file (``checkpoint_<n>ranks_<r>.npz`` in the output folder) that
NumPy reads with ``allow_pickle=False``: the arrays of the state (float64, one dimension)
and ``header``, the UTF-8 bytes of a JSON object with the time, the step, the step
controller, the tracked rotations of the probes, and the fingerprints of the scene and the
mesh it was written for. Nothing in it is executed: a file with an object array, a truncated
or altered file, or a header of the wrong shape is refused with a message naming the file.

Reading is collective (:func:`read_checkpoints`): each rank reads its own file and the ranks
agree on the outcome, so a missing or damaged file of one rank stops every rank with the
same message instead of leaving the others waiting.
"""

import hashlib
import json
import math
import os
import re
import zipfile
from pathlib import Path

import numpy as np

FORMAT, VERSION = "beamfx-checkpoint", 1


class CheckpointError(ValueError):
    """A checkpoint that cannot be used: missing on some rank, damaged, or for another scene."""

    collective = True  # raised on every rank together (see read_checkpoints)


def checkpoint_path(folder, ranks, rank):
    """The checkpoint file of ``rank`` of a run on ``ranks`` ranks in ``folder``."""
    return Path(folder) / f"checkpoint_{ranks}ranks_{rank}.npz"


#: the name :func:`checkpoint_path` gives (ranks, rank)
CHECKPOINT_NAME = re.compile(r"checkpoint_(\d+)ranks_(\d+)\.npz")


def checkpoint_ranks(folder):
    """{number of ranks: [file names]} of the checkpoints in ``folder`` (none if missing)."""
    try:
        names = sorted(os.listdir(folder))
    except OSError:
        return {}
    found = {}
    for name in names:
        match = CHECKPOINT_NAME.fullmatch(name)
        if match:
            found.setdefault(int(match[1]), []).append(name)
    return found


def _digest(a):
    return hashlib.sha256(np.ascontiguousarray(a).tobytes()).hexdigest()


def write_checkpoint(path, header, arrays):
    """Write ``arrays`` (name -> 1-D float array) and the JSON ``header`` atomically: to a
    temporary file beside ``path``, flushed to disk, then renamed over it."""
    path = Path(path)
    arrays = {k: np.ascontiguousarray(v, dtype=np.float64).ravel() for k, v in arrays.items()}
    header = {
        "format": FORMAT,
        "version": VERSION,
        **header,
        "arrays": {k: {"size": int(a.size), "sha256": _digest(a)} for k, a in arrays.items()},
    }
    text = json.dumps(header, allow_nan=False).encode("utf-8")
    tmp = path.with_name(f".{path.stem}.{os.getpid()}.tmp.npz")
    with open(tmp, "wb") as f:
        np.savez(f, header=np.frombuffer(text, np.uint8), **arrays)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


def read_checkpoint(path):
    """(header, arrays) of one checkpoint file, checked.

    Raises:
        CheckpointError: naming the file and what is wrong with it.
    """
    try:
        with np.load(path, allow_pickle=False) as data:
            if "header" not in data.files:
                raise CheckpointError(f"{path}: not a beamfx checkpoint (no header)")
            raw = data["header"]
            arrays = {k: data[k] for k in data.files if k != "header"}
    except (zipfile.BadZipFile, EOFError, OSError, KeyError, ValueError) as e:
        if isinstance(e, CheckpointError):
            raise
        why = "it holds Python objects (pickles are refused)" if "pickle" in str(e) else str(e)
        raise CheckpointError(f"{path}: not a readable checkpoint: {why}") from None
    if raw.dtype != np.uint8 or raw.ndim != 1:
        raise CheckpointError(f"{path}: the header is not a byte string")
    try:
        header = json.loads(raw.tobytes().decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as e:
        raise CheckpointError(f"{path}: the header is not JSON: {e}") from None
    problems = list(_header_problems(header)) or list(_array_problems(header, arrays))
    if problems:
        raise CheckpointError(f"{path}: " + "; ".join(problems))
    return header, arrays


def _number(x, low=-math.inf):
    return isinstance(x, (int, float)) and not isinstance(x, bool) and low <= x < math.inf


def _header_problems(h):
    """What is wrong with a header's shape (not with its agreement with the run)."""
    if not isinstance(h, dict) or h.get("format") != FORMAT:
        yield f"not a beamfx checkpoint (format {FORMAT!r} expected)"
        return
    if h.get("version") != VERSION:
        yield f"checkpoint version {h.get('version')!r}; this beamfx reads version {VERSION}"
    for key, low in (("t", 0.0), ("size", 0.0)):
        if not _number(h.get(key), low):
            yield f"{key}: expected a finite number >= {low:g}, got {h.get(key)!r}"
    step = h.get("step")
    if not isinstance(step, int) or isinstance(step, bool) or step < 0:
        yield f"step: expected an integer >= 0, got {step!r}"
    for key in ("controller", "balance", "probes", "scene", "mesh", "arrays"):
        if not isinstance(h.get(key), dict):
            yield f"{key}: expected a table, got {h.get(key)!r}"


def _array_problems(h, arrays):
    listed = h["arrays"]
    if set(listed) != set(arrays):
        yield f"arrays {sorted(arrays)} differ from those its header lists: {sorted(listed)}"
        return
    for k, a in arrays.items():
        entry = listed[k] if isinstance(listed[k], dict) else {}
        if a.dtype != np.float64 or a.ndim != 1 or a.size != entry.get("size"):
            yield f"array {k!r} is {a.dtype}{list(a.shape)}, not float64[{entry.get('size')}]"
        elif _digest(a) != entry.get("sha256"):
            yield f"array {k!r} was altered (its checksum differs from the header's)"


def read_checkpoints(folder, comm):
    """This rank's (header, arrays), or None if no rank has a checkpoint for this number of
    ranks. Collective: every rank raises the same :class:`CheckpointError` if any rank's file
    is missing or damaged."""
    path = checkpoint_path(folder, comm.size, comm.rank)
    found, error, out = path.exists(), None, None
    if found:
        try:
            out = read_checkpoint(path)
        except CheckpointError as e:
            error = str(e)
    states = comm.allgather((found, error)) if comm.size > 1 else [(found, error)]
    if not any(f for f, _ in states):
        return None
    messages = [e for _, e in states if e]
    missing = [r for r, (f, _) in enumerate(states) if not f]
    if missing:
        names = ", ".join(checkpoint_path(folder, comm.size, r).name for r in missing)
        messages.insert(0, f"{folder}: the checkpoint of rank(s) {missing} is missing ({names})")
    if messages:
        raise CheckpointError("; ".join(messages))
    return out


def agree(problems, comm):
    """Raise :class:`CheckpointError` on every rank if any rank found ``problems`` (a list of
    strings); the message lists each problem once, in rank order. Collective."""
    every = comm.allgather(list(problems)) if comm.size > 1 else [list(problems)]
    unique = list(dict.fromkeys(p for part in every for p in part))
    if unique:
        raise CheckpointError("; ".join(unique))


__all__ = [
    "CheckpointError",
    "agree",
    "checkpoint_path",
    "read_checkpoint",
    "read_checkpoints",
    "write_checkpoint",
]
