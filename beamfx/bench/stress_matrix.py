"""The stress matrix (issue 16): every static, buckling, modal and rotating benchmark re-run
with EA and GA multiplied by 1, 1e2, 1e4, 1e6 and 1e8, at one setting per degree 2, 3, 4 that
the case has: converged or not, how far its answer moves, and the condition number of the
tangent (static runs). Writes ``docs/validation/stress_matrix.md``.

Run ``python -m beamfx.bench.stress_matrix [case ids...]`` (all cases: about half an hour;
not part of ``make bench``); the runs are saved next to the report (``stress_matrix.json``),
and ``python -m beamfx.bench.stress_matrix --render`` writes the report again from them. The stiffnesses are multiplied where the model reads them
(:meth:`~beamfx.physics.sections.Section.stiffnesses`, patched for the run), so every case
runs as its own bench run does, scenes and the penalty limits included (a shear-rigid or
inextensible case has its penalty multiplied too). Static and SceneCase settings run once
through ``beamfx run``'s path (:mod:`.scenes`); the cases with a run of their own (rotating,
torque buckling, the planar roll-up) through that.

The answers of :data:`INDEPENDENT` cases do not depend on EA and GA (pure bending, or
inextensible and shear-rigid already): they are flagged when they move by more than
:data:`TOLERANCE`. The others move towards their shear-rigid, inextensible limit: their
trend (the move from the previous factor) must converge: its last move below
:data:`TOLERANCE`, or at most half of each of the two before (:func:`falls`). A value that
tends to its limit as a power of 1/factor does that (a move 1/100 or 1/10 of the one before
per factor 100); its first moves, far from the limit, may rise or fall.

Moves are relative to each value's own magnitude over the factors: the largest |value| of
that name among the converged runs (or the case's ``scale``). A value that tends to 0 (the
coupled cantilever's axial tip displacement, ~1/√factor) is thus judged against the size it
had, not against the vanishing one (relative to it, each move stays near 1), and round-off
in a quantity that is ~0 counts against the largest size the quantity reached.
"""

import itertools
import json
import re
import sys
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np

FACTORS = (1.0, 1e2, 1e4, 1e6, 1e8)
TOLERANCE = 1e-6
#: cases whose answer does not depend on EA and GA: the roll-ups (a pure end moment: no axial
#: or shear force) and those that are inextensible and shear-rigid by construction
INDEPENDENT = (
    "rollup_0.25",
    "rollup_0.5",
    "rollup_1",
    "rollup_2",
    "rollup_planar_vs_full",
    "sm21_shear_rigid",
    "sm210_rotating_inextensible",
    "shallow_arch_bifurcation",
    "sm27_torque_buckling",
)
#: transients and adaptive cases are out of the matrix's scope (issue 16: static, buckling,
#: modal and rotating)
SKIP = ("TransientCase", "DecayCase", "AdaptiveCase")
OUT = Path("docs/validation/stress_matrix.md")


@contextmanager
def stiffened(factor):
    """EA, GA_y and GA_z multiplied by ``factor`` in every section the models read. A 6×6
    matrix section becomes D C D with D = diag(√f, √f, √f, 1, 1, 1): its force block times f,
    its force–moment coupling times √f (positive definite as C is; the diagonal case is EA, GA
    times f)."""
    from ..physics import matrix_sections, sections

    original = sections.Section.stiffnesses
    original_matrices = matrix_sections.MatrixSection.matrices_at
    d = np.r_[np.full(3, np.sqrt(factor)), np.ones(3)]

    def scaled(self):
        s = original(self)
        return np.r_[s[:3] * factor, s[3:]]

    def scaled_matrices(self, s):
        C, M = original_matrices(self, s)
        return C * d[:, None] * d[None, :], M

    sections.Section.stiffnesses = scaled
    matrix_sections.MatrixSection.matrices_at = scaled_matrices
    try:
        yield
    finally:
        sections.Section.stiffnesses = original
        matrix_sections.MatrixSection.matrices_at = original_matrices


