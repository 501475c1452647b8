"""The condition estimate of the tangent in results.json (issue 16), and the floor acceptance
at stiffness ratios far beyond 1e8 (EA, GA multiplied by 1e4 and 1e6)."""

import json
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp
from mpi4py import MPI

from beamfx.runner import run_scene
from beamfx.solvers import conditioning

CANTILEVER = """
[material]
E = {E!r}
nu = 0.3

[[beams]]
name = "b"
curve = {{ shape = "line", start = [0, 0, 0], end = [{L!r}, 0, 0] }}
section = {{ type = "circle", d = {d!r} }}
elements = 6
degree = 2

[model]  # the full 3D model (a planar or condensed one has other unknowns)
plane = "none"
condense = "none"

[[supports]]
at = "b:start"
fix = "all"

[[loads]]
at = "b:end"
force = [0, 0, -1.0]

[analysis]
type = "static"
steps = 2
"""


def run(tmp_path, text):
    folder = Path(MPI.COMM_WORLD.bcast(str(tmp_path)))
    scene = folder / "scene.toml"
    if MPI.COMM_WORLD.rank == 0:
        folder.mkdir(parents=True, exist_ok=True)
        scene.write_text(text)
    MPI.COMM_WORLD.barrier()
    run_scene(scene, folder / "out", log=lambda *a, **k: None)
    MPI.COMM_WORLD.barrier()
    return json.loads((folder / "out" / "results.json").read_text())


def test_the_scaled_condition_does_not_depend_on_the_units(tmp_path):
    """The same cantilever in m, N, Pa and in mm, N, N/mm²: the tangent changes by a diagonal
    congruence (displacements 1000 times larger, moments in N mm), which the symmetric
    diagonal scaling removes exactly (to round-off); the unscaled number changes (by about 90)."""
    metre = run(tmp_path / "m", CANTILEVER.format(E=210e9, L=1.0, d=0.02))
    mm = run(tmp_path / "mm", CANTILEVER.format(E=210e3, L=1000.0, d=20.0))
    a, b = metre["condition_estimate"], mm["condition_estimate"]
    assert a["scaling"] == conditioning.SCALING and a["norm"] == "2"
    assert a["free_unknowns"] == b["free_unknowns"] > 0
    assert b["value"] == pytest.approx(a["value"], rel=1e-6)
    assert max(a["unscaled"], b["unscaled"]) > 30 * min(a["unscaled"], b["unscaled"])
    assert 1 < a["value"] < a["unscaled"]


def test_the_condition_grows_with_the_stiffness_ratio(tmp_path):
    """EA and GA 1e4 times larger (the stress matrix's patch): the scaled condition number
    grows with the stiffness ratio EA L²/EI (by 1e4 within a factor 3), which no diagonal
    scaling removes: the round-off floor of every solve rises with it."""
    from beamfx.bench.stress_matrix import stiffened

    text = CANTILEVER.format(E=210e9, L=1.0, d=0.02)
    displacement = text.replace(
        'condense = "none"', 'condense = "none"\nformulation = "displacement"'
    )
    base = run(tmp_path / "a", displacement)["condition_estimate"]["value"]
    with stiffened(1e4):
        stiff = run(tmp_path / "b", displacement)["condition_estimate"]["value"]
        # "auto" takes the mixed form there (ratio 4e8 ≥ 1e8): its saddle point, equilibrated,
        # keeps the condition of the ordinary beam
        mixed = run(tmp_path / "c", text)["condition_estimate"]
    assert 1e4 / 3 < stiff / base < 3e4
    assert mixed["scaling"] == conditioning.SADDLE_SCALING and mixed["value"] < base


def test_the_dense_and_the_estimated_norms_agree_on_a_known_matrix():
    """A tridiagonal SPD matrix with a condition number known in closed form: the SVD gives it
    to round-off, the 1-norm estimate (above DENSE_LIMIT) within the bounds κ₂/n ≤ κ₁ ≤ n κ₂
    and, for this matrix, within a factor 2."""
    for n in (50, conditioning.DENSE_LIMIT + 50):
        K = 2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1)
        k = np.arange(1, n + 1)
        eig = 2 - 2 * np.cos(k * np.pi / (n + 1))
        kappa2 = eig.max() / eig.min()
        value, norm = conditioning.condition(sp.csr_matrix(K))
        if n <= conditioning.DENSE_LIMIT:
            assert norm == "2" and value == pytest.approx(kappa2, rel=1e-8)
        else:
            assert norm.startswith("1") and kappa2 / 2 < value < 2 * kappa2


def test_a_singular_matrix_has_no_finite_condition():
    K = sp.csr_matrix(np.ones((3, 3)))
    value, _ = conditioning.condition(K)
    assert conditioning._finite(value if value > 1e17 else np.inf) is None


