"""The rigid-body near-null space of the beam tangent (solvers/nullspace.py) and the
node-blocked AMG preconditioner (solvers/blocked.py) on a small lattice."""

import numpy as np
import pytest
from mpi4py import MPI


def _model(tmp_path, cells, kinematics):
    from beamfx.analyses.planar_condensed import build_model
    from beamfx.bench.frame_scaling import lattice_scene

    scene = lattice_scene(tmp_path, cells, kinematics, "iterative", MPI.COMM_SELF)
    return build_model(scene.model, MPI.COMM_SELF, list(scene.probes.values()), False)


def _free_tangent(model):
    """The tangent without supports at the current state, as a scipy CSR matrix."""
    import dolfinx.fem.petsc as fp
    import scipy.sparse as sp

    from beamfx.solvers.forms import compile_form

    A = fp.assemble_matrix(compile_form(model.J))
    A.assemble()
    indptr, indices, values = A.getValuesCSR()
    K = sp.csr_matrix((values, indices, indptr), shape=A.getSize())
    A.destroy()
    return K


def _worst_cancellation(K, v):
    """max over rows of |K v| / Σ_j |K_ij| (|v_j| + max|v|): the round-off of the product
    and of the vector's entries (each exact to a few ulp of max|v|) is about 1e-16 of it, a
    vector off the kernel gives order 1 (rows with K_ij = 0 throughout are skipped)."""
    scale = abs(K) @ (abs(v) + abs(v).max())
    return float(np.max(np.abs(K @ v)[scale > 0] / scale[scale > 0]))


def _rigid_state(model, angle, axis):
    """Set ``model.w`` to the rigid rotation by ``angle`` about ``axis`` (through the origin):
    u = R X − X at the nodes, q = its quaternion; strain-free and unloaded."""
    from scipy.spatial.transform import Rotation

    from beamfx.solvers.nullspace import beam_node_dofs

    W = model.W
    u_dofs, r_dofs = beam_node_dofs(W)
    V0, collapsed = W.sub(0).collapse()
    node = np.empty(len(model.w.x.array), np.int64)
    node[np.asarray(collapsed)[0::3]] = np.arange(len(collapsed) // 3)
    X = V0.tabulate_dof_coordinates()[node[u_dofs[:, 0]]]
    rot = Rotation.from_rotvec(angle * np.asarray(axis) / np.linalg.norm(axis))
    x = model.w.x.array
    x[u_dofs] = rot.apply(X) - X
    x[r_dofs] = np.roll(rot.as_quat(), 1)  # scipy: scalar last
    model.w.x.scatter_forward()


@pytest.mark.parametrize("kinematics", ["linear", "finite"])
def test_rigid_modes_are_the_kernel_of_the_free_tangent(tmp_path, kinematics):
    """The six rigid-body modes are null vectors of the unsupported tangent to round-off,
    at the reference state and (finite kinematics) at a rigidly rotated one, where the
    quaternion part ½ (0, ω) ⊗ q and u part ω × (X + u) matter; a generic vector is not."""
    from beamfx.solvers.nullspace import beam_node_dofs, rigid_modes

    model = _model(tmp_path, 2, kinematics)
    states = [None] + ([(1.1, (1.0, -2.0, 0.5))] if kinematics == "finite" else [])
    for state in states:
        if state:
            _rigid_state(model, *state)
        K = _free_tangent(model)
        u, r = beam_node_dofs(model.W)
        modes = rigid_modes(model.W, u, r, model.w.x.array if state else None)
        assert modes.shape == (6, K.shape[0]) and np.linalg.matrix_rank(modes) == 6
        for v in modes:
            assert _worst_cancellation(K, v) < 1e-13, (state, _worst_cancellation(K, v))
        generic = np.random.default_rng(0).standard_normal(K.shape[0])
        assert _worst_cancellation(K, generic) > 1e-3


def test_node_permutation_covers_every_unknown_once(tmp_path):
    """Each node block holds its 3 displacement and 4 quaternion unknowns, every owned
    unknown once."""
    from beamfx.solvers.nullspace import node_permutation

    model = _model(tmp_path, 2, "finite")
    perm, bs = node_permutation(model.W)
    assert bs == 7 and np.array_equal(np.sort(perm), np.arange(len(model.w.x.array)))


def _krylov_its(tmp_path, cells):
    """CG iterations (to 1e-12) of the iterative preset on the first tangent of the linear
    ``cells``³ lattice, and whether the node-blocked preconditioner was used."""
    from beamfx.solvers import NewtonSolver
    from beamfx.solvers.options import LINEAR

    model = _model(tmp_path / str(cells), cells, "linear")
    model.load_factor.value = 1.0
    options = {**LINEAR["iterative"], "snes_type": "ksponly"}
    solver = NewtonSolver(model.F, model.J, model.w, model.bcs, "test_blocked_", options)
    solver.solve()
    its, blocked = solver.snes.getLinearSolveIterations(), solver.blocks is not None
    solver.destroy()
    return its, blocked


def test_blocked_amg_iterations_do_not_grow_with_the_lattice(tmp_path):
    """The preset's CG + BoomerAMG on node blocks: the iterations stay within 20 % from the
    2³ to the 4³ lattice (7 times the unknowns); on the unknowns one by one (block size 1)
    they grew about twice over 10 times the unknowns (docs/validation/frame_scaling.md)."""
    small, large = _krylov_its(tmp_path, 2), _krylov_its(tmp_path, 4)
    assert small[1] and large[1]
    assert large[0] <= 1.2 * small[0], (small, large)
