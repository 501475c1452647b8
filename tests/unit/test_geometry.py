"""Curves: lengths, arc-length parametrisation, gmsh input, convergence to the exact geometry."""

from pathlib import Path

import numpy as np
import pytest
import ufl
from mpi4py import MPI

from beamfx.geometry import (
    Arc,
    BeamSpec,
    Helix,
    Line,
    Polyline,
    SampledCurve,
    build_mesh,
    curve_from_gmsh,
)
from beamfx.solvers import compile_form

MESHES = Path(__file__).parents[2] / "meshes"
ARC = Arc((0, 0, 0), (1, 0, 0), (0, 1, 0), 90.0)


def mesh_length(curve, n, p):
    m = build_mesh(MPI.COMM_WORLD, [BeamSpec("c", curve, n)], p).mesh
    form = compile_form(1.0 * ufl.dx(domain=m, metadata={"quadrature_degree": 2 * p + 2}))
    import dolfinx

    return MPI.COMM_WORLD.allreduce(dolfinx.fem.assemble_scalar(form), op=MPI.SUM)


@pytest.mark.parametrize("p", [2, 3])
def test_curved_mesh_converges_to_the_exact_arc_length(p):
    """Isoparametric P_p geometry: length error O(h^(2p)) (even p: one order more by symmetry)."""
    errors = [abs(mesh_length(ARC, n, p) - np.pi / 2) for n in (2, 4, 8)]
    order = np.log2(errors[1] / errors[2])
    assert order > p + 0.8, errors


def test_arc_helix_polyline_and_spline_are_parametrised_by_arc_length():
    for curve, length in [
        (ARC, np.pi / 2),
        (Helix((0, 0, 0), (0, 0, 1), 2.0, 1.0, 1.5), 1.5 * np.hypot(4 * np.pi, 1.0)),
        (Polyline(((0, 0, 0), (3, 0, 0), (3, 4, 0))), 7.0),
        (Line((1, 1, 1), (2, 3, 3)), 3.0),
    ]:
        assert np.isclose(curve.length, length, rtol=1e-12)
        s = np.union1d(np.linspace(0, curve.length, 2001), curve.kinks)
        steps = np.linalg.norm(np.diff(curve.points(s), axis=0), axis=1)
        assert np.allclose(steps.sum(), curve.length, rtol=1e-5)
    circle = SampledCurve(tuple(ARC.points(np.linspace(0, ARC.length, 40))))
    assert np.isclose(circle.length, np.pi / 2, rtol=1e-6)


def test_gmsh_geo_curve_matches_the_exact_arc():
    curve = curve_from_gmsh(MESHES / "quarter_circle.geo")
    assert np.isclose(curve.length, np.pi / 2, rtol=1e-8)
    s = np.linspace(0, curve.length, 7)
    assert np.allclose(curve.points(s), ARC.points(s), atol=1e-8)


def test_polyline_kinks_are_vertices_and_frames_share_joints():
    frame = [
        BeamSpec("a", Polyline(((0, 0, 0), (1, 0, 0), (1, 1, 0))), 4),
        BeamSpec("b", Line((1, 1, 0), (1, 1, 1)), 2),
    ]
    bm = build_mesh(MPI.COMM_WORLD, frame, 2, {"corner": (1, 0, 0), "joint": (1, 1, 0)})
    assert set(bm.points) == {"corner", "joint"}
    n_vertices = bm.mesh.topology.index_map(0).size_global
    assert n_vertices == 4 + 1 + 2  # joint shared
