"""The report of :mod:`beamfx.bench.peers`: ``peers.md`` (summary table, then per problem the
full table, its plot and why the numbers look as they do) and the error-against-time plots.

Times (seconds; each record's fields):

* ``whole_s``: the whole run as a user waits for it in a warm process. beamfx: the second
  :func:`~beamfx.runner.run_scene` of the setting's scene (model, solve, probes, output as the
  scene asks); peers: model build + solve, the second of two identical runs (no files).
* ``first_s``: the first such run in the process (JIT compilation or its cache, numba, first
  calls).
* ``process_s``: a fresh process. beamfx: ``beamfx run`` of the setting timed from outside
  (:mod:`.process`), measured for the setting that reaches the target; peers: a fresh
  interpreter that imports the code (``meta.import_s``) + ``first_s``; CalculiX: its first
  ``ccx`` run (a program of its own).
* ``wall_s``: the solve alone, warm (beamfx: assembly and linear solves; Exudyn: its
  solver call on the assembled system; PyElastica: the whole relaxation; ccx: the process).

The verdict uses whole runs; the solve-only verdict stands beside it.
"""

from .peers_score import curves, line, summary

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
    'setting (8 x P3, scheme "extrapolated" at dt = 0.00625: generalized-α with ρ∞ = 0.7 at '
    "dt and dt/2, Richardson-combined; its error in time is about 1e-8, in space that of "
    "8 x P3). The plain beamfx rows and Exudyn use generalized-α with ρ∞ = 0.9, second "
    "order in time, so dt sets the error; the extrapolated rows (three Newton solves per "
    "step, the coarse one started from the fine copy's result: about 2.1 times the "
    "iterations of the plain run at the same dt) are third to fourth order in time, and at "
    "dt = 0.025 their error in time (2e-6) is below the error in space "
    "of 4 x P2 (1e-4), so the mesh sets it: 8 x P2 costs little more per iteration. At "
    "equal dt beamfx's planar model has fewer unknowns (4 quadratic elements, 27) than "
    "Exudyn's 32 two-node elements (99). The Exudyn hub angle is a Python offset user "
    "function, called at every Newton iteration. Exudyn's Newton absolute tolerance had to "
    "be raised to 1e-6 N: at its default, Newton stalls at round-off (EA = 2.8e7) and the "
    "adaptive step collapses (95 s instead of 0.6 s). With the plain scheme beamfx needs "
    "dt = 0.00625 (4 x P2, 4882 Newton iterations) for Exudyn's best error (32 elements at "
    "dt = 0.00125), but its cost per step (solve s / (18 s / dt) in the table) is higher "
    "than Exudyn's at this size: each step assembles through DOLFINx/PETSc, where Exudyn "
    "evaluates its two-node elements in C++. The extrapolated "
    "rows at dt = 0.025 take about 4650 iterations, and their error is that of the mesh "
    "(4 x P2: 1e-4, 8 x P2: 1e-5); at dt = 0.05 (about 2760 iterations) the error in time "
    "(1e-4) is that of the mesh of 4 x P2, and 2 x P2 (1.6e-3) is mesh-bound at either dt. "
    "The base ρ∞ = 0.7 is the largest that runs the extrapolated spin-up at dt = 0.05 "
    "with a margin: with 0.8 Newton diverges near t = 17 s (Ω·dt = 0.3), and cut-backs "
    "excite the axial mode (ω ≈ 760 rad/s), which spoils the mean stretch; 0.75 runs at "
    "0.05 but not at 0.0625, 0.7 at both; a lower ρ∞ moves the mean stretch further (at "
    "dt = 0.05: 1.8e-4 with 0.7, 2.2e-3 with 0.6, 1.3 % with 0.5). Error-controlled steps "
    "(tolerance) do not pay here: the local error estimate in the inertial frame is that of "
    "the rigid rotation, so the steps shrink as Ω grows (dt 0.011 at Ω = 6 for tolerance "
    "1e-5) while the scored extremes are set during the spin-up, where the steps are "
    "longest (tolerance 1e-5: 7.3e-3, as fixed dt = 0.025, in 1039 steps); an estimate on "
    "the rotations alone changes the step all along, and each change excites the axial "
    "mode (mean stretch off by 50 %).",
    "bend45": "Reference withheld: the finest beamfx setting (32 x P4). Exudyn's two-node "
    "elements on the arc (nodes on the circle, chord lengths) converge at second order.",
}


