"""Run benchmark cases and write the JSON and markdown report."""

import json
from itertools import pairwise
from pathlib import Path

import numpy as np

from .model_choice import formulation
from .profiling import newton_seconds, per_iteration


def _error(case, values, ref):
    diffs = [abs(values[k] - ref[k]) / (case.scale or max(abs(ref[k]), 1e-300)) for k in ref]
    return float(max(diffs))


def run_setting(case, elements, degree):
    """One setting through ``beamfx run``'s path, twice: cold (first in this process: JIT or
    cache load included) and warm (again: forms compiled); both write the output a user's
    run writes. The solve-only time and its split are the analysis's own figures."""
    import tempfile

    from ..solvers.forms import compile_seconds
    from .profiling import jit_seconds, stack_limits
    from .scenes import case_scene, run_in_process

    scene = case_scene(case, elements, degree)
    with tempfile.TemporaryDirectory(prefix="beamfx-bench-") as folder:
        c0 = compile_seconds[0]
        run, cold = run_in_process(scene, folder)
        jit = compile_seconds[0] - c0
        warm_run, warm = run_in_process(scene, folder)
    result = warm_run.result
    model = _model_of(scene, case)
    if result.status != "converged":  # a bench setting that fails is a finding, said as such
        raise RuntimeError(f"{case.id} {elements} x P{degree}: {result.status}: {result.reason}")
    path = [
        {"load_factor": float(p["load_factor"]), **case.measure(p["probes"])}
        for p in run.result.path
    ]
    return {
        "elements": elements,
        "degree": degree,
        "unknowns": run.model["unknowns"],
        "formulation": formulation(run.model),
        "newton_iterations": run.result.newton_iterations,
        "load_steps": len(run.result.load_steps),
        "wall_s_cold": cold,
        "wall_s_whole": warm,
        # the warm run's own split (results.json wall_time_s: model, solve, output per step)
        "whole_split": {k: float(v) for k, v in warm_run.wall_time_s.items()},
        "wall_s_warm": newton_seconds(result.seconds),
        "jit_s": jit,
        "warm_per_iteration_s": per_iteration(result.seconds, result.newton_iterations),
        "linear_solver": warm_run.get("linear_solver"),
        **jit_seconds(case.id, model),
        **stack_limits(model),
        "values": {k: float(v) for k, v in case.measure(run.probes).items()},
        "path": [{k: float(v) for k, v in p.items()} for p in path],
    }


def _model_of(scene, case):
    """The model the run of ``scene`` solves (condensed where the scene builder chose it)."""
    from mpi4py import MPI

    from ..analyses.planar_condensed import build_model

    return build_model(scene.model, MPI.COMM_WORLD, case.probes.values(), scene.condense)


def rates(rows):
    """Observed convergence order between successive element doublings of the same degree."""
    out = []
    for a, b in pairwise(rows):
        if "dt" in a and "dt" in b and a["elements"] == b["elements"]:  # order in time
            same = a.get("scheme") == b.get("scheme")
            if (
                same
                and abs(b["dt"] - a["dt"] / 2) < 1e-12 * a["dt"]
                and a["error"] > 0 < b["error"]
            ):
                rate = float(np.log2(a["error"] / b["error"]))
                out.append({"degree": a["degree"], "dt": b["dt"], "rate": rate})
            continue
        if (
            a["degree"] == b["degree"]
            and b["elements"] == 2 * a["elements"]
            and a["error"] > 0
            and b["error"] > 0
        ):
            out.append(
                {
                    "degree": a["degree"],
                    "elements": b["elements"],
                    "rate": float(np.log2(a["error"] / b["error"])),
                }
            )
    return out


def criterion_1mm(rows):
    """Per degree, the smallest model whose tip moves by < 1 mm when its elements double."""
    best = {}
    for a in rows:
        for b in rows:
            if b["degree"] == a["degree"] and b["elements"] == 2 * a["elements"]:
                move = max(abs(a["values"][k] - b["values"][k]) for k in a["values"])
                # lengths in inches (Bathe-Bolourchi); the published criterion is 1 mm
                if move < 1.0 / 25.4 and a["degree"] not in best:
                    best[a["degree"]] = {
                        "elements": a["elements"],
                        "unknowns": a["unknowns"],
                        "move": move,
                    }
    return best


