"""Stiffness-proportional damping is objective: a bent beam carried through a rigid rotation at
constant angular velocity has strains constant in time, so its viscous stresses a1 C ε̇ and
their power are zero to round-off (:mod:`beamfx.analyses.strain_rates`). The directional
derivative ∂ε/∂q [q̇] with the integrator's rates, which the damping used before, is not:
the rates of the rotating displacements and of the quaternions are too fast by different
O((ωh)²) factors."""

import numpy as np
import pytest
import ufl
from scenekit import cantilever

from beamfx.analyses.model import BeamModel
from beamfx.analyses.static import solve_static
from beamfx.analyses.strain_rates import bdf2_weights, strain_vector
from beamfx.analyses.transient import Dynamics, TransientSettings
from beamfx.physics.rotations import np_exp_rotation, np_quaternion

OMEGA, H, STEPS, A1 = 12.0, 0.01, 30, 0.05
AXIS = np.array([0.3, 0.4, 0.866])


def _qmul(a, b):
    """Quaternion products a b of rows (scalar part first)."""
    a0, av, b0, bv = a[:, :1], a[:, 1:], b[:, :1], b[:, 1:]
    return np.hstack(
        [a0 * b0 - np.sum(av * bv, 1, keepdims=True), a0 * bv + b0 * av + np.cross(av, bv)]
    )


def _rotated(dyn, q0, angle):
    """The unknowns of the state ``q0`` turned rigidly by ``angle`` about AXIS (through 0)."""
    q = q0.copy()
    X = dyn.u_points
    x = X + q0[dyn.u_dofs]
    q[dyn.u_dofs] = x @ np_exp_rotation(angle * AXIS / np.linalg.norm(AXIS)).T - X
    r = np.tile(np_quaternion(AXIS, angle), (len(dyn.r_dofs), 1))
    q[dyn.r_dofs] = _qmul(r, q0[dyn.r_dofs])
    return q


@pytest.fixture(scope="module")
def bent():
    """The tube cantilever bent and twisted by a static tip load (strains ~1e-2)."""
    spec = cantilever(history=np.ones_like, force=(0.0, 3e3, 4e3))
    model = BeamModel(spec, extra_points=["b:end"])
    solve_static(model, steps=2)
    return model


def _norm(form):
    from dolfinx import fem

    return np.sqrt(abs(fem.assemble_scalar(fem.form(form))))


def test_rigid_rotation_dissipates_nothing(bent):
    from dolfinx import fem

    model = bent
    settings = TransientSettings(t_end=1.0, dt=H, damping_stiffness=A1)
    dyn = Dynamics(model, settings)
    q0 = model.w.x.array.copy()
    dyn.start()
    sh = dyn.strain_history
    eps = strain_vector(model)
    scale = _norm(ufl.dot(eps, eps) * sh.dx) * OMEGA  # ω |ε|: a rate of the strains' size
    strain_energy = fem.assemble_scalar(fem.form(model.Pi))
    assert scale > 1e-3
    power = fem.form(dyn.power)
    elastic = np.linalg.norm(fem.assemble_vector(fem.form(model.F)).array)  # ~ C ε δε
    damping = fem.form(ufl.derivative(_dissipation(dyn, model), model.w, ufl.TestFunction(model.W)))
    old_rates = []
    for n in range(1, STEPS + 1):
        dyn.h.value = H
        model.w.x.array[:] = _rotated(dyn, q0, OMEGA * H * n)
        force = np.linalg.norm(fem.assemble_vector(damping).array)
        assert force < 1e-9 * A1 * OMEGA * elastic, (n, force, elastic)  # a1 ω C ε δε: 1
        dyn.accept(H)
        rate = sh.stored_rate()
        r = ufl.as_vector([rate[0][i] for i in range(3)] + [rate[1][i] for i in range(3)])
        assert _norm(ufl.dot(r, r) * sh.dx) < 1e-12 * scale
        assert abs(fem.assemble_scalar(power)) < 1e-18 * A1 * OMEGA**2 * 2 * strain_energy
        old = ufl.derivative(eps, model.w, dyn.v_n)  # ∂ε/∂q [q̇] with the scheme's rates
        old_rates.append(_norm(ufl.dot(old, old) * sh.dx))
    # the rate the damping was built on: a spurious rate of relative size (ωh)² remains
    assert old_rates[-1] > 1e-4 * scale


def _dissipation(dyn, model):
    """D with the factor 1/c0 that makes ∂D/∂q the viscous force a1 C ε̇ · δε."""
    sh, d = dyn.strain_history, model.discretisation
    c0 = bdf2_weights(dyn.h, sh.h_prev, sh.second)[0]
    return d.strain_energy(*sh.rate(), scale=A1 / c0, dx=sh.dx)


def test_bdf2_weights_differentiate_quadratics():
    """Variable-step BDF2 is exact for quadratics; the first step is a backward difference."""
    t = np.array([0.0, 0.3, 0.5])
    f = 2 + 3 * t - 5 * t**2
    c0, c1, c2 = bdf2_weights(t[2] - t[1], t[1] - t[0], 1.0)
    assert c0 * f[2] + c1 * f[1] + c2 * f[0] == pytest.approx(3 - 10 * t[2], rel=1e-13)
    c0, c1, c2 = bdf2_weights(0.2, 1.0, 0.0)
    assert (c0, c1, c2) == pytest.approx((5.0, -5.0, 0.0))