def _fmt(x, f="{:.2e}"):
    return "—" if x is None else f.format(x)


def _g(x):
    return _fmt(x, "{:.3g}")


def plot(records, problem, title, path, target=None):
    """Error against whole-run time of every code on ``problem`` (log-log), beamfx's
    solve-only times dotted beside its whole runs; saved to ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    groups = {}
    for r in records:
        if r["problem"] == problem and r.get("error") and r.get("whole_s"):
            groups.setdefault(line(r), []).append(r)
    for name, group in sorted(groups.items(), key=lambda g: g[1][0]["code"] != "beamfx"):
        group.sort(key=lambda r: r["whole_s"])
        fx = group[0]["code"] == "beamfx"
        (h,) = ax.loglog(
            [r["whole_s"] for r in group],
            [r["error"] for r in group],
            "o-" if fx else "s--",
            label=f"{name}, whole run",
        )
        if fx and all(r.get("wall_s") for r in group):
            solve = sorted(group, key=lambda r: r["wall_s"])
            x, y = [r["wall_s"] for r in solve], [r["error"] for r in solve]
            ax.loglog(x, y, ":", color=h.get_color(), alpha=0.6, label="beamfx, solve only")
    if target:
        ax.axhline(target, color="grey", lw=0.8, ls=":", label=f"target {target:.1e}")
    ax.set_xlabel("whole-run wall time (warm process) [s]")
    ax.set_ylabel("error")
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


INTRO = (
    "Generated by `make bench-peers`: the peer codes run in their own environment "
    "(`.venv-peers`; CalculiX from Debian), then beamfx, on the same machine in one run (a "
    "shared 2-core machine: times are noisy, ±30 %). Errors use the metric and reference of "
    "the beamfx case (the reference of withheld cases is the finest beamfx setting, marked "
    "*reference* and not scored). Target = the larger of 1e-6 and the best error any peer "
    "reaches. **Times are whole runs** as a user waits for them in a warm process: for beamfx "
    "the scene through `run_scene` (the call behind `beamfx run`: model, solve, probes, output "
    "as the scene asks), for a peer its model build and solve; *solve* is the solve alone. "
    "*process* adds the one-off start: for beamfx `beamfx run` of that setting timed from "
    "outside (interpreter, imports, form cache, model, solve, output; the second of two "
    "processes); for a peer a fresh interpreter importing it (the second of two) plus its "
    "first run (numba JIT and first calls included); for "
    "CalculiX its first `ccx` run. beamfx is *ahead* when its whole run reaches the target "
    "in less time than every peer's that reaches it; the solve-only verdict is beside it. "
    "Linear space frames beside OpenSeesPy: [peers_frames.md](peers_frames.md)."
)


def _beamfx_cell(s):
    fx = s["beamfx_at_target"]
    if fx is None:
        return "—"
    return (
        f"{_g(fx['whole_s'])} ({fx['setting']}; solve {_g(fx.get('wall_s'))}; "
        f"process {_g(fx.get('process_s'))})"
    )


def _peer_cell(name, v):
    if v["best_error"] is None:
        return f"{name}: {v['note'] or 'not run'}"
    if v["time_to_target"] is None:
        return f"{name}: — (best {v['best_error']:.1e})"
    return (
        f"{name}: {_g(v['time_to_target'])} ({v['setting_at_target']}; solve "
        f"{_g(v['solve_at_target'])}; process {_g(v['process_at_target'])}; best "
        f"{v['best_error']:.1e})"
    )


def _yes(x):
    return "yes" if x else "**no**"


def _solve_verdict(s):
    """The solve-only verdict with beamfx's and the fastest peer's least solve times."""
    fastest = s["fastest_peer_solve"]
    if s["beamfx_solve_time"] is None or fastest is None:
        return _yes(s["beamfx_ahead_solve"])
    return f"{_yes(s['beamfx_ahead_solve'])} ({_g(s['beamfx_solve_time'])} vs {_g(fastest[1])})"


def summary_table(records, problems):
    """The summary table and, where beamfx is not ahead, by how much (lines of markdown)."""
    lines = [
        (
            "| problem | target | beamfx: whole s (setting; solve; process) | peers: whole s to "
            "target (setting; solve; process; best error) | ahead, whole run | ahead, solve only "
            "(least solve s: beamfx vs fastest peer) |"
        ),
        "|---|---|---|---|---|---|",
    ]
    behind = []
    for pid in problems:
        s = summary(records, pid)
        cells = [_peer_cell(n, v) for n, v in s["lines"].items() if v["code"] != "beamfx"]
        lines.append(
            f"| {pid} | {s['target']:.1e} | {_beamfx_cell(s)} | "
            + "<br>".join(cells or ["no peer"])
            + f" | {_yes(s['beamfx_ahead'])} | {_solve_verdict(s)} |"
        )
        if not s["beamfx_ahead"]:
            behind.append(_behind(pid, s))
    if behind:
        lines += ["", "Where beamfx is not ahead on whole runs, by how much (why: the sections):"]
        lines += [""] + behind
    return lines


def _behind(pid, s):
    """One bullet: beamfx's whole run against the fastest peer's, and where beamfx's whole
    run goes (the measured split of its warm run, :func:`whole_split_text`)."""
    fx, fastest = s["beamfx_at_target"], s["fastest_peer"]
    if fx is None:
        return f"- **{pid}**: beamfx does not reach the target {s['target']:.1e}."
    name, t = fastest
    return (
        f"- **{pid}**: beamfx {_g(fx['whole_s'])} s ({fx['setting']}) against {name} "
        f"{_g(t)} s: {fx['whole_s'] / t:.2g} x the time. {whole_split_text(fx)} beamfx's "
        "whole run includes writing what `beamfx run` writes (frames, probes, reactions, "
        "results.json); the Exudyn scripts write no result files (writeSolutionToFile = False)."
    )


#: the parts of a beamfx record's ``whole_split`` (results.json ``wall_time_s`` of its warm
#: run) named in the report, in the order of a run
SPLIT_PARTS = (
    ("model", "model build (mesh, function spaces, UFL forms, frame writers)"),
    ("compile", "residual and tangent from the JIT cache"),
    ("solve", "solve"),
    ("condition", "condition estimate"),
    ("output_probes", "probes (the first evaluation loads the section expression from the cache)"),
    ("output_reactions", "reactions and reactions.csv"),
    ("output_frames", "frames (VTK files)"),
)


def whole_split_text(fx):
    """Where beamfx's whole run ``fx["whole_s"]`` goes: the parts of its measured
    ``whole_split`` (:data:`SPLIT_PARTS`; "solve" is ``fx["wall_s"]``) and the rest (load
    stepping, folder, log, results.json); without a split, solve and rest only."""
    whole, solve = fx["whole_s"], fx.get("wall_s")
    split = dict(fx.get("whole_split") or {})
    if solve is not None:
        split["solve"] = solve
    parts = [(label, split[key]) for key, label in SPLIT_PARTS if split.get(key) is not None]
    if not fx.get("whole_split"):
        rest = whole - solve if solve is not None else None
        return (
            f"Of beamfx's whole run {_g(solve)} s is the solve and {_g(rest)} s the rest "
            "(model, forms from the cache, and per step the work outside the Newton solves)."
        )
    rest = whole - sum(v for _, v in parts)
    items = ", ".join(f"{label} {_g(v)}" for label, v in parts)
    text = (
        f"beamfx's whole run, measured (s): {items}, the rest (load stepping, folder, log, "
        f"results.json) {_g(rest)}."
    )
    return text + (f" {stack_text(fx)}" if fx.get("stack_s") else "")


def stack_text(fx):
    """The stack's fixed costs of ``fx`` (:func:`.peers_stack.stack_costs`), as a sentence
    with the floor they make for its run: a mesh, 5 spaces, the forms, the expression, the
    solve and one frame per load step (the frames of ``whole_split``, per its steps)."""
    c, steps = fx["stack_s"], fx.get("load_steps")
    floor = c["mesh"] + 5 * c["space"] + c["forms"] + c["expression"] + (fx.get("wall_s") or 0)
    frames = f", one frame {_g(c['frame'])}"
    if steps:
        floor += steps * c["frame"]
        frames += f" (x {steps} load steps)"
    return (
        f"The stack's fixed costs, each measured alone (s): a DOLFINx mesh {_g(c['mesh'])}, a "
        f"function space {_g(c['space'])} (the model makes 5), residual and tangent from the "
        f"JIT cache {_g(c['forms'])}, the section expression {_g(c['expression'])}{frames}: "
        f"with the solve, a floor of {_g(floor)} s for this run."
    )


def problem_section(records, pid, meta, s, note=None):
    """Markdown lines of one problem: target, plot, every record, the note."""
    out = [
        "",
        f"## {pid}: {meta.get('title', '')}",
        "",
        f"beamfx case `{meta.get('beamfx_case', '')}`; target error {s['target']:.1e}.",
        "",
        f"![error against whole-run time, {pid}](peers_{pid}.png)",
        "",
        "| code (element) | setting | unknowns | whole s | first s | solve s | process s | error |",
        "|---|---|---|---|---|---|---|---|",
    ]
    mine = [r for r in records if r["problem"] == pid]
    mine.sort(
        key=lambda r: (r["code"] != "beamfx", line(r), r.get("unknowns") or 0, r["wall_s"] or 0)
    )
    for r in mine:
        err = "reference" if r.get("is_reference") else _fmt(r.get("error"))
        if r.get("error") is None and not r.get("is_reference") and r.get("note"):
            err = r["note"]
        times = " | ".join(_g(r.get(k)) for k in ("whole_s", "first_s", "wall_s", "process_s"))
        out.append(f"| {line(r)} | {r['setting']} | {r.get('unknowns') or '—'} | {times} | {err} |")
    return out + (["", note] if note else [])


def curves_text(records, problems):
    """Lines of markdown: per problem and peer, whether beamfx's error-against-whole-run-time
    curve lies below the peer's over the errors both reach (:func:`.peers_score.curves`), and
    where not, at which errors and by how much."""
    lines = [
        "",
        (
            "Error against whole-run time over the whole range of errors both reach (each "
            "curve: the least whole run to reach an error ≤ x; compared at every setting's "
            "error from the larger of the two best errors up):"
        ),
        "",
    ]
    for pid in problems:
        for name, c in curves(records, pid).items():
            head = f"- **{pid}** against {name} (errors ≥ {c['from']:.1e}): "
            if not c["behind"]:
                lines.append(head + "beamfx's curve lies below.")
                continue
            worst = max(c["behind"], key=lambda x: x[1] / x[2])
            errors = [e for e, _, _ in c["behind"]]
            lines.append(
                head + f"beamfx behind at {len(errors)} of the steps, errors "
                f"{min(errors):.1e} to {max(errors):.1e}; at most {worst[1] / worst[2]:.3g} x "
                f"the time (at {worst[0]:.1e}: {_g(worst[1])} s against {_g(worst[2])} s)."
                + _floor_text(c, worst)
            )
    return lines


def _floor_text(c, worst):
    """Why, where beamfx's time there is that of its cheapest run on the problem: what that
    run spends its time on (the solve's share of it)."""
    fx = c["floor"]
    if worst[1] > 1.5 * fx["whole_s"]:
        return ""
    solve = fx.get("wall_s") or 0.0
    if solve < 0.25 * fx["whole_s"]:
        return (
            f" There beamfx's time is that of its cheapest run ({fx['setting']}, "
            f"{_g(fx['whole_s'])} s, of which the solve {_g(solve)} s): the fixed costs of a "
            "run (model build, JIT look-ups, probes, reactions, frames and results.json), "
            "not its discretisation."
        )
    return (
        f" There beamfx's time is that of its cheapest run ({fx['setting']}, "
        f"{_g(fx['whole_s'])} s, of which the solve {_g(solve)} s; the rest is the work of "
        "each step outside Newton and the output)."
    )


def markdown(records, problems, notes=None):
    """The report: the summary table (whole runs to the target per code), by how much beamfx
    is behind where it is, then per problem the full table, its plot and its note."""
    lines = ["# beamfx beside its peers", "", INTRO, "", *summary_table(records, problems)]
    lines += curves_text(records, problems)
    for pid, meta in problems.items():
        note = (notes or {}).get(pid)
        lines += problem_section(records, pid, meta, summary(records, pid), note)
    return "\n".join(lines) + "\n"
