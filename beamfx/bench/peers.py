"""beamfx beside the open codes users would pick instead ("peers"), measured in one run.

``make bench-peers`` runs three steps (see ``peers/README.md``)::

    python -m beamfx.bench.peers export DIR    # problems.json: the data the peer scripts read
    .venv-peers/bin/python peers/run.py DIR    # Exudyn, PyElastica, CalculiX: DIR/<code>.json
    python -m beamfx.bench.peers DIR REPORT    # beamfx on the same problems, merge, report

A peer record is ``{problem, code, element, setting, unknowns, wall_s, error, values}``
(``wall_s`` warm: the second of two identical solves). The merge recomputes every error
from ``values`` with the metric and reference of the beamfx case (:func:`.run._error`),
so beamfx and the peers are scored by the same numbers; where the reference is withheld
(spin-up, 45° bend) it is the finest beamfx setting, which is then not scored itself.
"""

import json
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

TARGET = 1e-6  # issue 7: the error at which beamfx must be ahead

# problem id -> (beamfx case id, settings (None: the case's own), what the problem is)
SPIN_DT = tuple(0.025 / 2**k for k in range(6))
X = "extrapolated"  # beamfx's scheme of runs at dt and dt/2 combined (analyses/extrapolation.py)
PROBLEMS = {
    "rollup_half": ("rollup_0.5", None, "roll-up to a half circle, tip moment π EI/L"),
    "rollup_full": ("rollup_1", None, "roll-up to a full circle, tip moment 2π EI/L"),
    "sm23": ("sm23_end_moments", None, "Schwab & Meijaard 2.3, fixed end moments"),
    "sm28": ("sm28_free_free_eigen", None, "Schwab & Meijaard 2.8, free-free frequencies"),
    "sm28_timoshenko": (
        "sm28_free_free_timoshenko",
        tuple((n, p) for p in (2, 3, 4) for n in (1, 2, 4, 8)) + ((16, 4),),
        "Schwab & Meijaard 2.8 with shear and rotary inertia: frequencies / Euler-Bernoulli",
    ),
    "spin_up": (
        "spin_up_time",
        tuple((4, 2, dt) for dt in SPIN_DT[:-1])
        + ((2, 2, SPIN_DT[0], X), (4, 2, SPIN_DT[0], X), (8, 2, SPIN_DT[0], X))
        + ((8, 3, SPIN_DT[2], X),),
        "spin-up manoeuvre (VM258), extremes over 0–18 s in the hub frame",
    ),
    "bend45": (
        "bend45_vertical",
        tuple((n, p) for p in (2, 3, 4) for n in (1, 2, 4, 8, 16)) + ((32, 4),),
        "45° bend, vertical tip load",
    ),
}


#: the element label of a beamfx record, by the formulation that solved it (bench.run)
ELEMENTS = {
    "full": "Simo-Reissner, quaternion field",
    "planar": "Simo-Reissner, planar (angle field)",
    "condensed": "Simo-Reissner, condensed (rotation vector field)",
    "planar condensed": "Simo-Reissner, planar condensed (angle field)",
}

