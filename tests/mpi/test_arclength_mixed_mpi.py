"""Arc length in the mixed formulation on all ranks against one process: the inertia less the
force unknowns (summed over the ranks), the kinematic metric of the located bifurcation's
eigenvector and the deflation are collective. Howcroft's shallow arch
(``beamfx/scenes/shallow_arch_snap.toml``, 8 × P3, planar, mixed form stated) past its
bifurcation and limit point (the inextensible arch's path, u ≡ 0 up to round-off, is no test:
its load factors per step follow the round-off of its displacements)."""

import numpy as np
import pytest
from mpi4py import MPI

pytestmark = pytest.mark.mpi


def test_mixed_trace_is_the_same_on_all_ranks(shared_folder):
    from beamfx.bench.shallow_arch import scene_data
    from beamfx.runner import run_scene
    from beamfx.scene.load import parse_scene

    data = scene_data("shallow_arch_snap", 8, 3)
    data["model"] = {"formulation": "mixed"}
    data["analysis"].update(max_steps=12)
    scene = parse_scene(data, "arch.toml")
    folder = shared_folder
    rank = MPI.COMM_WORLD.rank
    log = lambda *a, **k: None
    serial = run_scene("s.toml", folder / f"s{rank}", comm=MPI.COMM_SELF, scene=scene, log=log)
    parallel = run_scene("s.toml", folder / "p", scene=scene, log=log)
    assert parallel.model["formulation"]["name"] == "mixed"
    one, all_ = serial.result, parallel.result
    counts = [p["negative_eigenvalues"] for p in one.path]
    assert counts == [p["negative_eigenvalues"] for p in all_.path]
    assert counts[0] == 0 and max(counts) == 2  # the force unknowns left out on every rank
    a = np.array([p["load_factor"] for p in all_.path])
    b = np.array([p["load_factor"] for p in one.path])
    assert np.allclose(a, b, rtol=1e-8, atol=1e-10)
    assert [c["kind"] for c in one.critical_points] == ["bifurcation", "limit"]
    for s, p in zip(one.critical_points, all_.critical_points):
        (lo, hi), (lo_p, hi_p) = s["load_factor_bracket"], p["load_factor_bracket"]
        assert max(lo, lo_p) <= min(hi, hi_p) + 1e-12 * abs(hi)  # the same point
