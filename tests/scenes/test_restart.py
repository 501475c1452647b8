"""Interrupted and restarted runs, and checkpoints or folders that must be refused.

A short spin-up (a 3D beam on a hub that turns past 2π, quaternion rotations) is run whole,
then interrupted (SIGINT, SIGTERM, SIGKILL) at steps past π and 2π of the tip's rotation and
restarted with ``--restart``: the history (positions, unwrapped rotations, energies) equals
the whole run's to round-off. The run is deterministic, so the restarted march repeats the
same floating-point operations; the tolerance 1e-12 of each column's size only leaves room
for nothing else. A checkpoint of another scene, a damaged one or one holding a pickle is
refused before anything is solved; a busy output folder is refused naming the process.
"""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from scenekit import SPIN_HISTORY, spun_beam
from test_reactions import CANTILEVER

from beamfx.cli import main
from beamfx.io.output import default_every

SPIN = spun_beam(SPIN_HISTORY, 1.2, checkpoint_every=20)


def beamfx(*args, cwd):
    """``beamfx`` in a process of its own (signals reach it, not pytest)."""
    return subprocess.Popen(
        [sys.executable, "-m", "beamfx.cli", *map(str, args)],
        cwd=cwd,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def history(folder):
    return np.genfromtxt(folder / "probes.csv", delimiter=",", names=True)


@pytest.fixture(scope="module")
def whole(tmp_path_factory):
    """The uninterrupted run: its folder."""
    root = tmp_path_factory.mktemp("whole")
    (root / "spin.toml").write_text(SPIN)
    run = beamfx("run", "spin.toml", "--out", "out", cwd=root)
    _, err = run.communicate(timeout=600)
    assert run.returncode == 0, err
    rot = history(root / "out")["tip_rot_z"]
    assert rot[-1] > 3 * np.pi  # the tip turned past 2π: whole turns are tracked
    return root / "out"


def interrupt(root, rows, signum):
    """Start the run and send ``signum`` once probes.csv has ``rows`` lines."""
    run = beamfx("run", "spin.toml", "--out", "out", cwd=root)
    csv = root / "out" / "probes.csv"
    deadline = time.monotonic() + 600
    while time.monotonic() < deadline and run.poll() is None:
        if csv.exists() and csv.read_text().count("\n") >= rows:
            run.send_signal(signum)
            break
        time.sleep(0.002)
    out, err = run.communicate(timeout=600)
    return run.returncode, out, err


@pytest.mark.parametrize(
    "signum, rows",
    [
        (signal.SIGINT, 200),  # tip past 2π (step 191)
        (signal.SIGTERM, 170),  # past π (step 155)
        (signal.SIGKILL, 165),  # the last checkpoint (step 160) before π
        (signal.SIGKILL, 215),  # the last checkpoint (step 200) past 2π
    ],
    ids=["SIGINT-after-2pi", "SIGTERM-after-pi", "SIGKILL-before-pi", "SIGKILL-after-2pi"],
)
def test_interrupted_and_restarted_run_equals_the_whole_run(whole, tmp_path, signum, rows):
    (tmp_path / "spin.toml").write_text(SPIN)
    code, out, err = interrupt(tmp_path, rows, signum)
    folder = tmp_path / "out"
    if signum == signal.SIGKILL:
        assert code == -signal.SIGKILL
    else:
        name = signal.Signals(signum).name
        assert code == 128 + signum, err
        assert "Traceback" not in err and f"stopped: interrupted by {name}" in err
        results = json.loads((folder / "results.json").read_text())
        assert results["status"] == "stopped" and results["reason"] == f"interrupted by {name}"
        assert results["time_steps"] < 240
    run = beamfx("run", "spin.toml", "--out", "out", "--restart", cwd=tmp_path)
    out, err = run.communicate(timeout=600)
    assert run.returncode == 0, err
    if signum == signal.SIGKILL:
        assert "stale lock" in out
    a, b = history(whole), history(folder)
    assert len(a) == len(b) == 241
    for name in a.dtype.names:
        scale = max(1.0, np.max(np.abs(a[name])))
        np.testing.assert_allclose(b[name], a[name], rtol=0, atol=1e-12 * scale, err_msg=name)
    results = json.loads((folder / "results.json").read_text())
    assert results["status"] == "converged" and results["restarted_from"] > 0
    end = json.loads((whole / "results.json").read_text())["probes"]["tip"]
    assert results["probes"]["tip"]["rotation_vector_unwrapped"] == pytest.approx(
        end["rotation_vector_unwrapped"], abs=1e-12
    )
    # the frames of an uninterrupted run (step 0 and every default-th of the 240): the frame
    # written where the interrupted run stopped is dropped on the restart if off that grid
    frames = (folder / "deformed.pvd").read_text().count("<DataSet")
    every = default_every("transient", 240)
    assert frames == (whole / "deformed.pvd").read_text().count("<DataSet") == 240 // every + 1


@pytest.fixture
def stopped(whole, tmp_path):
    """A folder with the checkpoints of a run to t = 1.2 (a copy of the whole run's)."""
    import shutil

    shutil.copytree(whole, tmp_path / "out")
    (tmp_path / "spin.toml").write_text(SPIN)
    return tmp_path


def restart(folder, capsys, scene="spin.toml"):
    """``beamfx run --restart`` in-process in ``folder``: (exit status, stderr)."""
    cwd = os.getcwd()
    os.chdir(folder)
    try:
        code = main(["run", scene, "--out", "out", "--restart"])
    finally:
        os.chdir(cwd)
    return code, capsys.readouterr().err


def test_restart_from_another_scene_is_refused_naming_the_differences(stopped, capsys):
    """Refused before anything runs, and the folder is left as it was, results included."""
    before = (stopped / "out" / "probes.csv").read_text()
    results = (stopped / "out" / "results.json").read_text()
    scene = SPIN.replace("EA = 2.8e7", "EA = 2.8e5").replace("dt = 0.005", "dt = 0.004")
    (stopped / "other.toml").write_text(scene.replace("t_end = 1.2", "t_end = 2.0"))
    code, err = restart(stopped, capsys, "other.toml")
    assert code == 2
    assert "the checkpoint is for another scene" in err
    assert "beams[0].section.EA: 28000000.0 in the checkpoint, 280000.0 in the scene" in err
    assert "analysis.dt: 0.005 in the checkpoint, 0.004 in the scene" in err
    assert "t_end" not in err  # a restart may go on to a later end time
    assert (stopped / "out" / "probes.csv").read_text() == before
    assert (stopped / "out" / "results.json").read_text() == results


def _evil_checkpoint(path, marker):
    """A checkpoint whose state is an object array: a pickle that would create ``marker``."""

    class Evil:
        def __reduce__(self):
            return (os.system, (f"touch {marker}",))

    with np.load(path, allow_pickle=False) as data:
        arrays = {k: data[k] for k in data.files}
    arrays["q_n"] = np.array([Evil()], dtype=object)
    with open(path, "wb") as f:
        np.savez(f, **arrays)


@pytest.mark.parametrize("damage", ["pickle", "truncated", "altered", "header"])
def test_a_damaged_checkpoint_is_refused_and_nothing_runs(stopped, capsys, damage):
    path = stopped / "out" / "checkpoint_1ranks_0.npz"
    marker = stopped / "pwned"
    results = (stopped / "out" / "results.json").read_text()
    if damage == "pickle":
        _evil_checkpoint(path, marker)
        expected = "pickles are refused"
    elif damage == "truncated":
        path.write_bytes(path.read_bytes()[: path.stat().st_size // 2])
        expected = "not a readable checkpoint"
    elif damage == "altered":
        with np.load(path) as data:
            arrays = {k: data[k] for k in data.files}
        arrays["v_n"][3] += 1.0
        np.savez(path, **arrays)
        expected = "array 'v_n' was altered"
    else:
        with np.load(path) as data:
            arrays = {k: data[k] for k in data.files}
        header = json.loads(arrays["header"].tobytes())
        header["step"] = "12; rm -rf /"
        arrays["header"] = np.frombuffer(json.dumps(header).encode(), np.uint8)
        np.savez(path, **arrays)
        expected = "step: expected an integer"
    code, err = restart(stopped, capsys)
    assert code == 2 and expected in err and "Traceback" not in err
    assert "out/checkpoint_1ranks_0.npz" in err  # the file named
    assert not marker.exists()
    assert (stopped / "out" / "results.json").read_text() == results  # left as it was


def test_a_checkpoint_of_another_mesh_is_refused(stopped, capsys):
    """Same scene, but the header says another mesh (e.g. a gmsh file changed since)."""
    from beamfx.io.checkpoint import read_checkpoint, write_checkpoint

    path = stopped / "out" / "checkpoint_1ranks_0.npz"
    header, arrays = read_checkpoint(path)
    header["mesh"]["elements"] = 5
    write_checkpoint(path, {k: v for k, v in header.items() if k != "arrays"}, arrays)
    code, err = restart(stopped, capsys)
    assert code == 2
    assert "the checkpoint is for another mesh: mesh elements: 5 in the checkpoint, 4 now" in err


def test_a_busy_output_folder_is_refused_naming_the_process(tmp_path, capsys):
    (tmp_path / "spin.toml").write_text(SPIN.replace("t_end = 1.2", "t_end = 100.0"))
    first = beamfx("run", "spin.toml", "--out", "out", cwd=tmp_path)
    try:
        lock = tmp_path / "out" / ".beamfx.lock"
        deadline = time.monotonic() + 300
        while not (lock.exists() and lock.read_text()) and time.monotonic() < deadline:
            time.sleep(0.01)
        cwd = os.getcwd()
        os.chdir(tmp_path)
        try:
            code = main(["run", "spin.toml", "--out", "out"])
        finally:
            os.chdir(cwd)
        err = capsys.readouterr().err
        assert code == 2
        assert f"in use by another beamfx run (pid {first.pid} on " in err
        assert first.poll() is None  # the first run goes on
    finally:
        first.send_signal(signal.SIGTERM)
        _, err = first.communicate(timeout=120)
    assert first.returncode == 143, err
    assert not lock.exists()  # released by the stopped run


def test_a_fresh_run_removes_the_files_of_an_earlier_run(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    stale = ["deformed_0999.vtu", "surface_0003_1.vtu", "deformed_0007.pvtu", "probes.jsonl"]
    stale += ["checkpoint_2ranks_1.npz", "results.json", "mode_03.png"]
    for name in [*stale, "notes.txt", "deformed_final.vtu"]:
        (out / name).write_text("an earlier run")
    rewritten = out / "deformed_0001.vtu"  # a frame of the new run too: overwritten in place
    rewritten.write_bytes(b"an earlier, longer frame " * 4000)
    inode = rewritten.stat().st_ino
    linked = out / "deformed_0002.vtu"  # also a frame, but linked from elsewhere: replaced
    linked.write_text("an earlier run, kept elsewhere")
    os.link(linked, tmp_path / "kept.vtu")
    (tmp_path / "spin.toml").write_text(SPIN.replace("t_end = 1.2", "t_end = 0.01"))
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        assert main(["run", "spin.toml", "--out", "out"]) == 0
    finally:
        os.chdir(cwd)
    left = {p.name for p in out.iterdir()}
    assert not left & (set(stale) - {"results.json", "probes.jsonl"})  # written anew
    assert {"notes.txt", "deformed_final.vtu"} <= left  # not names beamfx writes
    # the frame files are kept for this run to overwrite in place; those it did not write
    # again (the three numbered 0999, 0003 and 0007 here) are removed at its end (checked above)
    assert "removed 5 file(s) of an earlier run; its 4 frame file(s)" in capsys.readouterr().out
    assert (tmp_path / "kept.vtu").read_text() == "an earlier run, kept elsewhere"
    assert linked.read_bytes().endswith(b"</VTKFile>\n")
    frame = rewritten.read_bytes()
    assert rewritten.stat().st_ino == inode and frame.endswith(b"</VTKFile>\n")  # cut to length
    assert b"earlier" not in frame
    assert json.loads((out / "results.json").read_text())["status"] == "converged"
    assert Path(out / "probes.csv").read_text().count("\n") == 4  # header, t = 0 and 2 steps


STATIC = CANTILEVER.replace("KIN", "finite").replace("CONDENSE", "auto")  # 2 load steps


def test_restart_of_a_static_run_is_a_fresh_run_and_says_so(tmp_path, capsys):
    """--restart of an analysis without checkpoints: the log says so, and the earlier run's
    files go as on any fresh run (its frames past this run's last were left before)."""
    scene = tmp_path / "static.toml"
    scene.write_text(STATIC.replace("steps = 2", "steps = 4"))
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        assert main(["run", "static.toml", "--out", "out"]) == 0
        scene.write_text(STATIC)
        code = main(["run", "static.toml", "--out", "out", "--restart"])
    finally:
        os.chdir(cwd)
    assert code == 0
    out = capsys.readouterr()
    assert "has no checkpoint to go on from: a fresh run" in out.out + out.err
    assert not (tmp_path / "out" / "deformed_0004.vtu").exists()
