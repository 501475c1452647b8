"""PETSc options with a mandatory prefix, removed from the global database after use, and
the allow-list of the options a scene may set."""

import math
import re
from contextlib import contextmanager


@contextmanager
def petsc_options(prefix, options):
    """Put ``options`` under ``prefix`` for the duration of a ``setFromOptions`` call."""
    from petsc4py import PETSc

    db = PETSc.Options()
    for key, value in options.items():
        db[f"{prefix}{key}"] = value
    try:
        yield
    finally:
        for key in options:
            db.delValue(f"{prefix}{key}")


#: PETSc options a scene's ``[solver]`` table may set (names without prefix): solver types,
#: tolerances and iteration limits; ``<n>`` stands for a number. Viewers, logs, option files
#: and the like (they write or read files) are not in it.
ALLOWED = (
    "snes_type", "snes_linesearch_type", "snes_linesearch_damping", "snes_linesearch_max_it",
    "snes_linesearch_order", "snes_rtol", "snes_stol", "snes_max_it", "snes_max_funcs",
    "snes_divergence_tolerance", "snes_lag_jacobian", "snes_lag_preconditioner",
    "ksp_type", "ksp_rtol", "ksp_atol", "ksp_divtol", "ksp_max_it", "ksp_gmres_restart",
    "ksp_norm_type", "ksp_pc_side", "ksp_initial_guess_nonzero",
    "pc_type", "pc_factor_mat_solver_type", "pc_factor_mat_ordering_type",
    "pc_factor_shift_type", "pc_factor_shift_amount", "pc_factor_levels", "pc_hypre_type",
    "pc_hypre_boomeramg_strong_threshold", "pc_hypre_boomeramg_agg_nl",
    "pc_hypre_boomeramg_relax_type_all", "pc_hypre_boomeramg_coarsen_type",
    "pc_gamg_type", "pc_gamg_threshold", "pc_gamg_aggressive_coarsening", "mat_coarsen_type",
    "pc_asm_overlap", "sub_pc_type", "sub_ksp_type",
    "mat_mumps_icntl_<n>", "mat_mumps_cntl_<n>",
    "eps_type", "eps_tol", "eps_max_it", "eps_ncv", "eps_mpd", "st_type",
    "st_ksp_type", "st_pc_type", "st_pc_factor_mat_solver_type",
)  # fmt: skip
#: options that print to the terminal only: allowed with an empty value (no viewer)
TERMINAL = (
    "snes_monitor", "snes_converged_reason", "snes_linesearch_monitor", "ksp_monitor",
    "ksp_converged_reason", "eps_monitor", "eps_converged_reason",
)  # fmt: skip
_WORD = re.compile(r"[A-Za-z0-9_.+-]{1,64}")


