"""Where a benchmark's time goes: JIT (cold and cached), assembly, linear solves and Python,
per Newton iteration and per time step; the header table of the report.

Cold JIT is measured once per case (its first setting) by compiling the model's residual and
tangent into an empty cache directory; the cached time is the same two forms loaded again from
the normal cache (UFL signature, FFCx cache lookup, module import), which is what every later
run pays. The per-iteration split comes from the Newton solver's timers and PETSc's log events
(:func:`beamfx.solvers.snes.linear_solve_seconds`), measured on the warm solve.
"""

import tempfile
import time

_cold = {}  # case id -> seconds of the cold compile of its first setting


def newton_seconds(seconds):
    """The Newton iterations' own time in a solve's split (assembly and linear solves, SNES):
    the "solve only" figure, without model building, output or probes."""
    return seconds["assemble_F"] + seconds["assemble_J"] + seconds["solve"]


def per_iteration(seconds, iterations):
    """Seconds per Newton iteration of a solve: assembly, LU, triangular solves, the rest
    (Python), from the solve's wall-time split ``seconds``."""
    its = max(iterations, 1)
    keys = ("assemble_F", "assemble_J", "factorise", "triangular_solve", "python")
    return {k: seconds[k] / its for k in keys}


def jit_seconds(case_id, model):
    """{"jit_cold_s", "jit_cached_s"} for the residual and tangent of ``model``."""
    import dolfinx.fem

    from ..solvers.forms import JIT_PARAMS

    forms = (model.F, model.J)
    if case_id not in _cold:
        with tempfile.TemporaryDirectory(prefix="beamfx_jit_") as cache:
            t = time.perf_counter()
            for f in forms:
                dolfinx.fem.form(f, jit_params={**JIT_PARAMS, "cache_dir": cache})
            _cold[case_id] = time.perf_counter() - t
    t = time.perf_counter()
    for f in forms:
        dolfinx.fem.form(f, jit_params=JIT_PARAMS)
    return {"jit_cold_s": _cold[case_id], "jit_cached_s": time.perf_counter() - t}


def _row_profile(row):
    """(per-iteration ms dict or None, per-time-step ms or None) of a result row."""
    split = row.get("warm_per_iteration_s")
    per_step = None
    if "dt" in row and row.get("load_steps"):
        per_step = 1e3 * row["wall_s_warm"] / row["load_steps"]
    return split, per_step


def profile_lines(results):
    """The header table: per case, at its cheapest passing setting (else its last one)."""
    lines = [
        "",
        (
            "Where the time goes (cheapest passing setting; warm solve, ms per Newton iteration: "
            "assembly of residual + tangent, linear solve = LU factorisation + triangular solves, "
            "Python = SNES, callbacks and vector work; JIT in s, cold = empty cache, cached = "
            "loaded again):"
        ),
        "",
        (
            "| case | setting | JIT cold s | JIT cached s | assembly ms/it | linear solve ms/it | "
            "Python ms/it | its | ms per time step |"
        ),
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        row = r["cheapest_within_tolerance"] or (r["rows"][-1] if r["rows"] else None)
        if row is None:
            continue
        split, per_step = _row_profile(row)

        def ms(x):
            return f"{1e3 * x:.2f}"

        if split:
            parts = [
                ms(split["assemble_F"] + split["assemble_J"]),
                ms(split["factorise"] + split["triangular_solve"]),
                ms(split["python"]),
            ]
        else:
            parts = ["-"] * 3
        cold = f"{row['jit_cold_s']:.2f}" if "jit_cold_s" in row else "-"
        cached = f"{row['jit_cached_s']:.3f}" if "jit_cached_s" in row else "-"
        dt = f", dt {row['dt']:g}" if "dt" in row else ""
        lines.append(
            f"| {r['id']} | {row['elements']} x P{row['degree']}{dt} | {cold} | {cached} | "
            + " | ".join(parts)
            + f" | {row['newton_iterations']} | "
            + (f"{per_step:.2f}" if per_step is not None else "-")
            + " |"
        )
    return lines


def case_lines(r):
    """Extra report lines of the adaptive and planar-vs-full cases (none for the others)."""
    from .adaptive_bend45 import accuracy_lines
    from .planar_rollup import planar_lines

    return accuracy_lines(r) + planar_lines(r)