# why the numbers look as they do (facts of the methods, not of one run)
NOTES = {
    "rollup_half": "Exudyn's two-node BeamGeometricallyExact interpolates on SE(3): a constant-"
    "curvature arc is in its interpolation space, so pure bending is exact (to Newton "
    "tolerance) with any number of elements and Exudyn reaches round-off in milliseconds. "
    "beamfx's scene builder picks its planar statically condensed model here (a plane "
    "cantilever under an end moment): the angle θ(s) is the only unknown, the exact θ = M s/EI "
    "lies in every P_k, and the centre line of a θ linear in a cell is integrated in closed "
    "form, so one P1 element (2 unknowns) is exact to round-off at any number of turns; the "
    "P3/P4 rows are the meshes the quaternion model needed (4 x P3: 5.6e-7 at 91 unknowns). "
    "PyElastica applies the end moment as a couple on the last element, which "
    "stays straight, so its tip lags by about one element length (first order in h).",
    "rollup_full": "As for the half circle: exact for Exudyn's SE(3) element from 4 elements "
    "(2 elements fail: each would turn by π, where the SE(3) logarithm is singular); exact for "
    "beamfx's planar condensed model from one element (no 2π limit on the angle). "
    "PyElastica's straight last element lands on the exact tip for the full circle by "
    "symmetry (the tip is the root), so its small error there is a coincidence of this load.",
    "sm23": "The section is 4:1 and the moments are fixed in space, so the curvature varies "
    "along the beam and no element is exact: Exudyn's two-node element converges at second "
    "order (error /4 per doubling), beamfx's P4 elements at high order.",
    "sm28": "Scored against the Euler-Bernoulli theory of the paper; that needs a shear-rigid "
    "beam without bending rotary inertia, which beamfx has as a model option. Exudyn's "
    "geometrically exact element locks under a shear penalty, so it is compared on "
    "sm28_timoshenko instead, where both codes solve the same shear-flexible beam.",
    "sm28_timoshenko": "The same free-free beam with its shear stiffness and full rotary "
    "inertia; values are frequencies divided by the Euler-Bernoulli theory, the reference is "
    "the finest beamfx setting (16 x P4). Exudyn's eigenvalues are dense "
    "(ComputeODE2Eigenvalues), beamfx's shift-invert SLEPc, one solve per frequency.",
    "spin_up": "Reference values are withheld (VM258): the reference is the last beamfx "
    'setting (8 x P3, scheme "extrapolated" at dt = 0.00625: generalized-α with ρ∞ = 0.8 at '
    "dt and dt/2, Richardson-combined; its error in time is about 1e-8, in space that of "
    "8 x P3). The plain beamfx rows and Exudyn use generalized-α with ρ∞ = 0.9, second "
    "order in time, so dt sets the error; the extrapolated rows (three Newton solves per "
    "step: 2.2 to 2.8 times the iterations of the plain run at the same dt) are third to fourth "
    "order in time, and at dt = 0.025 their error in time (2e-6) is below the error in space "
    "of 4 x P2 (1e-4), so the mesh sets it: 8 x P2 costs little more per iteration. At "
    "equal dt beamfx's planar model has fewer unknowns (4 quadratic elements, 27) than "
    "Exudyn's 32 two-node elements (99). The Exudyn hub angle is a Python offset user "
    "function, called at every Newton iteration. Exudyn's Newton absolute tolerance had to "
    "be raised to 1e-6 N: at its default, Newton stalls at round-off (EA = 2.8e7) and the "
    "adaptive step collapses (95 s instead of 0.6 s). With the plain scheme beamfx needs "
    "dt = 0.00625 (4 x P2, 4882 Newton iterations) for Exudyn's best error (32 elements at "
    "dt = 0.00125), at a wall time within a few per cent of Exudyn's: its cost per step "
    "(about 0.4 ms, 27 unknowns) is several times Exudyn's (0.2 ms per step at 99 unknowns), "
    "the assembly through DOLFINx/PETSc per step dominating at this size. The extrapolated "
    "rows at dt = 0.025 take about 5100 iterations, and their error is that of the mesh "
    "(4 x P2: 1e-4, 8 x P2: 7e-6). Near 1e-3 extrapolation does not pay: its coarsest "
    "usable dt is 0.025 (at 0.05 the base with ρ∞ = 0.8 needs cut-backs; with ρ∞ = 0.5 "
    "the mean stretch is off by 1.3 %), which costs more than the plain run at dt = 0.0125.",
    "bend45": "Reference withheld: the finest beamfx setting (32 x P4). Exudyn's two-node "
    "elements on the arc (nodes on the circle, chord lengths) converge at second order.",
}


def _cases():
    from . import all_cases

    cases = all_cases()
    out = {}
    for pid, (cid, settings, _) in PROBLEMS.items():
        case = cases[cid]
        out[pid] = replace(case, settings=settings) if settings else case
    return out


def _section(s):
    keys = ("EA", "GA_y", "GA_z", "GJ", "EI_y", "EI_z", "rho_A")
    return {k: float(getattr(s, k)) for k in keys} | {"rho_I": [float(x) for x in s.rho_I]}


