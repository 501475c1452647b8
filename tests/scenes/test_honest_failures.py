"""Every numerical failure ends `beamfx run` with exit status 3 and a results.json that says
status "failed", never converged: true, with the cause and the remedy (issue 16)."""

import json
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI
from scenekit import MODAL_ROD

from beamfx.cli import main
from beamfx.solvers.convergence import REMEDIES

CANTILEVER = """
[material]
E = 210e9
nu = 0.3

[[beams]]
name = "b"
curve = {{ shape = "line", start = [0, 0, 0], end = [1, 0, 0] }}
section = {{ type = "circle", d = 0.02 }}
elements = 8
degree = 2

[[supports]]
at = "b:start"
fix = "all"

[[loads]]
at = "b:end"
force = [0, 0, {force}]

# the planar model (2 displacements and an angle per node), whose Newton path these tests
# are about; the planar condensed model the builder would pick solves these loads (the
# stretch and shear F/EA, F/GA follow from the known section force, no Newton on them)
[model]
condense = "none"

[analysis]
type = "static"
steps = 10
"""

MODAL = MODAL_ROD

ROTATING = """
[material]
E = 210e9
rho = 7850

[[beams]]
name = "blade"
curve = { shape = "line", start = [0, 0, 0], end = [1, 0, 0] }
section = { type = "rectangle", h = 0.02, w = 0.04 }
elements = 4
degree = 3

[[supports]]
at = "blade:start"
fix = "all"

[analysis]
type = "rotating"
speeds_rad_s = [0, 100, 200]
modes = 2

[solver]
pc_type = "none"  # the Newton 'linear solve' is the identity: a numerical failure
"""


def run(tmp_path, text, capsys):
    """`beamfx run` in-process: (exit status, results.json, captured stdout and stderr)."""
    folder = Path(MPI.COMM_WORLD.bcast(str(tmp_path)))
    scene, out = folder / "scene.toml", folder / "out"
    if MPI.COMM_WORLD.rank == 0:
        scene.write_text(text)
    MPI.COMM_WORLD.barrier()
    code = main(["run", str(scene), "--out", str(out)])
    MPI.COMM_WORLD.barrier()  # rank 0 writes results.json
    return code, json.loads((out / "results.json").read_text()), capsys.readouterr()


def assert_failed(code, results, captured, cause):
    err = captured.err
    assert code == 3
    assert results["converged"] is False and results["status"] == "failed"
    assert results["cause"] == cause and results["remedy"]
    assert f"cause: {cause}" in results["reason"] and "remedy:" in results["reason"]
    if MPI.COMM_WORLD.rank == 0:
        assert "beamfx: failed:" in err and f"cause: {cause}" in err


def test_a_force_of_1e15_on_a_1_m_cantilever_fails_with_exit_3(tmp_path, capsys):
    """It used to exit 0 with converged: true and a last residual 547 times the load (a
    step-size stop counted as convergence). The states it reaches have rotations and stretches
    so large that the residual cannot be resolved to 1e-5 of the load: the run fails. Which
    cause is named depends on the round-off of the last attempt (one rank: 'floor above the
    force scale'; two ranks: 'max iterations'), never 'other'."""
    code, results, captured = run(tmp_path, CANTILEVER.format(force=-1e15), capsys)
    assert results["cause"] in REMEDIES and results["cause"] != "other"
    assert_failed(code, results, captured, results["cause"])
    attempts = results["failure"]["attempts"]
    assert attempts and all(a["reason"] == "DIVERGED_MAX_IT" for a in attempts)
    for step in results["load_steps"]:  # what was accepted before is in equilibrium
        assert step["residuals"][-1] <= 1e-5 * step["force_scale"]


def test_a_force_of_1e12_is_not_accepted_with_a_large_residual(tmp_path, capsys):
    """Either every accepted load step is in equilibrium to 1e-5 of its force scale (the load
    or the reactions: here the tip force and its moment about the clamp, F·1 m) and the run
    converges, or the run fails with exit 3; never converged with |F| ~ 4e-4 |f|."""
    code, results, err = run(tmp_path, CANTILEVER.format(force=-1e12), capsys)
    for step in results["load_steps"]:
        load = 1e12 * step["load_factor"]
        assert load <= step["force_scale"] <= 2 * load
        assert step["residuals"][-1] <= 1e-5 * step["force_scale"]
    if code == 0:
        assert results["converged"] is True and results["load_steps"][-1]["load_factor"] == 1
    else:
        assert_failed(code, results, err, results["cause"])


