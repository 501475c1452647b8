"""Small serial tangents factored by PETSc's dense LU (LAPACK getrf, partial pivoting) instead
of MUMPS (issue 20): chosen only where no linear solver is given, the same answers as MUMPS to
the round-off the tangent's condition allows, the same Newton iterations, and a saddle point
(the mixed form's zero diagonal) factored through its pivoting."""

import numpy as np
import pytest
from petsc4py import PETSc

from beamfx.analyses.static import solve_static
from beamfx.bench import all_cases
from beamfx.bench.run import _model_of
from beamfx.bench.scenes import case_scene
from beamfx.solvers import NewtonSolver, SolveFailed
from beamfx.solvers.assembly import assemble_tangent
from beamfx.solvers.options import DENSE_LIMIT, use_dense

DENSE = "dense LU (LAPACK getrf, partial pivoting)"
MUMPS = {"pc_factor_mat_solver_type": "mumps"}
EPS = np.finfo(float).eps


def test_dense_only_where_no_linear_solver_is_given():
    assert use_dense({}, DENSE_LIMIT, 1) and use_dense(None, 9, 1)
    assert use_dense({"linear": "direct", "snes_rtol": 1e-9}, 27, 1)  # direct: dense is one
    assert not use_dense({}, DENSE_LIMIT + 1, 1)  # MUMPS's sparsity wins beyond
    assert not use_dense({}, 27, 2)  # several ranks: MUMPS
    for given in (
        MUMPS,
        {"pc_type": "cholesky"},
        {"ksp_type": "gmres"},
        {"linear": "iterative"},
        {"mat_mumps_icntl_14": 50},  # a MUMPS control: MUMPS
        {"pc_factor_shift_type": "nonzero"},  # a sparse factorisation's tuning
    ):
        assert not use_dense(given, 27, 1), given
    assert not use_dense({}, 27, 1, preset=["pc_factor_mat_solver_type"])  # PETSc's database


def _model(case_id, elements, degree):
    case = all_cases()[case_id]
    return _model_of(case_scene(case, elements, degree), case)


def _tangent(solver):
    """The assembled tangent at the solver's state, as a NumPy array."""
    assemble_tangent(solver.A, solver.J, solver.bcs)
    return solver.A.convert("dense", PETSc.Mat()).getDenseArray().copy()


def _solve(model, options, steps):
    model.reset()
    solver = NewtonSolver(model.F, model.J, model.w, model.bcs, "test_dense_lu_", options)
    try:
        result = solve_static(model, steps=steps, solver=solver)
        return solver.linear_solver, result, model.w.x.array.copy(), _tangent(solver)
    finally:
        solver.destroy()


def test_saddle_point_tangent_dense_equals_mumps():
    """The mixed form of a shear-rigid cantilever (60 unknowns, linear: one solve): its
    tangent has zero diagonal entries (no LU without pivoting), and the dense LU's solution
    equals MUMPS's within the forward error of two backward-stable solves, 10 κ eps."""
    model = _model("sm21_shear_rigid", 2, 3)
    name, result, dense, K = _solve(model, None, 1)
    assert name == DENSE and (np.diag(K) == 0).sum() > 0
    name_m, result_m, mumps, _ = _solve(model, MUMPS, 1)
    assert name_m == "LU (mumps)"
    assert result.newton_iterations == result_m.newton_iterations
    kappa = np.linalg.cond(K)
    assert np.linalg.norm(dense - mumps) <= 10 * kappa * EPS * np.linalg.norm(mumps)


def test_newton_path_dense_equals_mumps():
    """Finite rotations (end moments rolling a cantilever, 21 unknowns, 29 iterations): the
    same Newton iterations in every load step, and both answers within the residual test of
    the root: |Δw| ≤ ‖K⁻¹‖ (|F_dense| + |F_mumps|) at the last residuals."""
    model = _model("sm23_end_moments", 2, 3)
    name, result, dense, K = _solve(model, None, 10)
    _, result_m, mumps, _ = _solve(model, MUMPS, 10)
    assert name == DENSE
    its = [s.iterations for s in result.steps]
    assert its == [s.iterations for s in result_m.steps]
    last = result.steps[-1].residuals[-1] + result_m.steps[-1].residuals[-1]
    bound = np.linalg.norm(np.linalg.inv(K), 2) * last
    assert np.linalg.norm(dense - mumps) <= bound


