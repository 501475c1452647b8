"""Rules for what a scene may make beamfx write, and for a checkpoint file, without a solve:
output folders (no system folders, a scene's own folder or the current one), the output
folder's lock, the ``[solver]`` allow-list, checkpoint files and scene fingerprints."""

import json
import os
import socket
import subprocess
import sys

import numpy as np
import pytest

from beamfx.io.checkpoint import CheckpointError, read_checkpoint, write_checkpoint
from beamfx.io.fingerprint import scene_differences, scene_fingerprint
from beamfx.io.folder import LOCK, FolderError, acquire, check_output_dir, release
from beamfx.scene import SceneError
from beamfx.scene.load import parse_scene
from beamfx.solvers.options import option_problems

BASE = {
    "beams": [
        {
            "name": "b",
            "curve": {"shape": "line", "start": [0, 0, 0], "end": [1, 0, 0]},
            "section": {
                "type": "general",
                **dict.fromkeys(("EA", "GA_y", "GA_z", "GJ", "EI_y", "EI_z"), 1.0),
            },
        }
    ],
    "supports": [{"at": "b:start", "fix": "all"}],
}


@pytest.mark.parametrize("folder", ["/etc", "/etc/beamfx", "/usr/lib/x", "/proc/1", "/", "/dev"])
def test_system_folders_are_refused_even_from_the_command_line(folder):
    with pytest.raises(FolderError, match="system folder"):
        check_output_dir(folder)


def test_a_link_into_a_system_folder_is_refused(tmp_path):
    (tmp_path / "results").symlink_to("/etc")
    with pytest.raises(FolderError, match="system folder /etc"):
        check_output_dir(tmp_path / "results")


def test_a_scene_writes_under_its_folder_or_the_current_one(tmp_path, monkeypatch):
    scene = tmp_path / "scenes" / "a.toml"
    scene.parent.mkdir()
    scene.write_text("")
    here = tmp_path / "work"
    here.mkdir()
    monkeypatch.chdir(here)
    check_output_dir("results", scene)  # under the current folder
    check_output_dir(tmp_path / "scenes" / "out", scene)  # under the scene's folder
    with pytest.raises(FolderError, match=r"output\.dir: '\.\./elsewhere'.*outside.*--out"):
        check_output_dir("../elsewhere", scene)
    check_output_dir("../elsewhere")  # named on the command line: allowed
    for itself in (".", "", str(tmp_path / "scenes"), "../scenes/."):  # a folder of its own
        with pytest.raises(FolderError, match="folder itself: give a folder of its own"):
            check_output_dir(itself, scene)
    with pytest.raises(FolderError, match="'~' is not your home folder"):  # nor expanded
        check_output_dir("~/results", scene)
    check_output_dir(".")  # on the command line: the user's own choice


def test_the_cli_refuses_a_scene_that_writes_into_etc(tmp_path, capsys, monkeypatch):
    from beamfx.cli import main

    lines = [
        "[[beams]]",
        'name = "b"',
        'curve = { shape = "line", start = [0, 0, 0], end = [1, 0, 0] }',
        'section = { type = "general", EA = 1, GA_y = 1, GA_z = 1, GJ = 1, EI_y = 1, EI_z = 1 }',
        "[[supports]]",
        'at = "b:start"',
        'fix = "all"',
        "[output]",
        'dir = "/etc/beamfx"',
    ]
    (tmp_path / "a.toml").write_text("\n".join(lines) + "\n")
    monkeypatch.chdir(tmp_path)
    for command in (["check", "a.toml"], ["run", "a.toml"]):
        assert main(command) == 2
        assert "a.toml: output.dir: '/etc/beamfx' is in the system folder /etc" in (
            capsys.readouterr().err
        )
    assert not os.path.exists("/etc/beamfx")


def test_the_lock_names_its_process_and_a_dead_one_is_stale(tmp_path):
    path = acquire(tmp_path, "a.toml")
    owner = json.loads(path.read_text())
    assert owner["pid"] == os.getpid() and owner["host"] == socket.gethostname()
    with pytest.raises(FolderError, match=rf"in use by another beamfx run \(pid {os.getpid()}"):
        acquire(tmp_path, "b.toml")
    release(path)
    assert not path.exists()
    child = [sys.executable, "-c", "import os; print(os.getpid())"]
    dead = subprocess.run(child, text=True, capture_output=True, check=True).stdout
    (tmp_path / LOCK).write_text(json.dumps({"pid": int(dead), "host": socket.gethostname()}))
    notes = []
    acquire(tmp_path, "c.toml", notes.append)
    assert "stale lock" in notes[0] and json.loads(path.read_text())["scene"] == "c.toml"
    release(path)


