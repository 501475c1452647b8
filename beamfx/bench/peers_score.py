"""Scoring of peer records: errors against the beamfx reference, the time each code needs to
reach a target error (whole run or solve alone) and the verdict per problem. Used by
:mod:`.peers` (the merge) and :mod:`.peers_report` (the report)."""

import numpy as np

TARGET = 1e-6  # issue 7: the error at which beamfx must be ahead


def error(values, ref, scale):
    """The beamfx metric (:func:`.run._error`): max |v - ref| / scale, or relative per value."""
    if values is None or any(values.get(k) is None for k in ref):
        return None
    return float(max(abs(values[k] - ref[k]) / (scale or max(abs(ref[k]), 1e-300)) for k in ref))


def rescore(records, refs, scales):
    """Recompute each record's error against the beamfx reference of its problem."""
    for r in records:
        if r.get("is_reference"):
            r["error"] = None
        elif r["problem"] in refs and r.get("values"):
            r["error"] = error(r["values"], refs[r["problem"]], scales.get(r["problem"]))
        if r.get("error") is not None and not np.isfinite(r["error"]):
            r["error"], r["note"] = None, "diverged (NaN)"
    return records


def line(r):
    """The plot line / table group of a record: the code and its element."""
    return f"{r['code']} ({r['element']})" if r.get("element") else r["code"]


def at_target(records, target, key="whole_s"):
    """The record of ``records`` with error <= ``target`` and the least ``key`` time (None:
    none reaches it). ``key``: ``whole_s`` (the whole run) or ``wall_s`` (the solve alone)."""
    ok = [
        r
        for r in records
        if r.get("error") is not None and r["error"] <= target and r.get(key) is not None
    ]
    return min(ok, key=lambda r: r[key]) if ok else None


def time_to(records, target, key="whole_s"):
    """The least ``key`` time among ``records`` whose error is <= ``target`` (None: never)."""
    r = at_target(records, target, key)
    return None if r is None else r[key]


def _line_summary(group, target):
    """One code's figures on a problem: times to the target, best error, note."""
    scored = [r for r in group if r.get("error") is not None]
    best = min(scored, key=lambda r: r["error"]) if scored else None
    fastest = at_target(group, target)
    return {
        "code": group[0]["code"],
        "time_to_target": time_to(group, target),
        "solve_to_target": time_to(group, target, "wall_s"),
        "solve_at_target": None if fastest is None else fastest.get("wall_s"),
        "process_at_target": None if fastest is None else fastest.get("process_s"),
        "setting_at_target": None if fastest is None else fastest["setting"],
        "best_error": best["error"] if best else None,
        "note": next((r["note"] for r in group if r.get("note")), ""),
    }


def _ahead(lines, key):
    """(beamfx's least ``key`` time to the target, whether every peer that reaches the target
    takes longer, the fastest such peer (name, time) or None)."""
    fx = [v[key] for v in lines.values() if v["code"] == "beamfx" and v[key] is not None]
    t_fx = min(fx, default=None)
    others = [(v[key], n) for n, v in lines.items() if v["code"] != "beamfx" and v[key]]
    fastest = min(others, default=None)
    ahead = t_fx is not None and (fastest is None or fastest[0] > t_fx)
    return t_fx, ahead, None if fastest is None else (fastest[1], fastest[0])


def summary(records, problem):
    """Per problem: the target error and, per line, the times to reach it (whole run, solve
    only, process) and the best error; the verdict on whole runs and on the solve alone."""
    rows = [r for r in records if r["problem"] == problem]
    peers = [r for r in rows if r["code"] != "beamfx" and r.get("error") is not None]
    best_peer = min((r["error"] for r in peers), default=None)
    target = max(TARGET, best_peer) if best_peer is not None else TARGET
    groups = {}
    for r in rows:
        groups.setdefault(line(r), []).append(r)
    out = {"target": target, "lines": {n: _line_summary(g, target) for n, g in groups.items()}}
    t_fx, ahead, fastest = _ahead(out["lines"], "time_to_target")
    out |= {"beamfx_time": t_fx, "beamfx_ahead": ahead, "fastest_peer": fastest}
    t_solve, ahead_solve, fastest_solve = _ahead(out["lines"], "solve_to_target")
    out |= {"beamfx_solve_time": t_solve, "beamfx_ahead_solve": ahead_solve}
    out["fastest_peer_solve"] = fastest_solve
    fx = at_target([r for r in rows if r["code"] == "beamfx"], target)
    out["beamfx_at_target"] = fx
    return out


def curves(records, problem):
    """The curve of beamfx's error against whole-run time beside each peer's, over the errors
    both reach: ``{peer line: {"from": the least error both reach, "behind": [(error, beamfx
    s, peer s)], "floor": the record of beamfx's least whole run on the problem}}``. A curve is the least whole-run time to reach an error ≤ x (a step function
    of x); two of them are compared at every step of either (every setting's error) from the
    larger of their best errors up, which is where they can cross. ``behind`` lists the
    errors at which beamfx's time is the larger (empty: beamfx's curve lies below)."""
    rows = [
        r
        for r in records
        if r["problem"] == problem and r.get("error") is not None and r.get("whole_s") is not None
    ]
    fx = [r for r in rows if r["code"] == "beamfx"]
    groups = {}
    for r in rows:
        if r["code"] != "beamfx":
            groups.setdefault(line(r), []).append(r)
    out = {}
    for name, group in groups.items() if fx else ():
        lo = max(min(r["error"] for r in fx), min(r["error"] for r in group))
        steps = sorted({r["error"] for r in fx + group if r["error"] >= lo})
        pairs = [(e, time_to(fx, e), time_to(group, e)) for e in steps]
        behind = [(e, b, p) for e, b, p in pairs if b > p]
        out[name] = {"from": lo, "behind": behind, "floor": min(fx, key=lambda r: r["whole_s"])}
    return out
