"""A ``--restart`` that cannot go on from the folder's checkpoints is refused, not turned into
a fresh run over the earlier one's files.

A finished run's checkpoints, renamed as a 2-rank run's, met a 1-rank ``--restart``: it said
"note: no checkpoint for this number of ranks; starting from t = 0" and overwrote
probes.csv. Now it exits 2 naming the folder, the ranks of the checkpoints and what to do, and
every file of the folder is left as it was (contents and times), nothing added. The 2-rank
restart of a 1-rank run (the tester's case) is tests/mpi/test_restart_ranks_mpi.py.
"""

import os

from scenekit import spun_beam

from beamfx.cli import main

SCENE = spun_beam("4 * t**2", 0.05)


def snapshot(folder):
    """{name: (bytes, modification time)} of every entry of ``folder``."""
    return {
        e.name: (open(e.path, "rb").read(), e.stat().st_mtime_ns)
        for e in os.scandir(folder)
        if e.is_file()
    }


def test_a_restart_on_other_ranks_is_refused_and_touches_nothing(tmp_path, capsys):
    scene, out = tmp_path / "s.toml", tmp_path / "out"
    scene.write_text(SCENE)
    assert main(["run", str(scene), "--out", str(out)]) == 0
    (out / "checkpoint_1ranks_0.npz").rename(out / "checkpoint_2ranks_0.npz")
    (out / "checkpoint_2ranks_1.npz").write_bytes((out / "checkpoint_2ranks_0.npz").read_bytes())
    before = snapshot(out)
    capsys.readouterr()
    code = main(["run", str(scene), "--out", str(out), "--restart"])
    err = capsys.readouterr().err
    assert code == 2, err
    assert f"{out}: cannot --restart on 1 rank" in err
    assert "written by a run on 2 ranks (checkpoint_2ranks_0.npz, checkpoint_2ranks_1.npz)" in err
    assert "mpirun -n 2 beamfx run ... --restart" in err and "without --restart" in err
    assert "starting from t = 0" not in err and "Traceback" not in err
    assert snapshot(out) == before


def test_a_restart_with_checkpoints_of_this_and_other_ranks_goes_on(tmp_path, capsys):
    """A folder that also holds another rank count's checkpoints is not refused."""
    scene, out = tmp_path / "s.toml", tmp_path / "out"
    scene.write_text(SCENE)
    assert main(["run", str(scene), "--out", str(out)]) == 0
    (out / "checkpoint_3ranks_0.npz").write_bytes(b"stale")
    capsys.readouterr()
    assert main(["run", str(scene), "--out", str(out), "--restart"]) == 0
    assert "restart from the checkpoint at t = 0.05" in capsys.readouterr().out
