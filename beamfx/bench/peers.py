"""beamfx beside the open codes users would pick instead ("peers"), measured in one run.

``make bench-peers`` runs these steps (and the frames beside OpenSeesPy, see ``peers/README.md``)::

    python -m beamfx.bench.peers export DIR         # problems.json: what the peer scripts read
    .venv-peers/bin/python peers/<code>_cases.py DIR  # Exudyn, PyElastica, CalculiX: <code>.json
    python -m beamfx.bench.peers DIR REPORT         # beamfx on the same problems, merge, report

A record is ``{problem, code, element, setting, unknowns, whole_s, first_s, wall_s,
process_s, error, values}``: the times are defined in :mod:`.peers_report` (``whole_s`` the
whole run in a warm process, on which the verdict stands; ``wall_s`` the solve alone). The
merge recomputes every error
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

from .peers_report import NOTES, markdown, plot
from .peers_score import TARGET, at_target, error, line, rescore, summary, time_to  # noqa: F401

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
        + tuple((n, 2, dt, X) for dt in (2 * SPIN_DT[0], SPIN_DT[0]) for n in (2, 4, 8))
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


def element_name(formulation):
    """The element column of a beamfx row: :data:`ELEMENTS` of its formulation, with the mixed
    form said (:func:`.model_choice.formulation` appends " mixed")."""
    base = formulation.removesuffix(" mixed")
    if base == formulation:
        return ELEMENTS[base]
    return f"{ELEMENTS[base]}, mixed (section force unknowns)"


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


def run_beamfx(out_dir, log=print, problems=None):
    """Run beamfx on every problem (or those named in ``problems``) through
    :func:`.run.run_case`; write ``beamfx.json``."""
    from .run import run_case

    records, refs = [], {}
    for pid, case in _cases().items():
        if problems and pid not in problems:
            continue
        if log:
            log(f"beamfx {pid}: {case.id}")
        result = run_case(case, log)
        refs[pid] = result["reference"]
        finest = case.reference is None
        for i, row in enumerate(result["rows"]):
            setting = f"{row['elements']} x P{row['degree']}"
            if "dt" in row:
                setting += f", dt {row['dt']:g}"
            element = element_name(row.get("formulation", "full"))
            if "scheme" in row:  # a line of its own in the plot
                setting += f", {row['scheme']}"
                element += f"; {row['scheme']} in time"
            records.append(
                {
                    "problem": pid,
                    "code": "beamfx",
                    "element": element,
                    "setting": setting,
                    "case_setting": [row["elements"], row["degree"]]
                    + [row[k] for k in ("dt", "scheme") if k in row],
                    "unknowns": row["unknowns"],
                    "whole_s": row.get("wall_s_whole"),
                    "first_s": row["wall_s_cold"],
                    "wall_s": row["wall_s_warm"],
                    "process_s": row.get("wall_s_process"),
                    "whole_split": row.get("whole_split"),  # the warm run's own split
                    "load_steps": row.get("load_steps"),
                    "error": row["error"],
                    "values": row["values"],
                    "is_reference": finest and i == len(result["rows"]) - 1,
                }
            )
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    (out / "beamfx.json").write_text(json.dumps({"references": refs, "records": records}))
    return records, refs


PEER_FILES = ("calculix.json", "exudyn.json", "pyelastica.json")  # what peers/*_cases.py write


def _peer_files(peer_dir):
    return [Path(peer_dir) / f for f in PEER_FILES if (Path(peer_dir) / f).exists()]


def load_peer_records(peer_dir):
    """The records of every peer code's JSON file in ``peer_dir``, with their process time
    (the file's ``meta.import_s`` + the record's first run); a file written before the
    whole-run times has its whole run made up as model build + warm solve."""
    records = []
    for f in _peer_files(peer_dir):
        data = json.loads(f.read_text())
        import_s = data.get("meta", {}).get("import_s")
        for r in data["records"]:
            if "whole_s" not in r and r.get("wall_s") is not None:
                r["whole_s"] = r["wall_s"] + (r.get("setup_s") or 0.0)
            if import_s is not None and r.get("first_s") is not None:
                r["process_s"] = import_s + r["first_s"]
            records.append(r)
    return records


def load_peer_notes(peer_dir):
    """Per problem, the notes the peer scripts leave in their meta data (``"notes": {problem:
    text}``, e.g. what CalculiX could not do and why), joined in file order."""
    out = {}
    for f in _peer_files(peer_dir):
        for pid, text in json.loads(f.read_text()).get("meta", {}).get("notes", {}).items():
            out[pid] = f"{out[pid]} {text}" if pid in out else text
    return out


def measure_processes(records, problems, log=print):
    """``beamfx run`` timed from outside (:func:`.process.process_seconds`) for the beamfx
    setting of each problem that reaches the target in the least whole-run time, where not
    yet measured; returns how many were measured."""
    import tempfile

    from .process import process_seconds

    measured = 0
    for pid, meta in problems.items():
        fx = summary(records, pid)["beamfx_at_target"]
        if fx is None or fx.get("process_s") is not None or not fx.get("case_setting"):
            continue
        with tempfile.TemporaryDirectory(prefix="beamfx-peers-") as folder:
            fx["process_s"] = process_seconds(meta["beamfx_case"], fx["case_setting"], folder)
        measured += 1
        if log:
            log(f"beamfx {pid} {fx['setting']}: beamfx run process {fx['process_s']:.2f} s")
    return measured


def measure_stack(records, problems, log=print):
    """The stack's fixed costs (:func:`.peers_stack.stack_costs`) of the beamfx setting that
    reaches the target where beamfx is not ahead on whole runs (a P1 setting), where not yet
    measured: the why-line's floor; returns how many were measured."""
    from . import all_cases
    from .peers_stack import stack_costs

    measured = 0
    for pid, meta in problems.items():
        s = summary(records, pid)
        fx = s["beamfx_at_target"]
        if s["beamfx_ahead"] or fx is None or fx.get("stack_s") is not None:
            continue
        setting = fx.get("case_setting") or []
        if len(setting) != 2 or setting[1] != 1:
            continue
        fx["stack_s"] = stack_costs(all_cases()[meta["beamfx_case"]], setting)
        measured += 1
        if log:
            parts = ", ".join(f"{k} {v:.2e}" for k, v in fx["stack_s"].items())
            log(f"beamfx {pid} {fx['setting']}: stack costs (s) {parts}")
    return measured


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
    measured = measure_processes(records, problems, log) + measure_stack(records, problems, log)
    if measured:  # kept for a later --no-run merge
        (peer_dir / "beamfx.json").write_text(json.dumps({"references": refs, "records": fx}))
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
    """Command line: ``export DIR``, ``beamfx DIR [PROBLEM ...]`` (beamfx's side alone, of
    the problems named) or ``DIR REPORT_DIR [--no-run]``."""
    argv = list(sys.argv[1:] if argv is None else argv)
    usage = (
        "usage: python -m beamfx.bench.peers export DIR | beamfx DIR [PROBLEM ...] | "
        "DIR REPORT_DIR [--no-run]"
    )
    if len(argv) == 2 and argv[0] == "export":
        export(argv[1])
    elif len(argv) >= 2 and argv[0] == "beamfx":
        unknown = set(argv[2:]) - set(PROBLEMS)
        if unknown:
            raise SystemExit(f"unknown problems {sorted(unknown)}; known: {list(PROBLEMS)}")
        t0 = time.perf_counter()
        records, _ = run_beamfx(argv[1], problems=argv[2:])
        for r in records:
            print(
                f"{r['problem']} {r['setting']}: whole {r['whole_s']:.4f} s, solve {r['wall_s']:.5f} s"
            )
        print(f"beamfx: {time.perf_counter() - t0:.1f} s")
    elif len(argv) in (2, 3) and argv[0] not in ("export", "beamfx"):
        merge(argv[0], argv[1], run="--no-run" not in argv)
    else:
        raise SystemExit(usage)


if __name__ == "__main__":
    main()
