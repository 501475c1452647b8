"""A BCC lattice layer compressed between plates (demos/scenes/lattice_buckling.toml): its first
buckling load factor converges to Euler's load of its clamped corner posts.

Each post is clamped at both ends and its ends do not move sideways, so it buckles at
4π² EI/a²; under the load it carries EA δ/a (δ its top node's displacement), so the layer's
buckling factor is λ_E = 4π² EI/a² / (EA δ/a) for the most loaded posts (the corner posts; the
struts buckle later: beamfx.bench.lattice_buckling). The buckling factor of a conforming
discretisation converges from above at the eigenvalue rate of P3 elements (h^(2p) = h^6 for
the smooth mode; at least h^4 asserted).
"""

from mpi4py import MPI


def test_lattice_buckling_factor_converges_to_euler(tmp_path):
    from beamfx.bench import lattice_buckling as lb

    folder = MPI.COMM_WORLD.bcast(str(tmp_path), root=0)
    euler = lb.euler_factor(4, 3, f"{folder}/euler")
    e2, e4 = ((lb.buckling_factor(n, 3, f"{folder}/b{n}") - euler) / euler for n in (2, 4))
    assert 0 < e4 < e2 / 16  # from above, at least fourth order
    #: measured 2.7e-4 with 4 P3 elements per member (1.3e-2 with 2)
    assert e4 < 1e-3
