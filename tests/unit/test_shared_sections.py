"""One section evaluation per output step changes no number (issue 15): the probes, the
condensed reactions and the frame's fields read, inside :func:`beamfx.io.fields.shared_fields`,
bit for bit what their own evaluations give; and the condensed centre line integrates no
quadrature to the node at vertex 0, with the same bits as the quadrature to every node.
Collective throughout: the same file runs under ``mpirun -n 2`` (probe cells may be ghosts)."""

from dataclasses import replace

import numpy as np
import pytest
from mpi4py import MPI

from beamfx.analyses.condensed import CondensedModel
from beamfx.analyses.planar_condensed import PlanarCondensedModel
from beamfx.analyses.reactions import entries
from beamfx.analyses.static import solve_static
from beamfx.bench._builders import cantilever, straight
from beamfx.bench.classic import ROLL_SECTION, L
from beamfx.io import evaluate_points
from beamfx.io.fields import local_fields, shared_fields
from beamfx.physics.kinematics import Kinematics

POINTS = ["b:end", "b:start", "b:0.5"]


def _solved(kind, degree):
    """A cantilever with a point force and end moment, solved in 3 steps: planar condensed
    (the angle, in xz), 3D condensed (the rotation vector) or the full planar model."""
    force = (0.0, 0.0, 2e3) if kind != "condensed" else (0.0, 1e3, 2e3)
    moment = (0.0, -2 * np.pi * ROLL_SECTION.EI_y / L, 0.0)
    spec = cantilever(straight(L), ROLL_SECTION, 5, degree, force, moment)
    if kind == "planar":
        model = PlanarCondensedModel(
            replace(spec, kinematics=Kinematics(plane="xz")), MPI.COMM_WORLD, extra_points=POINTS
        )
    elif kind == "condensed":
        model = CondensedModel(spec, MPI.COMM_WORLD, extra_points=POINTS)
    else:
        from beamfx.analyses.model import BeamModel

        model = BeamModel(
            replace(spec, kinematics=Kinematics(plane="xz")), MPI.COMM_WORLD, extra_points=POINTS
        )
    result = solve_static(model, steps=3)
    assert result.steps and result.steps[-1].load_factor == 1.0
    return model


def _same(a, b):
    """Equal bit for bit: the same keys, lists and arrays (NaN-free here)."""
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, np.ndarray):
        return a.dtype == b.dtype and np.array_equal(a, b)
    return a == b


@pytest.mark.parametrize("kind, degree", [("planar", 3), ("condensed", 2), ("full", 3)])
def test_shared_evaluation_gives_each_consumer_its_own_numbers(kind, degree):
    model = _solved(kind, degree)

    def consumers():
        return (
            evaluate_points(model, POINTS),
            evaluate_points(model, POINTS, recover=False),
            evaluate_points(model, POINTS, full=False),
            entries(model),
            local_fields(model),
        )

    alone = consumers()
    with shared_fields(model):
        shared = consumers()
    for a, b in zip(alone, shared):
        assert _same(a, b)
    sections = evaluate_points(model, POINTS, recover=False, full="sections")
    for n in POINTS:
        assert set(sections[n]) == {"position", "section_axes", "section_force", "section_moment"}
        assert all(sections[n][k] == alone[1][n][k] for k in sections[n])


def _all_node_increments(model, xi, parts):
    """The quadrature of u_ξ from vertex 0 to every node ξ_j, the one at ξ = 0 included (the
    increments before the node at vertex 0 was left out)."""
    import ufl
    from dolfinx import fem

    from beamfx.analyses.condensed import EXACT_TABLES, _gauss
    from beamfx.solvers.forms import JIT_PARAMS

    m = model.mesh.mesh
    gx, gw = _gauss(model.degree + 2)
    local = (np.arange(parts)[:, None] + (gx[None, :] + 1) / 2) / parts
    points = (xi[:, None] * local.ravel()[None, :]).reshape(-1, 1)
    x_xi = ufl.Jacobian(m)[:, 0]
    sign = ufl.dot(model.t_s, model.discretisation.t0)
    u_xi = sign * ufl.sqrt(ufl.dot(x_xi, x_xi)) * (model.x_dot - model.t_s)
    expr = fem.Expression(
        u_xi, points, form_compiler_params=EXACT_TABLES, jit_params=dict(JIT_PARAMS)
    )
    weights = np.tile(gw / 2, parts) / parts
    n = m.topology.index_map(1).size_local
    vals = expr.eval(np.arange(n, dtype=np.int32)).reshape(n, len(xi), len(weights), 3)
    return xi[None, :, None] * np.einsum("cngi,g->cni", vals, weights)


@pytest.mark.parametrize("kind, degree, parts", [("planar", 3, 2), ("condensed", 2, 1)])
def test_centre_line_increments_skip_vertex_0_with_the_same_bits(kind, degree, parts):
    model = _solved(kind, degree)
    xi = model._xi
    assert np.count_nonzero(xi == 0) == 1  # the node at vertex 0
    want = _all_node_increments(model, xi, parts)
    got = model._quadrature_increments(xi, parts)
    assert np.array_equal(got, want)  # (the node at vertex 0: +0.0 here, ±0.0 there)
    assert np.abs(want[:, xi == 0]).max(initial=0.0) == 0.0