SHEAR_RIGID = """
[material]
E = 210e9
nu = 0.3

[[beams]]
name = "b"
curve = { shape = "line", start = [0, 0, 0], end = [1, 0, 0] }
section = { type = "rectangle", h = 0.02, w = 0.01 }
elements = 2
degree = 3

[model]
kinematics = "linear"
shear = false
plane = "none"
formulation = "displacement"  # the penalty GA = 1e8 EI/L² ("auto": the mixed form)

[[supports]]
at = "b:start"
fix = "all"

[[loads]]
at = "b:end"
force = [0, 0, 1e4]

[analysis]
type = "static"

[[probes]]
name = "tip"
at = "b:end"
"""


@pytest.mark.parametrize("factor", [1e4, 1e6])
def test_a_shear_rigid_cantilever_converges_far_beyond_the_penalty(tmp_path, factor):
    """Schwab & Meijaard 2.1 (shear-rigid by a penalty GA = 1e8 EI/L²) with EA and GA 1e4 and
    1e6 times larger: GA L²/EI = 1e12 and 1e14, the round-off floor eps·|K||x| is 1e-4 and
    1e-2 of the load. Newton's corrections settle at 1e-16 of the state, so the state is exact
    to round-off and the step is accepted at the floor (it failed with 'floor above the force
    scale'); the tip deflection is F L³/(3 EI) to 1e-6 as at factor 1."""
    from beamfx.bench.stress_matrix import stiffened

    with stiffened(factor):
        r = run(tmp_path, SHEAR_RIGID)
    assert r["converged"] is True and r["status"] == "converged"
    (step,) = r["load_steps"]
    assert step["converged_by"] == "floor"
    EI = 210e9 * 0.01 * 0.02**3 / 12
    uz = r["probes"]["tip"]["displacement"][2]
    assert uz == pytest.approx(1e4 / (3 * EI), rel=1e-6)


def test_beyond_double_precision_the_failure_says_how_ill_conditioned(tmp_path):
    """EA and GA 1e8 times larger on the shear-rigid cantilever: GA L²/EI = 1e16, the tangent
    is singular in double precision (κ ≥ 1/eps) and Newton cannot converge; the run fails
    (exit status 3 in ``beamfx run``) and its failure entry holds the condition estimate of
    the tangent at the last converged state (the undeformed one), at least 1e16 or None
    (singular to working precision)."""
    from beamfx.bench.stress_matrix import stiffened

    with stiffened(1e8):
        r = run(tmp_path, SHEAR_RIGID)
    assert r["converged"] is False and r["status"] == "failed"
    kappa = r["failure"]["condition_estimate"]
    assert kappa["value"] is None or kappa["value"] >= 1e16


def test_a_small_tangent_gives_the_same_numbers_dense_and_sparse():
    """The dense path of a small tangent (no SciPy sparse products) scales and decomposes the
    same numbers as the sparse one: identical condition numbers, scaled and unscaled."""
    condition, scaled = conditioning.condition, conditioning.scaled
    rng = np.random.default_rng(3)
    A = rng.normal(size=(7, 7)) * np.logspace(0, 6, 7)[:, None]
    K = A @ A.T  # symmetric positive definite, badly scaled
    for M in (K, K * (np.abs(K) > 1.0)):  # full, and with zeros
        assert condition(scaled(M)) == condition(scaled(sp.csr_matrix(M)))
        assert condition(M) == condition(sp.csr_matrix(M))


def test_the_dense_gather_holds_the_sparse_one():
    """A small tangent gathered dense (no SciPy CSR) holds the entries of the sparse gather,
    and the same free rows."""
    from petsc4py import PETSc

    A = PETSc.Mat().createAIJ((4, 4), comm=PETSc.COMM_SELF)
    A.setUp()
    for i, j, v in ((0, 0, 4.0), (0, 1, -1.5), (1, 0, -1.5), (1, 1, 3.0), (2, 2, 1.0), (3, 3, 2e6)):
        A.setValue(i, j, v)
    A.assemble()
    K, free = conditioning.gather(A, [2], dense=True)
    S, free_s = conditioning.gather(A, [2])
    assert isinstance(K, np.ndarray) and np.array_equal(K, S.toarray())
    assert free.tolist() == free_s.tolist() == [0, 1, 3]
    A.destroy()


def test_the_mixed_form_solves_it_exactly(tmp_path):
    """The same cantilever with "auto": the mixed form (shear-rigid: an exact constraint, no
    penalty) at EA, GA ×1e8 converges by the residual test, the tip deflection is
    F L³/(3 EI) to round-off (the penalty's 3/1e8 is gone) and κ stays below 1e3."""
    from beamfx.bench.stress_matrix import stiffened

    with stiffened(1e8):
        r = run(tmp_path, SHEAR_RIGID.replace('formulation = "displacement"', ""))
    assert r["converged"] is True and r["model"]["formulation"]["name"] == "mixed"
    EI = 210e9 * 0.01 * 0.02**3 / 12
    assert r["probes"]["tip"]["displacement"][2] == pytest.approx(1e4 / (3 * EI), rel=1e-12)
    assert r["condition_estimate"]["value"] < 1e3