def run_case(case, log=print):
    """Run every setting of ``case`` and score it against the reference: one result dict."""
    rows = []
    for setting in case.settings:  # (elements, degree) or, for transients, (…, dt)
        n, p = setting[:2]
        row = (
            case.run_setting(*setting) if hasattr(case, "run_setting") else run_setting(case, n, p)
        )
        rows.append(row)
        if log:
            dt = f", dt {row['dt']:g}" if "dt" in row else ""
            log(
                f"  {case.id}: {n} x P{p}{dt}, {row['unknowns']} unknowns, "
                f"{row['newton_iterations']} Newton its, cold {row['wall_s_cold']:.2f} s, "
                + (f"whole run {row['wall_s_whole']:.3f} s, " if "wall_s_whole" in row else "")
                + f"solve {row['wall_s_warm']:.3f} s"
            )
    ref_is_finest = case.reference is None
    ref = rows[-1]["values"] if ref_is_finest else case.reference
    for row in rows:
        row["error"] = _error(case, row["values"], ref)
    scored = rows[:-1] if ref_is_finest else rows
    passing = [r for r in scored if r["error"] <= case.tolerance]
    cheapest = min(passing, key=lambda r: (r["unknowns"], r["wall_s_warm"])) if passing else None
    if cheapest is not None and "wall_s_whole" in cheapest:
        import tempfile

        from .process import process_seconds

        setting = (cheapest["elements"], cheapest["degree"])
        setting += (cheapest["dt"],) if "dt" in cheapest else ()
        setting += (cheapest["scheme"],) if "scheme" in cheapest else ()
        with tempfile.TemporaryDirectory(prefix="beamfx-bench-") as folder:
            cheapest["wall_s_process"] = process_seconds(case.id, setting, folder)
    out = {
        "id": case.id,
        "paper": case.paper,
        "title": case.title,
        "note": case.note,
        "own_model": case.own_model,
        "reference": {k: float(v) for k, v in ref.items()},
        "reference_is_finest_setting": ref_is_finest,
        "tolerance": case.tolerance,
        "error_scale": case.scale or "relative",
        "rows": rows,
        "rates": rates(rows),
        "cheapest_within_tolerance": cheapest,
        "passed": cheapest is not None,
        "extra": case.extra,
    }
    for key in ("path", "history"):  # kept for the plots, of the finest setting only
        series = [row.pop(key, None) for row in rows][-1]
        if series and len(series) > 2:
            out[key] = series
    if "problem_size" in case.extra:
        out["criterion_1mm"] = criterion_1mm(rows)
    if "spread" in case.extra:
        lo, hi = (np.array(x) for x in case.extra["spread"])
        tip = np.array([ref[k] for k in ("x", "y", "z")])
        out["inside_published_spread"] = bool(np.all(tip >= lo - 1e-9) and np.all(tip <= hi + 1e-9))
        out["passed"] = out["passed"] and out["inside_published_spread"]
    return out


def _s(row, key):
    """Seconds of ``key`` in a row, or "-" where the case does not measure it."""
    return f"{row[key]:.3f}" if key in row else "-"


def _case_lines(r, figures):
    """The report section of one case: reference, table of settings, profile, orders."""
    from .model_choice import case_model_line
    from .profiling import case_lines, iteration_line

    lines = []
    lines += [
        "",
        f"## {r['id']}: {r['title']}",
        "",
        f"*{r['paper']}.* {r['note']}",
        "",
        case_model_line(r),
        "",
        *(
            [f"![{r['id']}: convergence and cost]({figures[r['id']]})", ""]
            if r["id"] in figures
            else []
        ),
        "Reference: "
        + ", ".join(f"{k} = {v:.10g}" for k, v in r["reference"].items())
        + (" (finest setting)" if r["reference_is_finest_setting"] else ""),
        "",
        f"Tolerance {r['tolerance']:g} ({'relative' if r['error_scale'] == 'relative' else 'absolute / ' + str(r['error_scale'])}).",
        "",
        "| elements x degree | unknowns | Newton its | cold s | whole run s | solve only s "
        "| error | " + " | ".join(r["reference"]) + " |",
        "|---|---|---|---|---|---|---|" + "---|" * len(r["reference"]),
    ]
    for row in r["rows"]:
        dt = f", dt = {row['dt']:g}" if "dt" in row else ""
        lines.append(
            f"| {row['elements']} x P{row['degree']}{dt} | {row['unknowns']} | {row['newton_iterations']} | "
            f"{row['wall_s_cold']:.2f} | {_s(row, 'wall_s_whole')} | {row['wall_s_warm']:.3f} | "
            f"{row['error']:.2e} | "
            + " | ".join(f"{row['values'][k]:.8g}" for k in r["reference"])
            + " |"
        )
    lines += case_lines(r)  # adaptive and planar-vs-full tables
    c = r["cheapest_within_tolerance"]
    if c and "warm_per_iteration_s" in c:
        lines += ["", iteration_line(c)]
    if r["rates"]:
        lines += [
            "",
            "Observed order: "
            + ", ".join(
                (
                    f"in time at dt = {x['dt']:g}: {x['rate']:.2f}"
                    if "dt" in x
                    else f"P{x['degree']} at {x['elements']} el: {x['rate']:.2f}"
                )
                for x in r["rates"]
            ),
        ]
    if "criterion_1mm" in r:
        lines += [
            "",
            "1 mm criterion (fewest unknowns): "
            + ", ".join(
                f"P{p}: {v['elements']} elements, {v['unknowns']} unknowns"
                for p, v in r["criterion_1mm"].items()
            )
            + "; published: "
            + ", ".join(
                f"{k}: " + (f"{v['dofs']} dofs" if "dofs" in v else f"{v['states']} states")
                for k, v in r["extra"]["problem_size"].items()
            ),
        ]
    if "inside_published_spread" in r:
        lines += [
            "",
            f"Converged tip inside the published spread: {r['inside_published_spread']}",
        ]
    return lines


