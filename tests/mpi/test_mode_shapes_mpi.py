"""Run under ``mpirun -n 2``: mode shapes at the probes and the model's size of the mode frames
are those of the whole model, whatever each rank's part of it.

The cantilever (1 m steel, 16 × P3) is the case a blind tester found: with its probes ``tip``
(b:end) and ``mid`` (b:0.5, on the partition's interface with 2 ranks), the tip's mode shape
came out as the mid's when the ranks looked the points up in different orders (string hashes
differ between processes), and the ParaView frames were scaled to each rank's own extent.
"""

import numpy as np
import pytest
from mpi4py import MPI

from beamfx.analyses.model import BeamModel
from beamfx.scene import load_scene

pytestmark = pytest.mark.mpi

POINTS = ("b:end", "b:0.5")


CANTILEVER = """
[material]
E = 210e9
nu = 0.3
rho = 7850
[[beams]]
name = "b"
curve = { shape = "line", start = [0, 0, 0], end = [1, 0, 0] }
section = { type = "rectangle", h = 0.02, w = 0.01 }
elements = 16
degree = 3
[[supports]]
at = "b:start"
fix = "all"
[[probes]]
name = "tip"
at = "b:end"
[[probes]]
name = "mid"
at = "b:0.5"
[analysis]
type = "modal"
modes = 4
"""


@pytest.fixture(scope="module")
def modal(tmp_path_factory):
    """The cantilever on all ranks with its first 4 modes, normalised as for the output."""
    from beamfx.analyses.modal import solve_modes
    from beamfx.analyses.mode_shapes import normalise

    path = tmp_path_factory.mktemp("scene") / "cantilever.toml"  # one per rank
    path.write_text(CANTILEVER)
    model = BeamModel(load_scene(path).model, MPI.COMM_WORLD, extra_points=list(POINTS))
    modes = solve_modes(model, n_modes=4).modes
    normalise(model, modes)
    return model, modes


class _RankOrdered(str):
    """A point name whose hash, so its place in a set, depends on the rank: the names of
    :data:`POINTS` iterate in their order on even ranks and reversed on odd ones (what
    different PYTHONHASHSEEDs of the ranks do at random)."""

    def __hash__(self):
        order = POINTS if MPI.COMM_WORLD.rank % 2 == 0 else POINTS[::-1]
        return 1 + order.index(str(self))


def test_mode_report_independent_of_set_order(modal, monkeypatch):
    """Each probe's mode shape is its own point's, when the ranks would visit the points in
    different orders."""
    from beamfx.analyses.dofs import point_displacement, point_displacement_dofs
    from beamfx.analyses.mode_shapes import mode_report

    model, modes = modal
    expected = {}  # looked up one point at a time, in the same order on every rank
    for at in POINTS:
        dofs = point_displacement_dofs(model, at)
        expected[at] = [point_displacement(model, dofs, m.x.array) for m in modes]
    assert list({_RankOrdered(p) for p in POINTS}) == list(
        POINTS if MPI.COMM_WORLD.rank % 2 == 0 else POINTS[::-1]
    )  # the set's order does differ between the ranks
    points = model.mesh.points  # the model's names, with the rank-dependent hash
    for at in POINTS:
        value = points[at]
        monkeypatch.delitem(points, at)
        monkeypatch.setitem(points, _RankOrdered(at), value)
    report = mode_report(model, {"tip": _RankOrdered("b:end"), "mid": _RankOrdered("b:0.5")}, modes)
    for i, shapes in enumerate(report):
        for name, at in (("tip", "b:end"), ("mid", "b:0.5")):
            assert np.allclose(shapes[name], expected[at][i], rtol=0, atol=1e-12), (i, name)
    # the first bending mode: the tip moves most (1 after normalising), the middle a third
    assert abs(report[0]["tip"][1]) == pytest.approx(1.0, abs=1e-9)
    assert abs(report[0]["mid"][1]) == pytest.approx(0.3396, abs=1e-3)


class _Recorder:
    """Frames of :func:`~beamfx.analyses.mode_shapes.write_modes`: the largest displacement
    of each (over all ranks), in place of a ParaView file."""

    def __init__(self, model):
        from beamfx.analyses.dofs import subspace_dofs

        self.model, self.u_dofs, self.largest = model, subspace_dofs(model.W, 0), []

    def write(self, step, time):
        local = np.abs(self.model.w.x.array[self.u_dofs]).max(initial=0.0)
        self.largest.append(self.model.comm.allreduce(local, op=MPI.MAX))


def test_mode_frames_scaled_to_the_whole_model(modal):
    """Each mode's frame moves the model by a tenth of its size (1 m), not of a rank's part."""
    from beamfx.analyses.mode_shapes import write_modes

    model, modes = modal
    frames = _Recorder(model)
    write_modes(model, modes, frames)
    assert np.allclose(frames.largest, 0.1, rtol=1e-12), frames.largest


def test_model_size_is_global(modal):
    """The model's size of the arc-length defaults and of buckling's difference step: the
    whole cantilever's length on every rank."""
    from beamfx.analyses.buckling import _scaled_max
    from beamfx.analyses.continuation import model_size
    from beamfx.analyses.dofs import subspace_dofs
    from beamfx.geometry.mesh import mesh_size

    model, modes = modal
    assert mesh_size(model.mesh.mesh) == pytest.approx(1.0, rel=1e-12)
    assert model_size(model) == pytest.approx(1.0, rel=1e-12)
    u_only = modes[0].copy()  # largest |u| 1 (normalised), no rotation: |u| / size = 1
    u_only.x.array[subspace_dofs(model.W, 1)] = 0.0
    assert _scaled_max(model, u_only) == pytest.approx(1.0, rel=1e-12)