@pytest.mark.parametrize(
    "options, message",
    [
        ({"snes_monitor": "ascii:/tmp/x"}, "solver.snes_monitor: prints to the terminal only"),
        ({"log_view": ":/tmp/log.txt"}, "solver.log_view: not allowed from a scene"),
        ({"options_file": "x"}, "solver.options_file: not allowed"),
        ({"malloc_dump": ""}, "solver.malloc_dump: not allowed"),
        ({"ksp_view": ""}, "solver.ksp_view: not allowed"),
        ({"ksp_type": "ascii:/etc/x"}, "solver.ksp_type: 'ascii:/etc/x': expected a number"),
        ({"snes_rtol": float("nan")}, "solver.snes_rtol: nan is not a finite number"),
    ],
)
def test_solver_options_outside_the_allow_list_are_refused(options, message):
    with pytest.raises(SceneError, match="allowed|expected|finite|terminal") as e:
        parse_scene(BASE | {"solver": options}, "x.toml")
    assert f"x.toml: {message}" in str(e.value)


def test_solver_options_in_the_allow_list_pass():
    ok = {"snes_rtol": 1e-8, "ksp_type": "gmres", "pc_type": "lu", "mat_mumps_icntl_14": 50}
    ok |= {"snes_monitor": "", "eps_tol": 1e-9, "pc_factor_mat_solver_type": "superlu_dist"}
    assert list(option_problems(ok)) == []
    assert parse_scene(BASE | {"solver": ok}, "x.toml").solver_options == ok


def test_a_checkpoint_round_trip_and_its_refusals(tmp_path):
    path = tmp_path / "c.npz"
    header = {"t": 0.5, "step": 3, "size": 0.1, "controller": {}, "balance": {}, "probes": {}}
    header |= {"scene": {}, "mesh": {}}
    write_checkpoint(path, header, {"q_n": np.arange(4.0)})
    back, arrays = read_checkpoint(path)
    assert back["t"] == 0.5 and np.array_equal(arrays["q_n"], np.arange(4.0))
    assert not list(tmp_path.glob(".*tmp*"))  # written atomically
    np.savez(path, q_n=np.arange(4.0))
    with pytest.raises(CheckpointError, match="no header"):
        read_checkpoint(path)
    path.write_bytes(b"not a zip file")
    with pytest.raises(CheckpointError, match="not a readable checkpoint"):
        read_checkpoint(path)
    with pytest.raises(ValueError):  # NaN cannot be written (JSON without NaN)
        write_checkpoint(path, header | {"t": float("nan")}, {})


def test_scene_fingerprints_name_each_difference():
    a = parse_scene(BASE, "a.toml")
    changed = json.loads(json.dumps(BASE))
    changed["beams"][0]["section"]["EA"] = 2.0
    changed["beams"][0]["elements"] = 7
    b = parse_scene(changed, "b.toml")

    def fingerprint(s):
        return scene_fingerprint(s.model, s.analysis, s.settings, s.probes)

    assert scene_differences(fingerprint(a), fingerprint(a)) == []
    assert scene_differences(fingerprint(a), fingerprint(b)) == [
        "beams[0].elements: 8 in the checkpoint, 7 in the scene",
        "beams[0].section.EA: 1.0 in the checkpoint, 2.0 in the scene",
    ]


def test_links_planted_in_the_output_folder_are_never_written_through(tmp_path):
    """A folder from someone else with links named like beamfx's files (a frame, the probes,
    the results) pointing out of it: the run replaces the links by its files and the targets
    keep their content, on a fresh run and when a frame is written over in place."""
    from beamfx.io.folder import clear_earlier_run
    from beamfx.io.vtkfiles import write_in_place

    outside = tmp_path / "outside.txt"
    outside.write_text("keep me")
    out = tmp_path / "out"
    out.mkdir()
    for name in ("deformed_0001.vtu", "probes.csv", "results.json"):
        (out / name).symlink_to(outside)
    removed, frames = clear_earlier_run(out, restart=True)
    assert sorted(removed) == ["deformed_0001.vtu", "probes.csv", "results.json"]
    assert not any((out / n).exists() for n in removed) and frames == {}
    (out / "deformed_0002.vtu").symlink_to(outside)  # planted after the clean-up
    write_in_place(out / "deformed_0002.vtu", b"frame")
    assert not (out / "deformed_0002.vtu").is_symlink()
    assert (out / "deformed_0002.vtu").read_bytes() == b"frame"
    assert outside.read_text() == "keep me"
