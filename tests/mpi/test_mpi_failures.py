"""A failure on one MPI rank ends the whole job within seconds, with its message: never a hang.

Each case starts ``mpirun -n 2 beamfx run`` in a process of its own with a time limit (from
the first rank of a plain or an ``mpirun`` pytest; the others skip): a restart whose rank-1
checkpoint is missing or cut short (every rank reads its file and the ranks agree: exit 2,
one message), and a write that fails on rank 1 only while rank 0 goes on (rank 1 waits a
few seconds for the others, then aborts the job: exit 2, its message).
"""

import os
import shutil
import subprocess
import sys
import time

import pytest
from scenekit import SPIN_HISTORY, spun_beam

pytestmark = [
    pytest.mark.mpi,
    pytest.mark.skipif(
        os.environ.get("OMPI_COMM_WORLD_RANK", "0") != "0", reason="rank 0 starts the jobs"
    ),
    pytest.mark.skipif(shutil.which("mpirun") is None, reason="needs mpirun"),
]

SCENE = spun_beam("4 * t**2", 0.1, checkpoint_every=5)
#: the spin-up of tests/scenes/test_restart.py: the tip turns past 2π by t = 0.96
# 600 steps: long enough for mpirun to pass a SIGINT on to the ranks mid-run
SPIN = spun_beam(SPIN_HISTORY, 3.0, checkpoint_every=20)
LIMIT = 240  # s: a hang would be killed here (a run takes about 10 s)


def mpirun(cwd, *args, entry=("-m", "beamfx.cli")):
    """``mpirun -n 2 beamfx ...`` (or ``entry``: a script): (exit status, stderr, seconds),
    killed after LIMIT."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_"))}
    env["OMPI_MCA_rmaps_base_oversubscribe"] = "1"
    command = ["mpirun", "--allow-run-as-root", "-n", "2", sys.executable, *entry]
    t = time.monotonic()
    run = subprocess.run(
        [*command, *args],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=LIMIT,
        check=False,
    )
    return run.returncode, run.stderr, time.monotonic() - t


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """A folder with the checkpoints of a finished run on 2 ranks."""
    root = tmp_path_factory.mktemp("mpi")
    (root / "spin.toml").write_text(SCENE)
    code, err, _ = mpirun(root, "run", "spin.toml", "--out", "out")
    assert code == 0, err
    return root


@pytest.mark.parametrize("damage", ["missing", "truncated"])
def test_a_bad_checkpoint_of_rank_1_stops_every_rank_with_the_message(finished, damage):
    path = finished / "out" / "checkpoint_2ranks_1.npz"
    saved = path.read_bytes()
    try:
        if damage == "missing":
            path.unlink()
            expected = "the checkpoint of rank(s) [1] is missing (checkpoint_2ranks_1.npz)"
        else:
            path.write_bytes(saved[: len(saved) // 3])
            expected = "checkpoint_2ranks_1.npz: not a readable checkpoint"
        code, err, seconds = mpirun(finished, "run", "spin.toml", "--out", "out", "--restart")
    finally:
        path.write_bytes(saved)
    assert code == 2, err
    assert err.count(expected) == 1  # printed once, by rank 0
    assert "Traceback" not in err
    print(f"{damage}: ended in {seconds:.1f} s")


def test_a_failure_on_rank_1_alone_aborts_the_job(tmp_path):
    """Rank 1 cannot write its checkpoint (its name is taken by a folder); rank 0 has written
    its own and goes on to the next step's collective calls."""
    (tmp_path / "spin.toml").write_text(SCENE)
    (tmp_path / "out" / "checkpoint_2ranks_1.npz").mkdir(parents=True)
    code, err, seconds = mpirun(tmp_path, "run", "spin.toml", "--out", "out")
    assert code == 2, err
    assert "Is a directory" in err and "(rank 1; stopping all ranks)" in err
    print(f"rank-1 failure: job ended in {seconds:.1f} s")


#: ``beamfx`` whose rank 0 cannot write its third row of reactions.csv (a full disk)
FULL_DISK = """import sys
from mpi4py import MPI
from beamfx.io import reaction_files
write, rows = reaction_files.ReactionCsv.write, [0]
def failing(self, row):
    rows[0] += 1
    if MPI.COMM_WORLD.rank == 0 and rows[0] == 3:
        raise OSError(28, "No space left on device (test)")
    return write(self, row)
reaction_files.ReactionCsv.write = failing
from beamfx.cli import main
sys.exit(main(sys.argv[1:]))
"""


def test_a_write_error_on_rank_0_with_probe_rows_kept_aborts_the_job(tmp_path):
    """Rank 0 fails to write reactions.csv between frames, while both ranks keep probe rows
    for the next block: the history must not gather them from a rank that went on (it hung
    once), the job ends with rank 0's message."""
    output = '[output]\nevery = 10\nreaction_rows = "steps"\n'
    (tmp_path / "spin.toml").write_text(spun_beam("0.5 * t", 0.4, dt=0.02) + output)
    (tmp_path / "full_disk.py").write_text(FULL_DISK)
    code, err, seconds = mpirun(
        tmp_path, "run", "spin.toml", "--out", "out", entry=("full_disk.py",)
    )
    assert code == 2, err
    assert "No space left on device (test)" in err and "(rank 0; stopping all ranks)" in err
    print(f"rank-0 write failure: job ended in {seconds:.1f} s")


@pytest.mark.slow
def test_two_ranks_interrupted_and_restarted_equal_the_whole_run(tmp_path):
    """The spin-up of tests/scenes/test_restart.py on 2 ranks: SIGINT to mpirun (which sends
    SIGTERM to the ranks) past the tip's 2π, then --restart: the history equals that of the
    whole 2-rank run to 1e-12 of each column's size."""
    import signal

    import numpy as np

    (tmp_path / "spin.toml").write_text(SPIN)
    code, err, _ = mpirun(tmp_path, "run", "spin.toml", "--out", "whole")
    assert code == 0, err
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_"))}
    command = ["mpirun", "--allow-run-as-root", "-n", "2", sys.executable, "-m", "beamfx.cli"]
    run = subprocess.Popen(
        [*command, "run", "spin.toml", "--out", "part"],
        cwd=tmp_path,
        env=env | {"OMPI_MCA_rmaps_base_oversubscribe": "1"},
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    csv = tmp_path / "part" / "probes.csv"
    while run.poll() is None:
        if csv.exists() and csv.read_text().count("\n") >= 200:
            run.send_signal(signal.SIGINT)
            break
        time.sleep(0.005)
    _, err = run.communicate(timeout=LIMIT)
    assert "stopped: interrupted by SIGTERM" in err
    code, err, _ = mpirun(tmp_path, "run", "spin.toml", "--out", "part", "--restart")
    assert code == 0, err
    a, b = (np.genfromtxt(tmp_path / f / "probes.csv", delimiter=",", names=True)
            for f in ("whole", "part"))  # fmt: skip
    assert len(a) == len(b) == 601
    for name in a.dtype.names:
        scale = max(1.0, np.max(np.abs(a[name])))
        np.testing.assert_allclose(b[name], a[name], rtol=0, atol=1e-12 * scale, err_msg=name)