def export(out_dir):
    """Write ``problems.json``: per problem the data a peer script needs (section
    stiffnesses exactly as beamfx builds them, loads, geometry) and the reference
    (None where withheld: then the merge scores against the finest beamfx setting)."""
    from . import classic, howcroft_2016, schwab_meijaard_2009, schwab_meijaard_eigen, transient

    cases = _cases()
    sm23 = schwab_meijaard_2009
    data = {
        "rollup_half": {"L": classic.L, "section": _section(classic.ROLL_SECTION)},
        "rollup_full": {"L": classic.L, "section": _section(classic.ROLL_SECTION)},
        "sm23": {"L": 1.0, "section": _section(sm23.S23), "moment": list(sm23.M23)},
        "sm28": {
            "L": schwab_meijaard_eigen.L28,
            "section": _section(schwab_meijaard_eigen.S28),
            "note": "Euler-Bernoulli theory: shear-rigid (GA large) and no bending rotary inertia",
        },
        "sm28_timoshenko": {
            "L": schwab_meijaard_eigen.L28,
            "section": _section(schwab_meijaard_eigen.S28),
            "theory": dict(schwab_meijaard_eigen.THEORY_28),
            "note": "real shear stiffness and full rotary inertia; values = omega / theory",
        },
        "spin_up": {"properties": transient.P, "t_end": 18.0, "rho_inf": 0.9},
        "bend45": {
            "geometry": howcroft_2016.V["geometry"],
            "section": _section(howcroft_2016.SECTION),
            "F_z": howcroft_2016.F,
        },
    }
    for pid, case in cases.items():
        lam = {"rollup_half": 0.5, "rollup_full": 1.0}.get(pid)
        if lam is not None:
            M = 2 * np.pi * lam * classic.ROLL_SECTION.EI_y / classic.L
            data[pid]["moment"] = [0.0, -M, 0.0]
        data[pid] |= {
            "beamfx_case": case.id,
            "beamfx_settings": [list(x) for x in case.settings],
            "title": PROBLEMS[pid][2],
            "reference": None if case.reference is None else dict(case.reference),
            "error_scale": case.scale,
        }
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    (out / "problems.json").write_text(json.dumps(data, indent=1, default=float))
    return data


def run_beamfx(out_dir, log=print):
    """Run beamfx on every problem through :func:`.run.run_case`; write ``beamfx.json``."""
    from .run import run_case

    records, refs = [], {}
    for pid, case in _cases().items():
        if log:
            log(f"beamfx {pid}: {case.id}")
        result = run_case(case, log)
        refs[pid] = result["reference"]
        finest = case.reference is None
        for i, row in enumerate(result["rows"]):
            setting = f"{row['elements']} x P{row['degree']}"
            if "dt" in row:
                setting += f", dt {row['dt']:g}"
            element = ELEMENTS[row.get("formulation", "full")]
            if "scheme" in row:  # a line of its own in the plot
                setting += f", {row['scheme']}"
                element += f"; {row['scheme']} in time"
            records.append(
                {
                    "problem": pid,
                    "code": "beamfx",
                    "element": element,
                    "setting": setting,
                    "unknowns": row["unknowns"],
                    "wall_s": row["wall_s_warm"],
                    "setup_s": row["wall_s_cold"] - row["wall_s_warm"],
                    "error": row["error"],
                    "values": row["values"],
                    "is_reference": finest and i == len(result["rows"]) - 1,
                }
            )
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    (out / "beamfx.json").write_text(json.dumps({"references": refs, "records": records}))
    return records, refs


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


def time_to(records, target):
    """Smallest warm wall time among ``records`` whose error is <= ``target`` (None: never)."""
    ok = [r["wall_s"] for r in records if r.get("error") is not None and r["error"] <= target]
    return min(ok) if ok else None


