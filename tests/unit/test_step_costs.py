"""What makes a small step cheap changes no number: the lifting skipped where the iterate holds
the prescribed values, the transient's reactions taken from Newton's last residual, the probe
history's cached path, and the stack limits of the bench report (issue 20)."""

import numpy as np
import pytest
from scenekit import comm, rollup_model

from beamfx.io import evaluate_points
from beamfx.solvers import NewtonSolver
from beamfx.solvers.assembly import assemble_residual, lifts, prescribed


@pytest.fixture(scope="module")
def rolled():
    """The quarter-turn roll-up solved in one load step (a state far from the reference)."""
    model, _ = rollup_model(0.25)
    model.set_load_factor(1.0)
    solver = NewtonSolver(model.F, model.J, model.w, model.bcs, "test_step_costs_")
    solver.keep_residual()
    report = solver.solve()
    assert report.converged
    yield model, solver
    solver.destroy()


def _residual(solver, x, rows, targets=None):
    b = solver.b.duplicate()
    local, lifted = assemble_residual(b, solver.F, solver.J, solver.bcs, x, rows, None, targets)
    values = b.getArray(readonly=True).copy()
    b.destroy()
    return values, local, lifted


def test_lifting_skipped_only_where_it_is_an_exact_zero(rolled):
    """At an iterate holding the prescribed values the lifting is skipped and the residual is
    bitwise the lifted one; an iterate off them is lifted (rows=None: always lifted)."""
    _, solver = rolled
    x, rows = solver.x.copy(), solver._rows
    skipped, local, lifted = _residual(solver, x, rows)
    always, _, _ = _residual(solver, x, None)
    assert not lifted
    assert comm.allreduce(local) > 0  # the reactions at the clamp (on the rank owning it)
    np.testing.assert_array_equal(skipped, always)
    g = prescribed(solver.bcs, rows, x.getLocalSize())
    off = x.copy()
    with off.localForm() as a:
        a.array[rows] += 1e-3  # the clamp's dofs moved off their targets
    assert lifts(solver.bcs, off, rows) and lifts(solver.bcs, off, rows, g)
    moved, _, lifted = _residual(solver, off, rows, g)
    reference, _, _ = _residual(solver, off, None)
    assert lifted
    np.testing.assert_array_equal(moved, reference)
    for v in (x, off):
        v.destroy()


def test_kept_residual_is_the_assembled_one(rolled):
    """Newton's last residual, kept, is bitwise an assembly of F at the solution (what the
    energy balance of a transient assembled for its reactions before)."""
    import dolfinx.fem.petsc as fp
    from petsc4py import PETSc

    _, solver = rolled
    kept = solver.residual_at_solution()
    assert kept is not None
    b = solver.b.duplicate()
    with b.localForm() as local:
        local.set(0.0)
    fp.assemble_vector(b, solver.F)
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    np.testing.assert_array_equal(kept, b.getArray(readonly=True))
    b.destroy()


def test_probe_history_path_gives_the_full_values(rolled):
    """The per-step path of the probes (full=False) reports the numbers of the full one."""
    model, _ = rolled
    names = list(model.mesh.points)
    full = evaluate_points(model, names)
    short = evaluate_points(model, names, full=False)
    assert set(short) == set(names)
    for n in names:
        assert set(short[n]) == {"position", "displacement", "quaternion"}
        for key, value in short[n].items():
            assert value == full[n][key]


@pytest.mark.skipif(comm.size > 1, reason="the dense LU limit is a serial measure")
def test_stack_limits_in_the_report(rolled):
    from beamfx.bench.profiling import iteration_line, profile_lines, stack_limits

    model, _ = rolled
    limits = stack_limits(model)
    assert set(limits) == {"limit_assembly_s", "limit_dense_lu_s"}
    assert all(0 < v < 1 for v in limits.values())
    split = dict.fromkeys(("assemble_F", "assemble_J", "factorise", "triangular_solve"), 1e-4)
    row = {"elements": 8, "degree": 3, "newton_iterations": 5, "warm_per_iteration_s": {
        **split, "python": 1e-5}, **limits}  # fmt: skip
    assert "LIMIT of the stack" in iteration_line(row)
    table = profile_lines([{"id": "case", "cheapest_within_tolerance": row, "rows": [row]}])
    header, cells = table[3], table[-1].split("|")
    assert "LIMIT assembly" in header and "LIMIT dense LU" in header
    assert cells[6].strip() == f"{1e3 * limits['limit_assembly_s']:.3f}"
    assert cells[8].strip() == f"{1e3 * limits['limit_dense_lu_s']:.3f}"