def markdown(results, figures=None, note=None):
    """The report; ``figures`` maps case ids (and "summary") to PNG files beside it, ``note``
    says why there are none."""
    from .model_choice import intro_lines, model_cell

    figures = figures or {}
    lines = [
        "# beamfx validation report",
        "",
        (
            "Generated by `beamfx bench --report docs/validation`. Error is against the reference "
            "(exact, independent, or the finest setting where the reference is withheld); wall "
            "times on the machine that ran it. **whole run** = `beamfx run`'s path in-process "
            "(`run_scene`: model, solve, probes, ParaView output as the scene asks), warm JIT "
            "cache, second run in the process; **process** = `beamfx run` of the cheapest "
            "setting as a process of its own, interpreter start and imports included, the "
            "second of two (`python -m beamfx.bench.process`); **solve only** = the Newton iterations' own "
            "time (assembly, linear solves, SNES; for eigen cases the eigen assembly and "
            "solve) inside that run, labelled as such; cold = the first run in the process (JIT "
            "or cache load included). A setting of several runs (one per target frequency or "
            "load) sums them. Cases marked * still run their own solver path (torque buckling, "
            "rotating and adaptive cases): their times are solve-only."
        ),
        "",
        (
            "Elsewhere: beamfx beside Exudyn and PyElastica on the same problems, "
            "[peers.md](peers.md) (`make bench-peers`); the 3D solid against the beam, "
            "[../solid.md](../solid.md), and at 231k unknowns on 1 and 2 ranks beside the beam, "
            "[solid_scaling.md](solid_scaling.md) (`make bench-solid-scaling`); lattice frames "
            "from 10³ to 10⁶ unknowns on 1 and 2 ranks, direct and iterative, "
            "[frame_scaling.md](frame_scaling.md) (`make bench-frame-scaling`); the Pai beam "
            "sweeps, [../pai_beam.md](../pai_beam.md); what the ParaView frames cost, per frame "
            "up to 10^4 frames and in whole runs, [output_cost.md](output_cost.md) "
            "(`python -m beamfx.bench.output_cost`)."
        ),
        *intro_lines(),
        "",
    ]
    if note:
        lines += [f"*{note}*", ""]
    if "summary" in figures:
        lines += [
            f"![Error over tolerance against warm wall time, every case]({figures['summary']})",
            "",
        ]
    lines += [
        (
            "| case | passed | cheapest within tolerance | model | error | unknowns | "
            "whole run s | process s | solve only s |"
        ),
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        c = r["cheapest_within_tolerance"]
        star = "" if c is None or "wall_s_whole" in c else " *"
        lines.append(
            f"| {r['id']}{star} | {'yes' if r['passed'] else 'NO'} | "
            + (
                f"{c['elements']} x P{c['degree']} | {model_cell(r, c)} | {c['error']:.2e} | "
                f"{c['unknowns']} | {_s(c, 'wall_s_whole')} | {_s(c, 'wall_s_process')} | "
                f"{c['wall_s_warm']:.3f} |"
                if c
                else f"- | {model_cell(r, r['rows'][-1] if r['rows'] else None)} | - | - | - | - | - |"
            )
        )
    from .profiling import profile_lines

    lines += profile_lines(results)
    for r in results:
        lines += _case_lines(r, figures)
    return "\n".join(lines) + "\n"


def run_bench(ids=None, report=None, log=print):
    """Run the cases ``ids`` (default all); with ``report``, write bench.json, plots, README.md."""
    from . import all_cases

    cases = all_cases()
    chosen = [cases[i] for i in ids] if ids else list(cases.values())
    results = []
    for case in chosen:
        if log:
            log(f"{case.id}: {case.title}")
        results.append(run_case(case, log))
    if report:
        out = Path(report)
        out.mkdir(parents=True, exist_ok=True)
        (out / "bench.json").write_text(json.dumps(results, indent=1, default=float))
        figures, note = {}, None
        try:
            from .plots import write_plots

            figures = write_plots(results, out)
        except ImportError as e:
            note = f"No plots: matplotlib is missing ({e}); pip install matplotlib"
        (out / "README.md").write_text(markdown(results, figures, note))
    return results