def summary(records, problem):
    """Per problem: the target error and, per line, the time to reach it and the best error."""
    rows = [r for r in records if r["problem"] == problem]
    peers = [r for r in rows if r["code"] != "beamfx" and r.get("error") is not None]
    best_peer = min((r["error"] for r in peers), default=None)
    target = max(TARGET, best_peer) if best_peer is not None else TARGET
    groups = {}
    for r in rows:
        groups.setdefault(line(r), []).append(r)
    out = {"target": target, "lines": {}}
    for name, group in groups.items():
        scored = [r for r in group if r.get("error") is not None]
        best = min(scored, key=lambda r: r["error"]) if scored else None
        out["lines"][name] = {
            "code": group[0]["code"],
            "time_to_target": time_to(group, target),
            "best_error": best["error"] if best else None,
            "best_wall_s": best["wall_s"] if best else None,
            "note": next((r["note"] for r in group if r.get("note")), ""),
        }
    fx = [v for v in out["lines"].values() if v["code"] == "beamfx"]
    t_fx = min((v["time_to_target"] for v in fx if v["time_to_target"] is not None), default=None)
    out["beamfx_time"] = t_fx
    out["beamfx_ahead"] = t_fx is not None and all(
        v["time_to_target"] is None or v["time_to_target"] > t_fx
        for v in out["lines"].values()
        if v["code"] != "beamfx"
    )
    return out


def _fmt(x, f="{:.2e}"):
    return "—" if x is None else f.format(x)


def plot(records, problem, title, path, target=None):
    """Error against wall time of every code on ``problem`` (log-log), saved to ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    groups = {}
    for r in records:
        if r["problem"] == problem and r.get("error") and r.get("wall_s"):
            groups.setdefault(line(r), []).append(r)
    for name, group in sorted(groups.items(), key=lambda g: g[0] != "beamfx"):
        group.sort(key=lambda r: r["wall_s"])
        style = "o-" if group[0]["code"] == "beamfx" else "s--"
        ax.loglog([r["wall_s"] for r in group], [r["error"] for r in group], style, label=name)
    if target:
        ax.axhline(target, color="grey", lw=0.8, ls=":", label=f"target {target:.1e}")
    ax.set_xlabel("warm wall time [s]")
    ax.set_ylabel("error")
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def markdown(records, problems, notes=None):
    """The report: a summary table (time to the target per code), then per problem the
    full table and its plot."""
    lines = [
        "# beamfx beside its peers",
        "",
        (
            "Generated by `make bench-peers`: the peer codes run in their own environment "
            "(`.venv-peers`; CalculiX from Debian), then beamfx, on the same machine in one run. "
            "Errors use the metric and reference of the beamfx case (the reference of withheld "
            "cases is the finest beamfx setting, marked *reference* and not scored). Wall times "
            "are warm: the second of two "
            "identical solves, so one-off costs (imports, JIT compilation, numba) are left out and "
            "shown separately where large. Target = the larger of 1e-6 and the best error any peer "
            "reaches; beamfx is *ahead* when it reaches the target in less time than every peer "
            "that reaches it."
        ),
        "",
        "| problem | target | beamfx s | " + "peers: s to target (best error) | beamfx ahead |",
        "|---|---|---|---|---|",
    ]
    sections = []
    for pid, meta in problems.items():
        s = summary(records, pid)
        peer_cells = []
        for name, v in s["lines"].items():
            if v["code"] == "beamfx":
                continue
            if v["best_error"] is None:
                peer_cells.append(f"{name}: {v['note'] or 'not run'}")
            else:
                peer_cells.append(
                    f"{name}: {_fmt(v['time_to_target'], '{:.3g}')} ({v['best_error']:.1e})"
                )
        lines.append(
            f"| {pid} | {s['target']:.1e} | {_fmt(s['beamfx_time'], '{:.3g}')} | "
            + "<br>".join(peer_cells or ["no peer"])
            + f" | {'yes' if s['beamfx_ahead'] else '**no**'} |"
        )
        sections += [
            "",
            f"## {pid}: {meta.get('title', '')}",
            "",
            f"beamfx case `{meta.get('beamfx_case', '')}`; target error {s['target']:.1e}.",
            "",
            f"![error against warm wall time, {pid}](peers_{pid}.png)",
            "",
            "| code (element) | setting | unknowns | warm s | error |",
            "|---|---|---|---|---|",
        ]
        for r in sorted(
            (r for r in records if r["problem"] == pid),
            key=lambda r: (
                r["code"] != "beamfx",
                line(r),
                r.get("unknowns") or 0,
                r["wall_s"] or 0,
            ),
        ):
            err = "reference" if r.get("is_reference") else _fmt(r.get("error"))
            if r.get("error") is None and not r.get("is_reference") and r.get("note"):
                err = r["note"]
            lines_wall = _fmt(r.get("wall_s"), "{:.3g}")
            sections.append(
                f"| {line(r)} | {r['setting']} | {r.get('unknowns') or '—'} | {lines_wall} | {err} |"
            )
        if notes and pid in notes:
            sections += ["", notes[pid]]
    return "\n".join(lines + sections) + "\n"


def load_peer_records(peer_dir):
    """The records of every peer code's JSON file in ``peer_dir``."""
    records = []
    for f in sorted(Path(peer_dir).glob("*.json")):
        if f.name in ("problems.json", "beamfx.json"):
            continue
        records += json.loads(f.read_text())["records"]
    return records