def settings_by_degree(case):
    """One setting per degree 2, 3, 4 that the case has: the middle one of that degree."""
    out = []
    for degree in (2, 3, 4):
        own = [s for s in case.settings if s[1] == degree]
        if own:
            out.append(own[len(own) // 2])
    return out or [case.settings[len(case.settings) // 2]]


def run_once(case, setting):
    """(values, path, condition) of one run of ``setting``: through ``beamfx run``'s path for a
    static Case and a SceneCase, the case's own run otherwise. Raises if it fails."""
    from .registry import Case
    from .scenes import SceneCase, case_scene, run_in_process

    elements, degree = setting[:2]
    if not isinstance(case, SceneCase) and type(case) is not Case:
        return case.run_setting(elements, degree)["values"], "own", None
    if isinstance(case, SceneCase):
        scenes = case.build(elements, degree)
    else:
        scenes = [(case_scene(case, elements, degree), None)]
    runs, values = [], {}
    with tempfile.TemporaryDirectory(prefix="beamfx-stress-") as folder:
        for scene, read in scenes:
            run, _ = run_in_process(scene, folder)
            if run.result.status != "converged":
                raise RuntimeError(f"{case.id}: {run.result.status}: {run.result.reason}")
            values.update(read(run.result) if read else run.probes)
            runs.append(run)
    return case.measure(values), _path(runs), _condition(runs)


def _path(runs):
    """The run column: `scene`, or `scene (mixed)` when the runs solved the mixed formulation
    (chosen by the scene builder, :mod:`beamfx.analyses.mixed`; both ran: `scene (mixed,
    displacement)`)."""
    names = [(r.model.get("formulation") or {}).get("name", "displacement") for r in runs]
    if "mixed" not in names:
        return "scene"
    return "scene (mixed)" if set(names) == {"mixed"} else "scene (mixed, displacement)"


def _condition(runs):
    """The largest scaled condition estimate of the runs (static runs have one), or None."""
    values = [(getattr(r.result, "condition_estimate", None) or {}).get("value") for r in runs]
    values = [v for v in values if v is not None]
    return max(values) if values else None


def run_setting(case, setting):
    """Per factor: dict(factor, ok, values, path, kappa, seconds, cause)."""
    rows = []
    for factor in FACTORS:
        t0 = time.perf_counter()
        row = {"factor": factor, "ok": False, "values": None, "path": "", "kappa": None}
        with stiffened(factor):
            try:
                values, path, kappa = run_once(case, setting)
                row.update(ok=True, path=path, kappa=kappa)
                row["values"] = {k: float(v) for k, v in values.items()}
            except Exception as e:  # noqa: BLE001  (a failed run is the matrix's finding)
                row["cause"] = _cause(str(e))
                print(f"  {case.id} {setting} x{factor:g}: {type(e).__name__}: {str(e)[:200]}")
        row["seconds"] = time.perf_counter() - t0
        rows.append(row)
    return rows


def _cause(message):
    """The cause named in a failure message (beamfx's 'cause: X (' or 'cause: X;'), else its
    first words."""
    found = re.search(r"cause: ([a-z ]+?)[ ]?[(;]", message)
    return found.group(1) if found else message[:60]


def move(values, reference, scale=None):
    """Largest relative change of the named values: the change over ``scale`` (a number, or
    a number per name, see :func:`scales`), else over |reference| (the change itself where
    the reference value is 0, e.g. a flag)."""
    if values is None or reference is None:
        return None
    out = 0.0
    for key, ref in reference.items():
        d = abs(values[key] - ref)
        size = scale.get(key) if isinstance(scale, dict) else scale
        out = max(out, d / size if size else d / abs(ref) if ref else d)
    return out


def scales(case, rows):
    """The size each value's moves are measured against: the case's ``scale`` if it has one,
    else per name the largest |value| among the converged rows (0 for a value that is 0
    throughout: its moves then count as they are)."""
    if case.scale:
        return case.scale
    done = [r["values"] for r in rows if r["ok"] and r["values"]]
    return {key: max(abs(v[key]) for v in done) for key in done[0]} if done else None


def falls(trend):
    """Whether a trend (moves from factor to factor) converges: its last move is below
    :data:`TOLERANCE`, or at most half of each of the (up to) two moves before it. The moves
    at the small factors are the value's approach to the stiff regime, where terms of
    different powers of 1/factor may cancel (a move may rise before the trend falls); round-off
    that grows with the factor raises the last move, a plateau of noise keeps it level: both
    fail."""
    if not trend or trend[-1] <= TOLERANCE:
        return True
    before = trend[-3:-1]
    return bool(before) and trend[-1] <= 0.5 * min(before)


def verdict(case, rows):
    """(passes, what) of one setting's rows: every factor converged, and an independent case
    moved by at most TOLERANCE, a dependent one with a converging trend (:func:`falls`);
    moves against :func:`scales`."""
    failed = [f"x{r['factor']:g}" for r in rows if not r["ok"]]
    if failed:
        return False, "fails at " + ", ".join(failed)
    scale = scales(case, rows)
    moves = [move(r["values"], rows[0]["values"], scale) for r in rows]
    if case.id in INDEPENDENT:
        worst = max(moves)
        return worst <= TOLERANCE, f"moves {worst:.1e} (independent of EA, GA)"
    trends = {
        key: [move(_one(b, key), _one(a, key), scale) for a, b in itertools.pairwise(rows)]
        for key in rows[0]["values"]
    }
    bad = {key: t for key, t in trends.items() if not falls(t)}
    show = lambda t: " → ".join(f"{x:.0e}" for x in t)
    if bad:
        return False, "; ".join(f"{k}: {show(t)} (does not fall)" for k, t in bad.items())
    worst = [max(t) for t in zip(*trends.values(), strict=True)]
    return True, f"trend {show(worst)} (converges, each value)"


def _one(row, key):
    """The row's value ``key`` alone (a dict for :func:`move`)."""
    return {key: row["values"][key]}


def table_rows(case, setting, rows):
    """Markdown rows of one setting: per factor, converged, moves, κ, time, cause."""
    fmt = lambda x: "–" if x is None else f"{x:.1e}"
    lines, scale = [], scales(case, rows)
    for i, r in enumerate(rows):
        m1 = move(r["values"], rows[0]["values"], scale)
        prev = move(r["values"], rows[i - 1]["values"], scale) if i else None
        lines.append(
            f"| {case.id} | {setting[0]}×P{setting[1]} | {r['factor']:g} | "
            f"{'yes' if r['ok'] else 'NO'} | {fmt(m1)} | {fmt(prev)} | {fmt(r['kappa'])} | "
            f"{r['seconds']:.1f} | {r['path'] or r.get('cause', '')} |"
        )
    return lines


HEADER = (
    "Generated by `python -m beamfx.bench.stress_matrix` (not part of `make bench`). EA, GA_y "
    "and GA_z multiplied by the factor in every section (penalties of shear-rigid and "
    "inextensible models included). Each case at one setting per degree; *move ×1*: the "
    "largest change of its values from factor 1, each relative to its largest magnitude over "
    "the factors (or to the case's scale), "
    "*move prev*: from the previous factor (the trend); *κ*: the condition number of the "
    "static tangent at the last state, symmetric diagonal scaling (Ruiz equilibration for the "
    "mixed formulation's saddle point; results.json `condition_estimate`); *run*: `scene` "
    "through `beamfx run`'s path (`scene (mixed)`: the builder chose the mixed formulation, "
    "`[model] formulation`), `own` the case's own run, or the cause of a failure."
)


#: the heading of the report's hand-written part, kept when the tables are regenerated
FINDINGS = "## Findings"


def markdown(results, findings=""):
    """The report: the verdicts, every run, then ``findings`` (hand-written, kept)."""
    lines = ["# Stress matrix: EA and GA multiplied by 1 … 1e8", "", HEADER, ""]
    lines += ["| case | setting | passes | what |", "|---|---|---|---|"]
    for case, setting, rows in results:
        ok, what = verdict(case, rows)
        lines.append(
            f"| {case.id} | {setting[0]}×P{setting[1]} | {'yes' if ok else 'NO'} | {what} |"
        )
    lines += ["", "| case | setting | factor | converged | move ×1 | move prev | κ | s | run |"]
    lines += ["|---|---|---|---|---|---|---|---|---|"]
    for case, setting, rows in results:
        lines += table_rows(case, setting, rows)
    text = "\n".join(lines) + "\n"
    return text + ("\n" + findings if findings else "")


def findings_of(path):
    """The hand-written part of an existing report (from :data:`FINDINGS` on), or ''."""
    text = path.read_text() if path.exists() else ""
    at = text.find(FINDINGS)
    return text[at:] if at >= 0 else ""


def main(ids=()):
    """Run the matrix (all cases, or ``ids`` in their order: their rows replace theirs in the
    saved runs, the other cases' are kept) and write :data:`OUT`; returns the settings that
    do not pass."""
    from . import all_cases

    every = {k: c for k, c in all_cases().items() if type(c).__name__ not in SKIP}
    unknown = [i for i in ids if i not in every]
    if unknown:
        raise SystemExit(
            f"stress_matrix: unknown case id(s) {unknown}; allowed: {sorted(every)} "
            "(or --render to rewrite the report from the saved runs)"
        )
    cases = [every[i] for i in ids] if ids else list(every.values())
    saved = load() if ids and OUT.with_suffix(".json").exists() else []
    results, failing, findings = [], [], findings_of(OUT)
    OUT.parent.mkdir(parents=True, exist_ok=True)
    for case in cases:
        for setting in settings_by_degree(case):
            print(f"{case.id} {setting} ...", flush=True)
            rows = run_setting(case, setting)
            results.append((case, setting, rows))
            if not verdict(case, rows)[0]:
                failing.append(f"{case.id} {setting[0]}×P{setting[1]}")
            merged = merge(saved, results)
            OUT.write_text(markdown(merged, findings))  # after each setting: a long run
            save(merged, OUT.with_suffix(".json"))
    print(f"wrote {OUT}; not passing: {failing}")
    return failing


def merge(saved, new):
    """The saved runs with those of the cases in ``new`` replaced (in place; new cases last)."""
    ids = {c.id for c, _, _ in new}
    out, placed = [], set()
    for entry in saved:
        case_id = entry[0].id
        if case_id not in ids:
            out.append(entry)
        elif case_id not in placed:
            out += [e for e in new if e[0].id == case_id]
            placed.add(case_id)
    return out + [e for e in new if e[0].id not in placed]


def save(results, path):
    """The runs as JSON (case id, setting, rows), to render the report again (:func:`render`)."""
    data = [{"case": c.id, "setting": list(s), "rows": rows} for c, s, rows in results]
    path.write_text(json.dumps(data, indent=1))


def load(path=None):
    """The saved runs: [(case, setting, rows)]."""
    from . import all_cases

    cases = all_cases()
    data = json.loads((path or OUT.with_suffix(".json")).read_text())
    return [(cases[d["case"]], tuple(d["setting"]), d["rows"]) for d in data]


def render(path=None):
    """Rewrite :data:`OUT` from the saved runs (after a change of the verdicts or the text)."""
    OUT.write_text(markdown(load(path), findings_of(OUT)))


if __name__ == "__main__":
    if sys.argv[1:] == ["--render"]:
        render()
    else:
        main(tuple(sys.argv[1:]))
