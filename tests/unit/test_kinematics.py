"""Objectivity, path independence and exactness of the Simo–Reissner model."""

import numpy as np
import pytest
import ufl
from conftest import nodal, value_at
from mpi4py import MPI

from beamfx.analyses.model import BeamModel
from beamfx.analyses.static import solve_static
from beamfx.geometry import Arc, Line
from beamfx.physics.rotations import np_quaternion, np_rotation
from beamfx.physics.sections import Section
from beamfx.solvers import compile_form
from beamfx.spec import Beam, Model, PointLoad, Support

CLAMP = ("ux", "uy", "uz", "rx", "ry", "rz")
SEC = Section(EA=1770e3, GA_y=1770e3, GA_z=1770e3, GJ=8.16e3, EI_y=86.9e3, EI_z=215e3)
L = 10.0


def energy(model):
    return MPI.COMM_WORLD.allreduce(
        __import__("dolfinx").fem.assemble_scalar(compile_form(model.Pi)), op=MPI.SUM
    )


def quat_mul(a, b):
    return np.c_[
        a[0] * b[:, 0] - b[:, 1:] @ a[1:],
        a[0] * b[:, 1:] + np.outer(b[:, 0], a[1:]) + np.cross(a[1:], b[:, 1:]),
    ]


def curved_model(n=4, p=3):
    arc = Arc((0, 0, 0), (0, 1, 0), (100, 0, 0), 45.0)
    return BeamModel(
        Model(
            (Beam("b", arc, SEC, n, p),),
            (Support("b:start", CLAMP),),
            (PointLoad("b:end", (0, 0, 600.0), (100.0, 50.0, 0.0)),),
        )
    )


def test_superposed_rigid_rotation_produces_no_strain():
    """Π(Q·state) = Π(state) for a rigid rotation Q, and Π = 0 for a pure rigid motion."""
    m = curved_model()
    m.set_load_factor(1.0)
    solve_static(m, steps=4)
    pi_deformed = energy(m)
    assert pi_deformed > 0
    Qq = np_quaternion((1, 2, -0.5), 2.7)
    Q = np_rotation(Qq)
    Xu, u, du = nodal(m, 0)
    _, q, dq = nodal(m, 1)
    m.w.x.array[du] = ((Xu + u) @ Q.T - Xu + [3.0, -1.0, 2.0]).ravel()
    m.w.x.array[dq] = quat_mul(Qq, q).ravel()
    assert abs(energy(m) - pi_deformed) < 1e-10 * pi_deformed
    # undeformed, rigidly rotated and translated: zero strain energy
    m.w.x.array[du] = (Xu @ Q.T - Xu + 5.0).ravel()
    m.w.x.array[dq] = np.tile(Qq, len(q)).ravel()
    assert abs(energy(m)) < 1e-18 * pi_deformed + 1e-20


def rollup(direction, moment_axis, k, n=16, p=3):
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    a = np.asarray(moment_axis, float) / np.linalg.norm(moment_axis)
    M = k * 2 * np.pi * SEC.EI_y / L
    # orientation: section z normal to the bending plane's... bending about section y = moment axis
    beam = Beam("b", Line((0, 0, 0), tuple(L * d)), SEC, n, p, orientation=tuple(np.cross(d, a)))
    return BeamModel(
        Model((beam,), (Support("b:start", CLAMP),), (PointLoad("b:end", moment=tuple(M * a)),))
    )


@pytest.mark.parametrize("steps", [1, 2, 4])
def test_skew_rollup_is_a_rotated_exact_circle_for_any_step_count(steps):
    """ROLLUP-SKEW: beam along (1,1,1)/√3, moment about (1,-1,0)/√2, λ = 1 (one full turn)."""
    d = np.array([1, 1, 1]) / np.sqrt(3)
    a = np.array([1, -1, 0]) / np.sqrt(2)
    m = rollup(d, a, 1.0)
    solve_static(m, steps=steps * 4)
    X, u = value_at(m, 0, L * d)
    # the exact tip of a full turn is back at the root: u_tip = -L d
    assert np.linalg.norm(X + u) < 1e-6 * L


def test_two_full_turns_and_back_returns_to_start():
    """Load to 4π then unload to 0: path independence for a conservative load."""
    m = rollup((1, 0, 0), (0, -1, 0), 2.0)
    solve_static(m, steps=16)
    X, u = value_at(m, 0, (L, 0, 0))
    assert np.linalg.norm(X + u) < 1e-6 * L  # two turns: tip at the root again
    _, q = value_at(m, 1, (L, 0, 0))
    assert q[0] / np.linalg.norm(q) > 1 - 1e-8  # q passed through -1 and back to +1 (4π)
    for lam in np.linspace(1, 0, 17)[1:]:
        m.set_load_factor(lam)
        from beamfx.solvers import NewtonSolver

        rep = NewtonSolver(m.F, m.J, m.w, m.bcs, "unload_").solve()
        assert rep.converged
    _, u, _ = nodal(m, 0)
    assert np.max(np.abs(u)) < 1e-9 * L


def test_rotation_matrices_stay_orthonormal_at_quadrature_points():
    """RᵀR = I of the interpolated (non-unit) quaternion field after a large deformation."""
    from beamfx.physics.rotations import rotation

    m = rollup((1, 0, 0), (0, -1, 0), 0.6, n=4)
    solve_static(m, steps=6)
    _, q = ufl.split(m.w)
    R = rotation(q)
    err = ufl.inner(R.T * R - ufl.Identity(3), R.T * R - ufl.Identity(3)) * m.discretisation.dx
    val = MPI.COMM_WORLD.allreduce(
        __import__("dolfinx").fem.assemble_scalar(compile_form(err)), op=MPI.SUM
    )
    assert val < 1e-24
