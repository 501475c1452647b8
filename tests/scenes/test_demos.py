"""The demos are literate scripts; each ends by checking a published or exact value.

A demo writes into results/<its name>/ under the current folder, or under $BEAMFX_DEMO_OUT:
here a temporary folder (rank 0's under MPI), so that the tests write nothing into the
repository (nor into docs/) and leave no folders behind but pytest's own."""

import runpy
from pathlib import Path

import pytest

REPO = Path(__file__).parents[2]
DEMOS = sorted((REPO / "demos").glob("*.py"))

#: demos of more than ~10 s warm: in the slow set (blade_prebend, a 61.5 m blade solved a
#: dozen times, takes 4 s warm now)
SLOW = set()


def _params(demos):
    marks = {True: [pytest.mark.slow], False: []}
    return [pytest.param(d, id=d.stem, marks=marks[d.stem in SLOW]) for d in demos]


#: the folder each demo writes into (under results/ or $BEAMFX_DEMO_OUT) as the tests run
#: it: the short runs have names of their own (a `--full` run's results stay); the others
#: write nothing
WRITES = {
    "blade_prebend": ["blade_prebend"],
    "pai_beam": ["pai_beam_short"],
    "pai_spin_ramp": ["pai_spin_ramp_short"],
    "shallow_arch": ["shallow_arch"],
}


@pytest.fixture
def demo_out(tmp_path, monkeypatch):
    """$BEAMFX_DEMO_OUT: a temporary folder, the same on every rank (rank 0's)."""
    from mpi4py import MPI

    folder = Path(MPI.COMM_WORLD.bcast(str(tmp_path), root=0))
    monkeypatch.setenv("BEAMFX_DEMO_OUT", str(folder))
    return folder


def _files(folder):
    """{path: modification time} of the files under ``folder`` (results/ and caches aside)."""
    skip = {".git", ".venv", "results", "__pycache__", ".pytest_cache", ".ruff_cache"}
    out = {}
    for p in folder.rglob("*"):
        if p.is_file() and not skip.intersection(p.relative_to(folder).parts):
            out[p] = p.stat().st_mtime_ns
    return out


@pytest.mark.parametrize("demo", _params(DEMOS))
def test_demo_runs_and_checks_its_result(demo, demo_out):
    before = _files(REPO)
    runpy.run_path(str(demo), run_name="__main__")
    assert _files(REPO) == before, "the demo wrote into the repository"
    written = sorted(p.name for p in demo_out.iterdir())
    assert written == WRITES.get(demo.stem, []), written
    if written:
        assert any((demo_out / written[0]).iterdir())


#: under mpirun: bend45 starts from one element, which leaves a rank of two without a cell
#: (the quaternion model refuses that with a ValueError; the demo is run serially above)
MPI_DEMOS = [d for d in DEMOS if d.stem != "bend45"]


@pytest.mark.mpi
@pytest.mark.parametrize("demo", _params(MPI_DEMOS))
def test_demo_under_mpi(demo, demo_out):
    runpy.run_path(str(demo), run_name="__main__")