def test_petsc_database_option_wins():
    """A linear solver given in PETSc's options database (e.g. the command line) is kept."""
    model = _model("sm23_end_moments", 2, 3)
    db = PETSc.Options()
    db["test_dense_db_pc_factor_mat_solver_type"] = "mumps"
    try:
        solver = NewtonSolver(model.F, model.J, model.w, model.bcs, "test_dense_db_")
        assert solver.linear_solver == "LU (mumps)" and solver.P is None
        solver.destroy()
    finally:
        db.delValue("test_dense_db_pc_factor_mat_solver_type")


@pytest.mark.parametrize("options", [{"pc_type": "lu"}, {"linear": "direct"}, {}])
def test_linear_solver_named(options):
    """What ran is said: a given pc_type keeps PETSc's choice for it (MUMPS here, the
    default), the direct preset and no options give the dense LU."""
    model = _model("sm23_end_moments", 2, 3)
    solver = NewtonSolver(model.F, model.J, model.w, model.bcs, "test_dense_named_", options)
    try:
        dense = "pc_type" not in options
        assert (solver.linear_solver == DENSE) is dense and (solver.P is not None) is dense
    finally:
        solver.destroy()


def test_zero_pivot_is_a_failed_linear_solve(monkeypatch):
    """A tangent with an exactly zero pivot (a free unknown's row and column zeroed): LAPACK's
    getrf stops PETSc with an error, which Newton reports as a failed linear solve (as MUMPS's
    failed factorisation), not an exception that ends the run without results.json."""
    from beamfx.solvers import snes

    def singular(A, J, bcs, *args, **kwargs):
        assemble_tangent(A, J, bcs, *args, **kwargs)
        A.zeroRowsColumns([A.getSize()[0] - 1], diag=0.0)

    monkeypatch.setattr(snes, "assemble_tangent", singular)
    model = _model("sm23_end_moments", 2, 3)
    model.reset()
    solver = NewtonSolver(model.F, model.J, model.w, model.bcs, "test_dense_pivot_")
    try:
        assert solver.P is not None
        with pytest.raises(SolveFailed, match="cause: linear solve"):
            solve_static(model, steps=1, solver=solver)
    finally:
        solver.destroy()


@pytest.mark.parametrize("options", [{"pc_type": "lu"}, {}], ids=["mumps", "dense"])
def test_a_retry_after_a_failed_factorisation_factorises_afresh(monkeypatch, options):
    """A step whose tangent cannot be factored is retried with a smaller step; that retry
    factorises anew (MUMPS stopped it with INFOG(1) = -3, exit 1 and no results.json): a
    tangent singular only at the first attempt gives the solution of a run without it, one
    singular at every attempt a failed solve with its cause."""
    from beamfx.solvers import snes

    calls = []

    def singular(first_only):
        def tangent(A, J, bcs, *args, **kwargs):
            assemble_tangent(A, J, bcs, *args, **kwargs)
            calls.append(1)
            if not first_only or len(calls) == 1:
                A.zeroRowsColumns([A.getSize()[0] - 1], diag=0.0)

        return tangent

    def run(prefix):
        model = _model("sm23_end_moments", 2, 3)
        model.reset()
        solver = NewtonSolver(model.F, model.J, model.w, model.bcs, prefix, options)
        try:
            solve_static(model, steps=1, solver=solver)
        finally:
            solver.destroy()
        return model.w.x.array.copy()

    expected = run("test_retry_plain_")
    monkeypatch.setattr(snes, "assemble_tangent", singular(first_only=True))
    got = run("test_retry_once_")
    assert len(calls) > 1  # the singular attempt and the retries that followed
    scale = np.abs(expected).max()
    assert np.abs(got - expected).max() <= 1e-8 * scale  # the Newton tolerance, not a bit match
    monkeypatch.setattr(snes, "assemble_tangent", singular(first_only=False))
    with pytest.raises(SolveFailed, match="cause: linear solve"):
        run("test_retry_always_")
