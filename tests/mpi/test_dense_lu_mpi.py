"""On several ranks Newton keeps MUMPS (the dense LU is serial only, issue 20), and the answer
is the serial dense LU's to within the residual test."""

import numpy as np
import pytest
from mpi4py import MPI

from beamfx.analyses.static import solve_static
from beamfx.bench import all_cases
from beamfx.bench.run import _model_of
from beamfx.bench.scenes import case_scene
from beamfx.io import evaluate_points
from beamfx.solvers import NewtonSolver


def _solve(comm):
    case = all_cases()["sm23_end_moments"]
    scene = case_scene(case, 2, 3)
    model = _model_of(scene, case) if comm is MPI.COMM_WORLD else None
    if model is None:
        from beamfx.analyses.planar_condensed import build_model

        model = build_model(scene.model, comm, case.probes.values(), scene.condense)
    solver = NewtonSolver(model.F, model.J, model.w, model.bcs, "test_dense_lu_mpi_")
    try:
        result = solve_static(model, steps=10, solver=solver)
        tip = evaluate_points(model, ["b:end"])["b:end"]
        return solver.linear_solver, result, np.asarray(tip["position"])
    finally:
        solver.destroy()


@pytest.mark.mpi
def test_ranks_keep_mumps_serial_uses_dense():
    name, result, tip = _solve(MPI.COMM_WORLD)
    serial_name, serial, serial_tip = _solve(MPI.COMM_SELF)
    assert serial_name == "dense LU (LAPACK getrf, partial pivoting)"
    assert name == ("LU (mumps)" if MPI.COMM_WORLD.size > 1 else serial_name)
    assert [s.iterations for s in result.steps] == [s.iterations for s in serial.steps]
    # both within the residual test (1e-10 of the load scale) of the same state; the tangent
    # of this unit cantilever maps that to ~1e-12 in position (serial: dense vs MUMPS 1e-16)
    assert np.abs(tip - serial_tip).max() < 1e-10


@pytest.mark.mpi
def test_ranks_retry_a_step_after_a_failed_factorisation(monkeypatch):
    """On every rank alike: a tangent MUMPS cannot factor at the first attempt (the last
    unknown's row and column zeroed, on the rank that owns it) is a failed linear solve, the
    step's retry factorises afresh and converges to the answer of a run without it."""
    from beamfx.solvers import snes
    from beamfx.solvers.assembly import assemble_tangent

    calls = []

    def once_singular(A, J, bcs, *args, **kwargs):
        assemble_tangent(A, J, bcs, *args, **kwargs)
        calls.append(1)
        if len(calls) == 1:
            A.zeroRowsColumns([A.getSize()[0] - 1], diag=0.0)

    _, plain, tip = _solve(MPI.COMM_WORLD)
    monkeypatch.setattr(snes, "assemble_tangent", once_singular)
    _, retried, retried_tip = _solve(MPI.COMM_WORLD)
    assert len(calls) > 1
    assert retried.steps[0].cutbacks == 1 and plain.steps[0].cutbacks == 0
    scale = np.abs(tip).max()
    assert np.abs(retried_tip - tip).max() <= 1e-8 * scale
