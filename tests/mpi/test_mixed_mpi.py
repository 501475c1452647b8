"""Run under ``mpirun -n 2``: the mixed formulation gives the serial answers (coupled 6×6
sections, modes and a large static deflection; Euler buckling at EA, GA ×1e8)."""

from dataclasses import replace

import numpy as np
import pytest
from mpi4py import MPI

from beamfx.analyses.buckling import solve_buckling
from beamfx.analyses.modal import solve_modes
from beamfx.analyses.model import BeamModel
from beamfx.analyses.static import solve_static
from beamfx.bench import schwab_meijaard_eigen as sme
from beamfx.bench._builders import cantilever, straight
from beamfx.bench.stress_matrix import stiffened
from beamfx.geometry import Line
from beamfx.io import evaluate_points
from beamfx.physics.matrix_sections import MatrixSection, offset_mass, offset_stiffness
from beamfx.spec import Beam, Model, PointLoad, Support

pytestmark = pytest.mark.mpi


def _spec():
    """test_matrix_mpi's tapered, twisted beam with offsets (coupled 6×6 sections)."""
    C0 = offset_stiffness(2e7, 6e6, 7e6, 3e3, 5e3, 9e3, (0.03, -0.05), (0.01, 0.02))
    M0 = offset_mass(2.0, (1e-3, 4e-4, 6e-4), (0.02, -0.04))
    sec = MatrixSection([C0, 0.5 * C0], [M0, 0.7 * M0], (0.0, 1.0), 1.5)
    beam = Beam("b", Line((0, 0, 0), (1.5, 0.2, 0.1)), sec, 8, 3, None, lambda s: 40.0 * s)
    load = PointLoad("b:end", (10.0, 30.0, -20.0), (2.0, 1.0, 0.0))
    clamp = ("ux", "uy", "uz", "rx", "ry", "rz")
    return Model(beams=(beam,), supports=(Support("b:start", clamp),), point_loads=(load,))


def test_a_coupled_beam_in_the_mixed_form_matches_serial_and_the_displacement_form():
    out = {}
    for comm, formulation in (
        (MPI.COMM_SELF, "displacement"),
        (MPI.COMM_SELF, "mixed"),
        (MPI.COMM_WORLD, "mixed"),
    ):
        model = BeamModel(replace(_spec(), formulation=formulation), comm, ["b:end"])
        hz = solve_modes(model, 6).hz
        solve_static(model, steps=4)
        tip = evaluate_points(model, ["b:end"])["b:end"]
        out[comm.size, formulation] = (hz, np.r_[tip["position"], tip["rotation_vector"]])
    hz_p, tip_p = out[MPI.COMM_WORLD.size, "mixed"]
    hz_s, tip_s = out[1, "mixed"]
    hz_d, tip_d = out[1, "displacement"]
    assert np.allclose(hz_p, hz_s, rtol=1e-9), (hz_p, hz_s)
    assert np.allclose(tip_p, tip_s, rtol=1e-8, atol=1e-10), (tip_p, tip_s)
    # the same discrete equations (the coupled split n·(Γ + A⁻¹BK) − ½n·A⁻¹n): modes to
    # round-off of a ratio-1e4 tangent, the tip to Newton's tolerance
    assert np.allclose(hz_s, hz_d, rtol=1e-9), (hz_s, hz_d)
    assert np.allclose(tip_s, tip_d, rtol=1e-7, atol=1e-9), (tip_s, tip_d)


def test_euler_buckling_at_1e8_matches_serial():
    got = {}
    for comm in (MPI.COMM_SELF, MPI.COMM_WORLD):
        with stiffened(1e8):
            spec = cantilever(
                straight(sme.L25), sme.stiffened(sme.S25, stretch=False), 4, 3, force=(-1, 0, 0)
            )
            model = BeamModel(replace(spec, formulation="mixed"), comm)
            res = solve_buckling(model, n_modes=1)
        got[comm.size] = (res.load_factors[0] / sme.F_TH_25, res.negative_eigenvalues)
    assert abs(got[1][0] - 1.0) < 1e-6
    assert abs(got[MPI.COMM_WORLD.size][0] - got[1][0]) < 1e-10, got
    assert got[1][1] == got[MPI.COMM_WORLD.size][1] == 0