def test_a_low_iteration_limit_is_named_and_the_condensed_failure_is_kept(tmp_path, capsys):
    """[solver] snes_max_it = 1 on a load Newton needs more for: the remedy names the limit
    (it said "steps = 4" after cut-backs to 1e-4 of the load), and a run that fell back from
    the condensed model to the full one says both (the first failure was lost)."""
    text = CANTILEVER.format(force=-2e5).replace('condense = "none"', 'condense = "auto"')
    code, results, captured = run(tmp_path, text + "[solver]\nsnes_max_it = 1\n", capsys)
    assert_failed(code, results, captured, results["cause"])
    assert results["remedy"].startswith("more iterations: [solver] snes_max_it = 1 ")
    assert "the statically condensed model failed first" in results["reason"]
    assert "statically condensed model failed" in results["failure"]["fallback"]
    assert results["model"]["condensed"] is False
    assert (
        "after the statically condensed model failed" in results["model"]["formulation"]["reason"]
    )


def test_a_step_cut_back_without_help_is_not_told_to_take_smaller_steps():
    """A failure that cut-backs to a hundredth of the first try did not cure gets no "smaller
    load steps" remedy; one with few cut-backs keeps it."""
    from beamfx.solvers.snes import SolveReport
    from beamfx.solvers.stepping import _remedy

    report = SolveReport(False, "DIVERGED_DTOL", 5, (1.0, 10.0), {}, cause="divergence")
    deep = _remedy(report, [1.0 / 2**k for k in range(10)], 40)
    assert deep.startswith("not a smaller step") and "steps =" not in deep
    assert "steps = 40" in _remedy(report, [1.0, 0.5], 40)


#: 16 modes of a 2-element cantilever with polar rotary inertia only: 5 nodes x 4 dofs with
#: mass, 4 of them clamped, 16 by the count; the tip's fixed rx takes the polar inertia of its
#: node too, which the count (that knows not which rotation has mass) leaves: 15 modes exist
POLAR_TIP = MODAL.replace("modes = 30", 'modes = 16\nrotary_inertia = "polar"').replace(
    "[analysis]", '[[supports]]\nat = "b:end"\nfix = ["rx"]\n\n[analysis]'
)


def test_an_eigen_solve_with_fewer_pairs_than_asked_is_reported_not_raised(tmp_path, capsys):
    """16 modes of a model with 15 finite eigenvalues: a report with the pairs found and what
    was asked, exit 3, no traceback (it raised RuntimeError, exit 1)."""
    code, results, captured = run(tmp_path, POLAR_TIP, capsys)
    assert_failed(code, results, captured, "eigen solve")
    failure = results["failure"]
    assert failure["requested"] == 16 and failure["converged"] == 15
    assert "found 15 of the 16 modes asked" in results["reason"]
    if MPI.COMM_WORLD.rank == 0:  # the log ends with the failure, not "done in" before it
        assert "done in" not in captured.out
        assert captured.out.splitlines()[-1].startswith("failed after ")
    assert len(failure["eigenvalues"]) == failure["converged"]
    assert "Traceback" not in captured.err


def test_more_modes_than_unknowns_is_bad_input_before_the_solve(tmp_path, capsys):
    """5000 modes of a 35-unknown model (24 free dofs with mass): exit 2 naming the key and the
    count (it failed as a numerical eigen solve, exit 3)."""
    folder = Path(MPI.COMM_WORLD.bcast(str(tmp_path)))
    if MPI.COMM_WORLD.rank == 0:
        (folder / "scene.toml").write_text(MODAL.replace("modes = 30", "modes = 5000"))
    MPI.COMM_WORLD.barrier()
    code = main(["run", str(folder / "scene.toml"), "--out", str(folder / "out")])
    err = capsys.readouterr().err
    assert code == 2 and not (folder / "out" / "results.json").exists()
    if MPI.COMM_WORLD.rank == 0:
        assert "analysis.modes = 5000: more than a modal analysis can find" in err
        assert "allowed: an integer in [1, 24]" in err


def test_a_numerical_newton_failure_of_a_rotating_run_is_failed_not_stopped(tmp_path, capsys):
    """The tangent is positive definite at the state where Newton gave up, so no steady state
    was lost: status "failed" (a physical stop would be "stopped"), exit 3."""
    code, results, err = run(tmp_path, ROTATING, capsys)
    assert_failed(code, results, err, results["cause"])
    assert results["stopped_by"] is None and results["speeds_rad_s"] == [0.0]
    assert "stays positive definite" in results["failure"]["tangent"]


SUDDEN = """
[material]
E = 2.1e11
nu = 0.3
rho = 7850

[[beams]]
name = "b"
curve = { shape = "line", start = [0, 0, 0], end = [1, 0, 0] }
section = { type = "rectangle", h = 0.01, w = 0.01 }
elements = 8
degree = 2

[[supports]]
at = "b:start"
fix = "all"

[[loads]]
at = "b:end"
force = [0, 0, 5000]
moment = [0, 500, 0]

[analysis]
type = "transient"
dt = 10
t_end = 100

[[probes]]
name = "tip"
at = "b:end"
"""


