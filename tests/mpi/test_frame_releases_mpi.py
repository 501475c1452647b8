"""Run under ``mpirun -n 2`` (and serially): released joints (beamfx.analyses.releases) and
the mechanism check (beamfx.analyses.mechanisms) on a partitioned mesh: the hinge unknowns
live on the cells of each rank, the dense check gathers the stiffness on rank 0."""

import tomllib
from dataclasses import replace
from pathlib import Path

import pytest
from mpi4py import MPI

from beamfx.analyses.model import BeamModel
from beamfx.bench import frame_peers, frame_stiffness
from beamfx.scene.load import parse_scene
from beamfx.spec import Release

pytestmark = pytest.mark.mpi

PORTAL = (Path(__file__).resolve().parents[1] / "convergence" / "test_frames.py").read_text()
PORTAL = PORTAL.split('PORTAL = """', 1)[1].split('"""', 1)[0].replace("ELEMENTS", "3")


def _spec(releases):
    return replace(parse_scene(tomllib.loads(PORTAL)).model, releases=releases)


def test_a_released_portal_equals_the_exact_frame_on_every_rank():
    spec = _spec((Release("top:start", ("ry", "rz")), Release("right:start", ("rx",))))
    u, reactions, _ = frame_peers.beamfx_frame(spec, MPI.COMM_WORLD)
    exact, exact_reactions = frame_stiffness.solve(frame_stiffness.problem_from_model(spec))
    errors = frame_peers.differences(u, reactions, exact, exact_reactions)
    assert max(MPI.COMM_WORLD.allreduce(max(errors), op=MPI.MAX), max(errors)) < 1e-9


def test_a_mechanism_is_reported_by_every_rank():
    """The girder pinned at both ends spins about its axis, and the right column (its foot
    holds rz only) swings."""
    spec = _spec((Release("top:start", joint="A"), Release("top:end", joint="B")))
    with pytest.raises(ValueError, match=r"leave 2 mechanism\(s\): joints \['A', 'B'\]"):
        BeamModel(spec, MPI.COMM_WORLD)