#: ``linear`` in ``[solver]``: the linear solver of every Newton iteration, as a preset of
#: PETSc options (options given beside it win). ``direct``: LU by MUMPS (the default; a
#: serial system of at most :data:`DENSE_LIMIT` unknowns: the dense LU, :func:`use_dense`).
#: ``iterative``: conjugate gradients preconditioned by BoomerAMG (hypre's algebraic
#: multigrid) on the unknowns ordered node by node (:mod:`beamfx.solvers.blocked`, so it
#: coarsens each kind of unknown over the nodes); for a symmetric tangent (dead loads). Why
#: these, and what they cost: docs/scenes.md ("[solver]") and docs/validation/frame_scaling.md
LINEAR = {
    "direct": {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"},
    "iterative": {
        "ksp_type": "cg",
        "ksp_rtol": 1e-12,
        "ksp_max_it": 5000,
        "pc_type": "hypre",
        "pc_hypre_type": "boomeramg",
    },
}


def expand_linear(options):
    """``options`` with the ``linear`` preset (:data:`LINEAR`) written out; the options given
    beside it win. Raises ValueError for an unknown preset."""
    options = dict(options or {})
    preset = options.pop("linear", None)
    if preset is None:
        return options
    if preset not in LINEAR:
        raise ValueError(f"linear = {preset!r}: allowed: {', '.join(map(repr, LINEAR))}")
    return {**LINEAR[preset], **options}


#: the largest serial system Newton factors by a dense LU (PETSc's seqdense LU: LAPACK getrf,
#: partial pivoting, so a saddle point's zero diagonal is no obstacle) instead of MUMPS.
#: Factorisation and solve on beamfx tangents (planar, condensed, 3D, mixed), CPU time: MUMPS
#: 110-160 µs below 100 unknowns (its set-up, not the work), the dense LU 7 µs at 27, 33 at
#: 51-60, 50-75 at 75-87 and 100 µs at 99, growing as n³; they cross at 110-125 unknowns
#: (ratio 1.1-1.4 at 111-114, 0.9 at 123) and 100 keeps a margin of 1.5 (issue 20)
DENSE_LIMIT = 100
#: the options of the dense LU (on the converted matrix: :func:`use_dense`)
DENSE = {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "petsc"}
#: the options (and prefixes of options) by which a user picks or tunes the linear solver: any
#: of them given (e.g. a MUMPS control, a factorisation's ordering or shift), the dense LU is not
LINEAR_KEYS = ("ksp_type", "pc_type", "pc_factor_", "mat_mumps_")


def use_dense(options, size, ranks, preset=()):
    """Whether Newton factors its tangent by the dense LU (:data:`DENSE`): one rank, at most
    :data:`DENSE_LIMIT` unknowns (``size``), and no linear solver chosen by the user's
    ``options`` (the scene's, before the ``linear`` preset is expanded) nor by the options
    ``preset`` (names without prefix already in PETSc's database, e.g. from the command
    line). ``linear = "direct"`` asks for a direct solve: the dense LU is one."""
    if ranks > 1 or size > DENSE_LIMIT:
        return False
    options = options or {}
    if options.get("linear", "direct") != "direct":
        return False
    return not any(name.startswith(LINEAR_KEYS) for name in (*options, *preset))


_used = {}  # the linear solvers of the Newton solvers made since the last reset, in order


def linear_solvers(reset=False):
    """The linear solvers (:func:`describe`) of the Newton solvers made in this process since
    the last call with ``reset`` (a run's start); ``reset``: forget them after reading."""
    out = list(_used)
    if reset:
        _used.clear()
    return out


def describe(ksp, dense=False):
    """The linear solver a KSP runs, in words: e.g. "LU (mumps)", "dense LU (LAPACK getrf,
    partial pivoting)", "cg + hypre"; recorded for :func:`linear_solvers`. ``dense``: its
    operator is the dense copy of :func:`use_dense`."""
    pc = ksp.getPC()
    kind = pc.getType()
    if dense:
        words = "dense LU (LAPACK getrf, partial pivoting)"
    elif kind in ("lu", "cholesky", "ilu", "icc"):
        solver = pc.getFactorSolverType() or "petsc"
        words = f"{'LU' if kind == 'lu' else kind} ({solver})"
        words = words if ksp.getType() == "preonly" else f"{ksp.getType()} + {words}"
    else:
        words = f"{ksp.getType()} + {kind}"
    _used.setdefault(words, None)
    return words


def is_iterative(options):
    """Whether PETSc ``options`` (expanded) solve with a Krylov method, not a factorisation."""
    return options.get("ksp_type", "preonly") != "preonly"


def _allowed(name):
    return name in ALLOWED or re.sub(r"_\d{1,4}$", "_<n>", name) in ALLOWED


def option_problems(options):
    """(option, message) of every ``[solver]`` option a scene may not set: names off
    :data:`ALLOWED` and :data:`TERMINAL`, a ``linear`` preset not in :data:`LINEAR`, a value
    on a terminal option (it would name a viewer, e.g. a file), values that are not a number,
    true/false or a plain word."""
    for key, value in options.items():
        if key == "linear":
            if value not in LINEAR:
                yield key, f"{value!r}: allowed: {', '.join(map(repr, LINEAR))}"
            continue
        if key in TERMINAL:
            if value != "":
                yield key, f'prints to the terminal only: give it as "", not {value!r}'
            continue
        if not _allowed(key):
            yield (
                key,
                (
                    "not allowed from a scene (PETSc options that write or read files, viewers "
                    f"and logs are refused); allowed: {', '.join(ALLOWED)}, and with the value "
                    f'"": {", ".join(TERMINAL)}'
                ),
            )
        elif isinstance(value, (bool, int, float)):
            if isinstance(value, float) and not math.isfinite(value):
                yield key, f"{value!r} is not a finite number"
        elif not (isinstance(value, str) and _WORD.fullmatch(value)):
            yield key, f"{value!r}: expected a number, true/false or a word of letters and digits"
