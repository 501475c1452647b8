"""Where a benchmark's time goes: JIT (cold and cached), assembly, linear solves and Python,
per Newton iteration and per time step; the header table of the report.

Cold JIT is measured once per case (its first setting) by compiling the model's residual and
tangent into an empty cache directory; the cached time is the same two forms loaded again from
the normal cache (UFL signature, FFCx cache lookup, module import), which is what every later
run pays. The per-iteration split comes from the Newton solver's timers and PETSc's log events
(:func:`beamfx.solvers.snes.linear_solve_seconds`), measured on the warm solve.

Beside it, the limit the stack imposes at the same size (:func:`stack_limits`): the compiled
kernels alone assembled over all cells into objects made beforehand (``dolfinx.fem.petsc``'s
``assemble_vector`` and ``assemble_matrix``, no Python of beamfx), and a dense LU
factorisation and solve of the same tangent (``scipy.linalg.lu_factor`` / ``lu_solve``,
LAPACK). What beamfx spends above them is its own.
"""

import tempfile
import time
import timeit

_cold = {}  # case id -> seconds of the cold compile of its first setting


def newton_seconds(seconds):
    """The Newton iterations' own time in a solve's split (assembly and linear solves, SNES):
    the "solve only" figure, without model building, output or probes."""
    return seconds["assemble_F"] + seconds["assemble_J"] + seconds["solve"]


def per_iteration(seconds, iterations):
    """Seconds per Newton iteration of a solve: assembly, LU, triangular solves, the rest
    (Python), and beamfx's convergence test (``test``, not in ``python``), from the solve's
    wall-time split ``seconds``."""
    its = max(iterations, 1)
    keys = ("assemble_F", "assemble_J", "factorise", "triangular_solve", "python", "test")
    return {k: seconds.get(k, 0.0) / its for k in keys}


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


def _best_seconds(f, budget=0.02, repeat=5):
    """Seconds per call of ``f()``: the least mean over ``repeat`` batches of about ``budget``
    seconds each (the machine's other work shows as the larger batches)."""
    t = time.perf_counter()
    f()
    once = max(time.perf_counter() - t, 1e-7)
    number = max(1, int(budget / once))
    return min(timeit.repeat(f, number=number, repeat=repeat)) / number


def stack_limits(model, settings=None):
    """Per Newton iteration, the limit of the stack at the size of ``model`` (serial; {} on
    several ranks): ``limit_assembly_s``, residual and tangent assembled by DOLFINx into a
    vector and a matrix made beforehand (the compiled kernels over all cells, the Dirichlet
    rows of the tangent set in C++), and ``limit_dense_lu_s``, a dense LU factorisation and
    one solve of that tangent (LAPACK through SciPy). ``settings``: a transient's
    :class:`~beamfx.analyses.transient.TransientSettings`, whose step residual (inertia
    included) is then measured instead of the static one."""
    if model.comm.size > 1:
        return {}
    import scipy.linalg
    from scipy.sparse import csr_matrix

    F, J = model.F, model.J
    if settings is not None:
        from ..analyses.transient import Dynamics

        dyn = Dynamics(model, settings)
        F, J = dyn.F, dyn.J
    from ..solvers.assembly import assembler

    b, A, assemble = assembler(F, J, model.bcs)
    try:
        assembly = _best_seconds(assemble)
        K = csr_matrix(A.getValuesCSR()[::-1], shape=A.getSize()).toarray()
        r = b.getArray(readonly=True).copy()

        def dense_lu():
            scipy.linalg.lu_solve(scipy.linalg.lu_factor(K, check_finite=False), r,
                                  check_finite=False)  # fmt: skip

        return {"limit_assembly_s": assembly, "limit_dense_lu_s": _best_seconds(dense_lu)}
    finally:
        A.destroy()
        b.destroy()


def limit_ms(row):
    """(assembly limit, dense LU limit) of a result row in ms per iteration, or ("-", "-")."""
    if "limit_assembly_s" not in row:
        return "-", "-"
    return f"{1e3 * row['limit_assembly_s']:.3f}", f"{1e3 * row['limit_dense_lu_s']:.3f}"


def iteration_line(c):
    """The sentence of a case's section: the split of a Newton iteration at the cheapest
    passing setting ``c``, and the stack's limit at that size where measured."""
    t = c["warm_per_iteration_s"]
    line = (
        f"Per Newton iteration at {c['elements']} x P{c['degree']} (warm, ms"
        + (f"; {', '.join(c['linear_solver'])}" if c.get("linear_solver") else "")
        + "): "
        f"assemble residual {1e3 * t['assemble_F']:.2f}, tangent "
        f"{1e3 * t['assemble_J']:.2f}, LU factorisation {1e3 * t['factorise']:.2f}, "
        f"triangular solves {1e3 * t['triangular_solve']:.2f}, Python and the rest "
        f"{1e3 * t['python']:.2f}"
        + (f", convergence test {1e3 * t['test']:.2f}." if "test" in t else ".")
    )
    if "limit_assembly_s" in c:
        assembly, lu = limit_ms(c)
        line += (
            f" LIMIT of the stack at this size: assembly of the compiled kernels alone "
            f"{assembly}, dense LU factorisation and solve {lu}."
        )
    return line


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
            "Python = SNES, callbacks and vector work; LIMIT = the stack at the same size: "
            "assembly of the compiled kernels alone (DOLFINx into objects made beforehand) and a "
            "dense LU factorisation and solve (LAPACK), serial; JIT in s, cold = empty cache, "
            "cached = loaded again):"
        ),
        "",
        (
            "| case | setting | JIT cold s | JIT cached s | assembly ms/it | LIMIT assembly "
            "ms/it | linear solve ms/it | LIMIT dense LU ms/it | Python ms/it | its | "
            "ms per time step |"
        ),
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        row = r["cheapest_within_tolerance"] or (r["rows"][-1] if r["rows"] else None)
        if row is None:
            continue
        split, per_step = _row_profile(row)

        def ms(x):
            return f"{1e3 * x:.2f}"

        assembly_limit, lu_limit = limit_ms(row)
        if split:
            parts = [
                ms(split["assemble_F"] + split["assemble_J"]),
                assembly_limit,
                ms(split["factorise"] + split["triangular_solve"]),
                lu_limit,
                ms(split["python"]),
            ]
        else:
            parts = ["-", assembly_limit, "-", lu_limit, "-"]
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
    """Extra report lines of the adaptive and planar-vs-full cases and the BeamDyn cases
    (none for the others)."""
    from .adaptive_bend45 import accuracy_lines
    from .beamdyn_static import report_lines
    from .planar_rollup import planar_lines

    return accuracy_lines(r) + planar_lines(r) + report_lines(r)
