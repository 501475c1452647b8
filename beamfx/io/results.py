"""Result files: atomic JSON, and an early check that the output folder is writable."""

import json
import os
import tempfile

import numpy as np
from mpi4py import MPI


def _plain(obj):
    """JSON fallback for NumPy values and other sequences."""
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, (set, frozenset)):
        return sorted(obj)
    if hasattr(obj, "_asdict"):
        return obj._asdict()
    raise TypeError(f"{type(obj).__name__} is not JSON serialisable")


def write_json_atomic(path, obj, comm=MPI.COMM_WORLD, indent=1):
    """Write ``obj`` as JSON on rank 0: to a temporary file in the same folder, then rename.

    A reader never sees a half-written file, and an interrupted run leaves the previous one.
    NumPy arrays and scalars become lists and numbers.
    """
    if comm.rank != 0:
        return
    path = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=".tmp-", suffix=".json", dir=folder)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            # one write of the whole text (json.dump writes each of its many pieces)
            f.write(json.dumps(obj, indent=indent, default=_plain) + "\n")
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


def check_writable(folder, comm=MPI.COMM_WORLD):
    """Create ``folder`` if needed and check that a file can be written there. Collective.

    Call it before a solve, so that a wrong output path fails in a second, not after the
    analysis. Rank 0 checks (it is the only writer) and every rank raises the same error.

    Raises:
        OSError: naming the folder and the reason.
    """
    error = None
    if comm.rank == 0:
        folder = os.fspath(folder)
        try:
            os.makedirs(folder, exist_ok=True)
            with tempfile.TemporaryFile(dir=folder) as f:
                f.write(b"beamfx")
        except OSError as e:
            error = f"cannot write results to {os.path.abspath(folder)!r}: {e.strerror or e}"
    error = comm.bcast(error, root=0)
    if error:
        raise OSError(error)
