"""A BCC lattice layer compressed between plates (demos/scenes/lattice_buckling.toml): its first
buckling load factor converges to Euler's load of its clamped corner posts.

Each post is clamped at both ends and its ends do not move sideways, so it buckles at
4π² EI/a²; under the load it carries EA δ/a (δ its top node's displacement), so the layer's
buckling factor is λ_E = 4π² EI/a² / (EA δ/a) for the most loaded posts (the corner posts; the
struts buckle later: beamfx.bench.lattice_buckling). The buckling factor of a conforming
discretisation converges from above at the eigenvalue rate of P3 elements (h^(2p) = h^6 for
the smooth mode; at least h^4 asserted).
"""

import pytest
from mpi4py import MPI


def test_lattice_buckling_factor_converges_to_euler(tmp_path):
    from beamfx.bench import lattice_buckling as lb

    folder = MPI.COMM_WORLD.bcast(str(tmp_path), root=0)
    # the posts' axial force is resolved by any mesh: 1, 2 and 4 P3 per member give λ_E to 1e-10
    euler = lb.euler_factor(2, 3, f"{folder}/euler")
    e2, e4 = ((lb.buckling_factor(n, 3, f"{folder}/b{n}") - euler) / euler for n in (2, 4))
    assert 0 < e4 < e2 / 16  # from above, at least fourth order
    #: measured 2.7e-4 with 4 P3 elements per member (1.3e-2 with 2)
    assert e4 < 1e-3


@pytest.mark.slow
def test_imperfect_lattice_tends_to_the_bifurcation(tmp_path):
    """A lateral force of 1e-3 N at each corner post's middle: Southwell's estimate from the
    arc-length path is the posts' bifurcation as extensible rods (0.6 % above λ_E), to the
    discretisation error of 4 P3 elements per member (2.7e-4 on λ₁; measured 1.4e-5 here)."""
    from beamfx.bench import lattice_buckling as lb

    folder = MPI.COMM_WORLD.bcast(str(tmp_path), root=0)
    euler = lb.euler_factor(4, 3, f"{folder}/euler")
    path = lb.arclength_path(4, 3, f"{folder}/path", imperfection=1e-3, limit=1e-4)
    estimate = lb.southwell(path, (0.05, 0.3))
    expected = lb.extensible_factor(euler)
    assert abs(estimate - expected) / expected < 1e-3
    assert abs(estimate - euler) / euler > 4e-3  # it is not the linear buckling factor


def test_stiff_lattice_keeps_the_corner_posts_symmetric(tmp_path):
    """EA × 1e8 (the stress matrix's last factor; shear-rigid members: the mixed form): the
    four corner posts, each in two directions, buckle at one load factor by symmetry, and the
    factor has reached its inextensible limit (it approaches it as 1/EA: 1.6e-3 from × 1 to
    × 1e2, so ~1.6e-9 from × 1e6 to × 1e8). The redundant axial forces of the posts and struts
    rest on the compliance 1/EA alone; one solve of the path left them an error ∝ EA (7e-6
    of the post force at × 1e8), which split the eight factors by 9e-7 and moved the first;
    the path solve's iterative refinement (buckling.refined_solve) keeps them to round-off."""
    import numpy as np

    from beamfx.bench import lattice_buckling as lb
    from beamfx.bench.stress_matrix import stiffened

    folder = MPI.COMM_WORLD.bcast(str(tmp_path), root=0)
    lam = {}
    for factor in (1e6, 1e8):
        with stiffened(factor):
            data = lb.scene_data(2, 2, {"type": "buckling", "modes": 8})
            lam[factor] = np.array(lb.run(data, f"{folder}/x{factor:g}").result.load_factors)
    top = lam[1e8]
    assert len(top) == 8 and np.ptp(top) < 1e-9 * top[0], top
    assert abs(top[0] - lam[1e6][0]) < 1e-8 * top[0], (top[0], lam[1e6][0])