def test_a_failed_time_step_reports_cause_remedy_and_attempts(tmp_path, capsys):
    """A sudden 5000 N on a 1 x 1 cm steel cantilever at dt = 10: no step size Newton can
    take from t = 0. results.json had only a reason ending in a colon (the residual lines
    lost) and said "down to dt_min = 0.01" when 0.0195 was the smallest tried; now it has the
    cause, the remedy (smaller steps: the inertia dominates a short step), every attempt with
    its residuals, the time and step, and dt_min itself is the last size tried."""
    code, results, captured = run(tmp_path, SUDDEN, capsys)
    assert_failed(code, results, captured, results["cause"])
    assert results["cause"] in REMEDIES and results["cause"] != "other"
    assert results["remedy"].startswith("smaller time steps: the smallest tried, dt = 0.01,")
    assert not results["reason"].endswith(":") and "from t = 0 " in results["reason"]
    failure = results["failure"]
    assert failure["time"] == 0.0 and failure["step"] == 1 and failure["dt_min"] == 0.01
    attempts = failure["attempts"]
    sizes = [a["dt"] for a in attempts]
    assert sizes[0] == 10.0 and sizes[-2] == pytest.approx(10 / 2**9) and sizes[-1] == 0.01
    assert failure["smallest_dt_tried"] == 0.01
    for a in attempts:  # each attempt's residual history, from the load's first residual
        assert a["reason"].startswith("DIVERGED") and a["cause"] in REMEDIES
        assert len(a["residuals"]) == a["iterations"] + 1 and a["residuals"][0] > 0
    if MPI.COMM_WORLD.rank == 0:
        last = captured.err.strip().splitlines()[-1]
        assert last.startswith("beamfx: failed: time step 1 from t = 0 ")
        assert "cause: " in last and "remedy: smaller time steps" in last


FRAME = """
[material]
E = {E!r}
nu = 0.3

[[beams]]
name = "a"
curve = {{ shape = "line", start = [0, 0, 0], end = [1, 0, 0.05] }}
section = {{ type = "rectangle", h = {h!r}, w = {h!r} }}
elements = 4
degree = 3

[[beams]]
name = "b"
curve = {{ shape = "line", start = [1, 0, 0.05], end = [2, 0, 0] }}
section = {{ type = "rectangle", h = {h!r}, w = {h!r} }}
elements = 4
degree = 3

[[supports]]
at = "a:start"
fix = "all"

[[supports]]
at = "b:end"
fix = "all"

[[loads]]
at = "a:end"
force = [0, 0, {P!r}]

[model]  # the displacement form's floor exits ("auto" takes the mixed form from ratio 1e8)
formulation = "displacement"

[analysis]
type = "static"
steps = 10

[[probes]]
name = "apex"
at = "a:end"
"""


@pytest.mark.parametrize("ratio, load", [(1e8, 1.0), (1e8, 10.0), (1e10, 1.0), (1e10, 10.0)])
def test_a_shallow_two_bar_frame_converges_at_every_load(tmp_path, capsys, ratio, load):
    """EA·L²/EI = 1e8 and 1e10 (EI = 1, bars of about 1, rise 0.05), 4 cubic elements per bar:
    the residual stalls at its round-off floor (about eps·EA: 2e-8 and 2e-6) far above 1e-10
    of the load, where the old test failed every step. Now each step converges, at the floor
    with small increments, in equilibrium to better than 1e-5 of the load, and the log says
    so (a floor exit is never called 'no convergence')."""
    h = (12.0 / ratio) ** 0.5
    text = FRAME.format(E=12.0 / h**4, h=h, P=-load)
    code, results, captured = run(tmp_path, text, capsys)
    assert code == 0 and results["converged"] is True and results["status"] == "converged"
    steps = results["load_steps"]
    assert steps[-1]["load_factor"] == pytest.approx(1.0, abs=1e-12)
    assert {s["converged_by"] for s in steps} <= {"residual", "floor"}
    assert any(s["converged_by"] == "floor" for s in steps)
    for s in steps:  # the scale: the load, or the reactions (the thrust, about 10 P)
        assert s["force_scale"] >= load * s["load_factor"]
        assert s["residuals"][-1] <= 1e-5 * s["force_scale"]
    if MPI.COMM_WORLD.rank == 0:
        assert "(at the round-off floor)" in captured.out + captured.err
        rejected = [x for x in captured.out.splitlines() if "no convergence" in x]
        assert not [x for x in rejected if "CONVERGED" in x or "floor)" in x]
    uz = results["probes"]["apex"]["displacement"][2]
    assert uz < 0 and np.isfinite(uz)
