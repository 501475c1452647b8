"""Fingerprints of a scene and a mesh, so that a checkpoint is used only by the run it is for.

The scene's fingerprint is its parsed description (the frozen dataclasses of the model, the
analysis settings and the probes) flattened to ``{key path: value}``, e.g.
``beams[0].section.EA: 1000000.0``, plus a SHA-256 of the canonical JSON of that table.
Keys that a restart may change are left out (:data:`RESTART_FREE`: the end time, the
checkpoint and frame intervals; ``[output]`` and ``[solver]`` are not part of it). Long
numeric lists (a gmsh or spline curve's points) enter as a hash of their values.

The mesh's fingerprint is its global counts and a hash of this rank's node coordinates (the
state arrays of a checkpoint are in this rank's numbering, so the partition must match too).
"""

import dataclasses
import functools
import hashlib
import json
from numbers import Integral, Real

import numpy as np

#: analysis settings a restart may change
RESTART_FREE = ("t_end", "checkpoint_every", "output_every")
LONG = 16  # numeric lists longer than this enter as a hash


def _plain(x):
    return json.loads(json.dumps(x, default=repr))


def _numeric(obj):
    """``obj`` as a numeric array, or None (ragged, or not numbers)."""
    try:
        a = np.asarray(obj)
    except (ValueError, TypeError):
        return None
    return a if a.dtype.kind in "fiu" else None


def _flatten(obj, path, out):
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        for f in dataclasses.fields(obj):
            if f.compare:  # caches (compare=False) are not part of the value
                _flatten(getattr(obj, f.name), f"{path}.{f.name}" if path else f.name, out)
    elif isinstance(obj, dict):
        for k in sorted(obj, key=str):
            _flatten(obj[k], f"{path}.{k}" if path else str(k), out)
    elif isinstance(obj, (list, tuple, np.ndarray)):
        a = _numeric(obj)
        if a is not None and a.size > LONG:
            digest = hashlib.sha256(np.ascontiguousarray(a, np.float64).tobytes()).hexdigest()
            out[path] = f"{a.size} values, sha256 {digest[:16]}"
        else:
            for i, v in enumerate(obj):
                _flatten(v, f"{path}[{i}]", out)
    elif isinstance(obj, functools.partial):
        _flatten(obj.func, f"{path}.function", out)
        _flatten(dict(enumerate(obj.args)) | obj.keywords, path, out)
    elif callable(obj):
        out[path] = getattr(obj, "text", None) or f"{obj.__module__}.{obj.__qualname__}"
    elif isinstance(obj, (bool, str)) or obj is None:
        out[path] = obj
    elif isinstance(obj, Integral):
        out[path] = int(obj)
    elif isinstance(obj, Real):
        out[path] = float(obj)
    else:
        out[path] = repr(obj)


def scene_fingerprint(model, analysis, settings, probes):
    """``{"sha256": ..., "values": {key path: value}}`` of a scene: its model (the
    :class:`~beamfx.spec.Model`), the analysis type and settings (less
    :data:`RESTART_FREE`) and the probes."""
    values = {}
    _flatten(model, "", values)
    values["analysis.type"] = analysis
    fields = {f.name: getattr(settings, f.name) for f in dataclasses.fields(settings)}
    _flatten({k: v for k, v in fields.items() if k not in RESTART_FREE}, "analysis", values)
    _flatten(dict(probes), "probes", values)
    values = _plain(values)
    text = json.dumps(values, sort_keys=True)
    return {"sha256": hashlib.sha256(text.encode()).hexdigest(), "values": values}


def mesh_fingerprint(model):
    """Counts of the model's mesh and unknowns (global), this rank's unknowns and a hash of
    its node coordinates."""
    mesh = model.mesh.mesh
    x = np.ascontiguousarray(mesh.geometry.x, np.float64)
    return {
        "elements": int(mesh.topology.index_map(1).size_global),
        "degree": int(model.degree),
        "unknowns": int(model.unknowns()),
        "local_unknowns": len(model.w.x.array),
        "coordinates": hashlib.sha256(x.tobytes()).hexdigest(),
    }


def _show(v):
    return "missing" if v is _MISSING else json.dumps(v)


_MISSING = object()


def scene_differences(saved, current):
    """What differs between two scene fingerprints: ``key: A in the checkpoint, B in the
    scene``, one string per key (empty if they agree)."""
    if saved.get("sha256") == current["sha256"]:
        return []
    old, new = saved.get("values", {}), current["values"]
    out = []
    for k in sorted(set(old) | set(new)):
        a, b = old.get(k, _MISSING), new.get(k, _MISSING)
        if a is _MISSING or b is _MISSING or json.dumps(a) != json.dumps(b):
            out.append(f"{k}: {_show(a)} in the checkpoint, {_show(b)} in the scene")
    return out or ["the scene's fingerprint differs"]


def mesh_differences(saved, current):
    """What differs between two mesh fingerprints (empty if they agree)."""
    counts = ("elements", "degree", "unknowns", "local_unknowns")
    out = [
        f"mesh {k}: {saved.get(k)!r} in the checkpoint, {current[k]!r} now"
        for k in counts
        if saved.get(k) != current[k]
    ]
    if not out and saved.get("coordinates") != current["coordinates"]:
        out.append("mesh: the same counts, but other node coordinates (another geometry)")
    return out


__all__ = ["mesh_differences", "mesh_fingerprint", "scene_differences", "scene_fingerprint"]
