"""Run under ``mpirun -n 2``: the rotating analysis in the mixed form gives the serial
answers (SM 2.10's blade at EA, GA ×1e8: steady state and gyroscopic frequencies, the shell
eigen solves of :mod:`beamfx.solvers.eigen_shell` on distributed vectors)."""

from dataclasses import replace

import numpy as np
import pytest
from mpi4py import MPI

from beamfx.analyses.model import BeamModel
from beamfx.analyses.rotating import RotatingFrame, solve_rotating_modes, solve_steady
from beamfx.analyses.rotating_checks import lowest_tangent_eigenvalue
from beamfx.bench import schwab_meijaard_rotating as smr
from beamfx.bench.stress_matrix import stiffened

pytestmark = pytest.mark.mpi


def _run(comm):
    with stiffened(1e8):
        model = BeamModel(replace(smr.blade_model(4, 3), formulation="mixed"), comm)
    frame = RotatingFrame(model, rotary="none")
    frame.set_speed(0.0)
    model.set_load_factor(0.0)
    mu, _ = lowest_tangent_eigenvalue(frame)
    solve_steady(frame, smr.OMEGA_BY, steps=1)
    omega = solve_rotating_modes(frame, 6).omega
    frame.destroy()
    return mu, omega


def test_stiff_rotating_blade_in_the_mixed_form_matches_serial():
    mu_s, omega_s = _run(MPI.COMM_SELF)
    mu_p, omega_p = _run(MPI.COMM_WORLD)
    assert abs(mu_p - mu_s) <= 1e-9 * abs(mu_s)
    assert np.allclose(omega_p, omega_s, rtol=1e-9), (omega_p, omega_s)
