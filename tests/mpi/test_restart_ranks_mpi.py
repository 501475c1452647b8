"""The tester's case: ``mpirun -n 2 beamfx run s.toml --restart`` on the folder of a finished
1-rank run exits 2 on both ranks with one message (the folder, the checkpoints' 1 rank, what
to do) and leaves every file as it was; it said "no checkpoint for this number of ranks;
starting from t = 0" and overwrote probes.csv.

Started from the first rank of a plain or an ``mpirun`` pytest (the others skip), each run a
process of its own (tests/mpi/test_mpi_failures.py's ``mpirun``).
"""

import os
import shutil
import subprocess
import sys

import pytest
from scenekit import spun_beam
from test_mpi_failures import mpirun

pytestmark = [
    pytest.mark.mpi,
    pytest.mark.skipif(
        os.environ.get("OMPI_COMM_WORLD_RANK", "0") != "0", reason="rank 0 starts the jobs"
    ),
    pytest.mark.skipif(shutil.which("mpirun") is None, reason="needs mpirun"),
]


def snapshot(folder):
    """{name: (bytes, modification time)} of every file of ``folder``."""
    return {
        e.name: (open(e.path, "rb").read(), e.stat().st_mtime_ns)
        for e in os.scandir(folder)
        if e.is_file()
    }


def test_a_two_rank_restart_of_a_one_rank_run_is_refused(tmp_path):
    (tmp_path / "s.toml").write_text(spun_beam("4 * t**2", 0.05))
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_"))}
    one = subprocess.run(
        [sys.executable, "-m", "beamfx.cli", "run", "s.toml", "--out", "out"],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=240,
        check=False,
    )
    assert one.returncode == 0, one.stderr
    before = snapshot(tmp_path / "out")
    code, err, _ = mpirun(tmp_path, "run", "s.toml", "--out", "out", "--restart")
    assert code == 2, err
    assert err.count("cannot --restart on 2 ranks") == 1  # once, from rank 0
    assert "written by a run on 1 rank (checkpoint_1ranks_0.npz)" in err
    assert "Restart on one rank (beamfx run ... --restart, without mpirun)" in err
    assert "starting from t = 0" not in err
    assert snapshot(tmp_path / "out") == before
