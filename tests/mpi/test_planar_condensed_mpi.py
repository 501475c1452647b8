"""Run under ``mpirun -n 2``: the planar condensed model gives the same tip from all ranks as
from one process (the closed-form and the quadrature centre line, the follower coupling)."""

from dataclasses import replace

import numpy as np
import pytest
from mpi4py import MPI

from beamfx.analyses.planar_condensed import PlanarCondensedModel
from beamfx.analyses.static import solve_static
from beamfx.bench._builders import cantilever, straight
from beamfx.bench.classic import ROLL_SECTION, L
from beamfx.io import evaluate_points
from beamfx.physics.kinematics import Kinematics

pytestmark = pytest.mark.mpi


@pytest.mark.parametrize(
    "degree, force, follower",
    [(1, (0.0, 0.0, 0.0), False), (2, (0.0, 0.0, 2e3), False), (2, (0.0, 0.0, 2e3), True)],
)
def test_planar_condensed_matches_serial(degree, force, follower):
    moment = (0.0, -4 * np.pi * ROLL_SECTION.EI_y / L, 0.0)  # two turns without the force
    spec = cantilever(straight(L), ROLL_SECTION, 6, degree, force, moment, follower)
    spec = replace(spec, kinematics=Kinematics(plane="xz"))
    tips = []
    for comm in (MPI.COMM_SELF, MPI.COMM_WORLD):
        model = PlanarCondensedModel(spec, comm, extra_points=["b:end", "b:0.5"])
        solve_static(model, steps=8)
        values = evaluate_points(model, ["b:end", "b:0.5"])
        tips.append(np.array([values[n]["position"] for n in ("b:end", "b:0.5")]))
    assert np.abs(tips[0] - tips[1]).max() < 1e-10 * L
