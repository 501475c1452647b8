"""Shared helpers of the peer scripts: problem data, records, timing, rotations.

Runs in `.venv-peers` (numpy only; no beamfx, no DOLFINx). The problem data and the
references come from `problems.json`, which `python -m beamfx.bench.peers export DIR` writes
from the beamfx cases (section stiffnesses exactly as beamfx builds them; references read by
beamfx from its json files beamfx/bench/*.json, or computed there where the file has only a
formula). The merge step recomputes every error with the beamfx metric anyway.
"""

import json
import math
import subprocess
import sys
import time
from pathlib import Path

import numpy as np


def load_problems(out_dir):
    return json.loads((Path(out_dir) / "problems.json").read_text())


def error(values, problem):
    """beamfx's metric: max |v - ref| / scale (scale None: relative per value); None where
    the reference is withheld (the merge fills it in from the finest beamfx setting)."""
    ref, scale = problem.get("reference"), problem.get("error_scale")
    if ref is None or values is None:
        return None
    return float(max(abs(values[k] - ref[k]) / (scale or max(abs(ref[k]), 1e-300)) for k in ref))


def warm(run):
    """Call ``run()`` twice; return (second result, second wall time, first wall time)."""
    t0 = time.perf_counter()
    run()
    cold = time.perf_counter() - t0
    t1 = time.perf_counter()
    out = run()
    return out, time.perf_counter() - t1, cold


def import_seconds(*modules):
    """Wall time of a fresh interpreter that only imports ``modules`` (the second of two
    runs, so the disk cache is warm): the one-off start of a user's script."""
    code = "; ".join(f"import {m}" for m in modules) or "pass"
    for _ in range(2):
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-c", code], check=True, capture_output=True)
        seconds = time.perf_counter() - t0
    return seconds


def whole_times(wall_s, extra):
    """The whole-run times of a record: ``whole_s`` = model build (``setup_s``) + the warm
    solve, ``first_s`` = build + the first solve (first calls, numba JIT); None where the
    solve failed."""
    setup = extra.get("setup_s") or 0.0
    cold = extra.get("cold_s")
    return {
        "whole_s": None if wall_s is None else setup + wall_s,
        "first_s": None if wall_s is None or cold is None else setup + cold,
    }


def record(problem_id, problem, code, element, setting, unknowns, wall_s, values, **extra):
    """One peer record; ``wall_s`` is the warm solve (the second of two identical solves),
    ``extra`` may hold ``setup_s`` (model build) and ``cold_s`` (the first solve)."""
    err = error(values, problem) if values is not None else None
    r = {
        "problem": problem_id,
        "code": code,
        "element": element,
        "setting": setting,
        "unknowns": unknowns,
        "wall_s": wall_s,
        **whole_times(wall_s, extra),
        "error": err,
        "values": values,
    }
    r.update(extra)
    e = "—" if err is None else f"{err:.2e}"
    w = "—" if wall_s is None else f"{wall_s:.3g} s"
    print(
        f"  {code} {problem_id} {element} {setting}: {unknowns} unknowns, {w}, error {e}",
        flush=True,
    )
    return r


def write(out_dir, code, records, meta=None, imports=()):
    """Write DIR/<code>.json; ``meta["import_s"]`` = :func:`import_seconds` of ``imports``
    (0 for a code run as its own program, e.g. ccx: its process time is its whole run)."""
    meta = dict(meta or {}, import_s=import_seconds(*imports) if imports else 0.0)
    path = Path(out_dir) / f"{code}.json"
    path.write_text(
        json.dumps({"code": code, "meta": meta, "records": records}, indent=1, default=float)
    )
    print(f"wrote {path} ({len(records)} records)")


def axis_angle(R):
    """Unit axis and angle in [0, π] of a rotation matrix (as beamfx reports a tip rotation)."""
    R = np.asarray(R, float).reshape(3, 3)
    c = np.clip((np.trace(R) - 1) / 2, -1.0, 1.0)
    angle = math.acos(c)
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    s = np.linalg.norm(w)
    if s > 1e-8:
        return w / s, angle
    # near 0 or π: the axis is the dominant column of R + I
    B = R + np.eye(3)
    k = int(np.argmax(np.linalg.norm(B, axis=0)))
    return B[:, k] / max(np.linalg.norm(B[:, k]), 1e-300), angle


def rotation_values(u, R):
    """The values of Schwab & Meijaard 2.3 as beamfx measures them."""
    axis, angle = axis_angle(R)
    return {
        "u_x": u[0],
        "u_y": u[1],
        "u_z": u[2],
        "e_x": axis[0],
        "e_y": axis[1],
        "e_z": axis[2],
        "phi": angle,
    }


def _spin_measure():
    """beamfx's spin-up measure (beamfx/bench/spin_measure.py, numpy only), loaded by its path:
    this venv has none of beamfx's dependencies, and both sides must score alike."""
    import importlib.util

    path = Path(__file__).resolve().parents[1] / "beamfx" / "bench" / "spin_measure.py"
    spec = importlib.util.spec_from_file_location("beamfx_spin_measure", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


_SPIN = _spin_measure()
hub_angle, spin_up_values = _SPIN.hub_angle, _SPIN.spin_up_values


def out_dir():
    if len(sys.argv) < 2:
        raise SystemExit(f"usage: {sys.argv[0]} DIR (with DIR/problems.json)")
    return sys.argv[1]
