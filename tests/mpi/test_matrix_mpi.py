"""Run under ``mpirun -n 2``: matrix sections (station tables, offsets) give the serial answers."""

import numpy as np
import pytest
from mpi4py import MPI

from beamfx.analyses.modal import solve_modes
from beamfx.analyses.model import BeamModel
from beamfx.analyses.static import solve_static
from beamfx.geometry import Line
from beamfx.io import evaluate_points
from beamfx.physics.matrix_sections import MatrixSection, offset_mass, offset_stiffness
from beamfx.spec import Beam, Model, PointLoad, Support

pytestmark = pytest.mark.mpi

CLAMP = ("ux", "uy", "uz", "rx", "ry", "rz")


def _spec():
    C0 = offset_stiffness(2e7, 6e6, 7e6, 3e3, 5e3, 9e3, (0.03, -0.05), (0.01, 0.02))
    M0 = offset_mass(2.0, (1e-3, 4e-4, 6e-4), (0.02, -0.04))
    sec = MatrixSection([C0, 0.5 * C0], [M0, 0.7 * M0], (0.0, 1.0), 1.5)
    twist = lambda s: 40.0 * np.asarray(s)
    beam = Beam("b", Line((0, 0, 0), (1.5, 0.2, 0.1)), sec, 8, 3, None, twist)
    load = PointLoad("b:end", (10.0, 30.0, -20.0), (2.0, 1.0, 0.0))
    return Model(beams=(beam,), supports=(Support("b:start", CLAMP),), point_loads=(load,))


def test_a_tapered_coupled_twisted_beam_matches_serial():
    out = {}
    for comm in (MPI.COMM_SELF, MPI.COMM_WORLD):
        model = BeamModel(_spec(), comm, ["b:end"])
        hz = solve_modes(model, 6).hz
        solve_static(model, steps=4)
        tip = evaluate_points(model, ["b:end"])["b:end"]
        out[comm.size] = (hz, np.r_[tip["position"], tip["rotation_vector"]])
    (hz_p, tip_p), (hz_s, tip_s) = out[MPI.COMM_WORLD.size], out[1]
    assert np.allclose(hz_p, hz_s, rtol=1e-9), (hz_p, hz_s)
    assert np.allclose(tip_p, tip_s, rtol=1e-8, atol=1e-10), (tip_p, tip_s)