def load_peer_notes(peer_dir):
    """Per problem, the notes the peer scripts leave in their meta data (``"notes": {problem:
    text}``, e.g. what CalculiX could not do and why), joined in file order."""
    out = {}
    for f in sorted(Path(peer_dir).glob("*.json")):
        if f.name in ("problems.json", "beamfx.json"):
            continue
        for pid, text in json.loads(f.read_text()).get("meta", {}).get("notes", {}).items():
            out[pid] = f"{out[pid]} {text}" if pid in out else text
    return out


def merge(peer_dir, report_dir, run=True, log=print):
    """Write the peer report: beamfx records (run now, or read from ``peer_dir/beamfx.json``)
    + peer records -> ``report_dir/peers.md``, ``peers.json`` and one ``peers_<problem>.png``
    per problem."""
    peer_dir, report = Path(peer_dir), Path(report_dir)
    problems = json.loads((peer_dir / "problems.json").read_text())
    if run or not (peer_dir / "beamfx.json").exists():
        fx, refs = run_beamfx(peer_dir, log)
    else:
        d = json.loads((peer_dir / "beamfx.json").read_text())
        fx, refs = d["records"], d["references"]
    scales = {pid: p.get("error_scale") for pid, p in problems.items()}
    records = rescore(fx + load_peer_records(peer_dir), refs, scales)
    notes_file = peer_dir / "notes.json"
    notes = NOTES | (json.loads(notes_file.read_text()) if notes_file.exists() else {})
    for pid, text in load_peer_notes(peer_dir).items():
        notes[pid] = f"{notes[pid]} {text}" if pid in notes else text
    report.mkdir(parents=True, exist_ok=True)
    for pid, meta in problems.items():
        plot(
            records,
            pid,
            meta.get("title", pid),
            report / f"peers_{pid}.png",
            summary(records, pid)["target"],
        )
    (report / "peers.md").write_text(markdown(records, problems, notes))
    (report / "peers.json").write_text(json.dumps(records, indent=1, default=float))
    return records


def main(argv=None):
    """Command line: ``export DIR``, ``beamfx DIR`` or ``DIR REPORT_DIR [--no-run]``."""
    argv = list(sys.argv[1:] if argv is None else argv)
    usage = (
        "usage: python -m beamfx.bench.peers export DIR | beamfx DIR | DIR REPORT_DIR [--no-run]"
    )
    if len(argv) == 2 and argv[0] == "export":
        export(argv[1])
    elif len(argv) == 2 and argv[0] == "beamfx":
        t0 = time.perf_counter()
        run_beamfx(argv[1])
        print(f"beamfx: {time.perf_counter() - t0:.1f} s")
    elif len(argv) in (2, 3) and argv[0] not in ("export", "beamfx"):
        merge(argv[0], argv[1], run="--no-run" not in argv)
    else:
        raise SystemExit(usage)


if __name__ == "__main__":
    main()
