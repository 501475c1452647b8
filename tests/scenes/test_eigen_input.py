"""Bad input of the eigen analyses refused before any solve, and a buckling run that finds no
load factor says so (a blind tester's findings: `load_factors: []` and silence, a sweep
aborted by one member, ``modes`` passing the check and failing in SLEPc)."""

import json
from pathlib import Path

import numpy as np
from mpi4py import MPI
from scenekit import MODAL_ROD

from beamfx.cli import main

COLUMN = """
[material]
E = 210e9

[[beams]]
name = "column"
curve = {{ shape = "line", start = [0, 0, 0], end = [0, 0, 2] }}
section = {{ type = "tube", d = 0.06, d_inner = 0.05 }}
elements = {elements}
degree = 3

[[supports]]
at = "column:start"
fix = "all"
{loads}
[analysis]
type = "buckling"
modes = {modes}
"""


def column(force=None, modes=4, elements=8):
    loads = "" if force is None else f'\n[[loads]]\nat = "column:end"\nforce = {force}\n'
    return COLUMN.format(loads=loads, modes=modes, elements=elements)


def _write(tmp_path, text):
    folder = Path(MPI.COMM_WORLD.bcast(str(tmp_path)))
    if MPI.COMM_WORLD.rank == 0:
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "scene.toml").write_text(text)
    MPI.COMM_WORLD.barrier()
    return folder


def run(tmp_path, text, capsys, command="run"):
    """(exit status, results.json or None, stdout, stderr) of ``beamfx run`` (or check)."""
    folder = _write(tmp_path, text)
    args = [command, str(folder / "scene.toml")]
    code = main(args + (["--out", str(folder / "out")] if command == "run" else []))
    out = folder / "out" / "results.json"
    captured = capsys.readouterr()
    return code, json.loads(out.read_text()) if out.exists() else None, captured.out, captured.err


def test_buckling_without_loads_is_bad_input_for_check_and_run(tmp_path, capsys):
    """No [[loads]] (or only zero ones): exit 2 before any solve, naming the file and key
    (it exited 0 with load factors inf or [])."""
    for text in (column(), column("[0, 0, 0]")):
        for command in ("check", "run"):
            code, results, _, err = run(tmp_path, text, capsys, command)
            assert code == 2 and results is None
            if MPI.COMM_WORLD.rank == 0:
                assert "scene.toml: analysis.type: a buckling analysis needs loads" in err


def test_a_column_in_tension_warns_and_notes_the_reversed_loads(tmp_path, capsys):
    """Tension: no positive load factor. Exit 0 (the analysis did what was asked: the answer
    is "none"), a warning in the log and a note in results.json that names the reversed
    loads' factors: minus those of the same column in compression (to the note's 6 digits),
    which has no note."""
    code, pushed, out, _ = run(tmp_path, column("[0, 0, -1]"), capsys)
    assert code == 0 and len(pushed["load_factors"]) == 4 and pushed["note"] is None
    assert "warning" not in out
    code, results, out, _ = run(tmp_path, column("[0, 0, 1]"), capsys)
    assert code == 0 and results["status"] == "converged"
    assert results["load_factors"] == []
    note = results["note"]
    assert note.startswith("no buckling load factor found of sign 'positive'")
    assert "put no member in compression?" in note
    listed = note.split("load factor(s) ")[1].split(" (sign")[0]
    reversed_ = [float(x) for x in listed.split(", ")]
    assert np.allclose(reversed_, -np.array(pushed["load_factors"]), rtol=1e-5, atol=0)
    if MPI.COMM_WORLD.rank == 0:
        assert "warning: no buckling load factor found" in out


def test_more_buckling_modes_than_free_dofs_is_bad_input(tmp_path, capsys):
    """2 elements x P3: 7 nodes, 6 free x 6 dofs = 36 roots at most; 37 is refused on reading."""
    code, _, _, err = run(tmp_path, column("[0, 0, -1]", modes=37, elements=2), capsys, "check")
    assert code == 2
    if MPI.COMM_WORLD.rank == 0:
        assert "analysis.modes = 37: more than a buckling analysis can find" in err
        assert "7 nodes x 6 dofs − 6 fixed by the supports" in err


def test_fewer_buckling_factors_than_asked_are_returned_with_a_note(tmp_path, capsys):
    """36 modes asked of a column with 36 finite roots of both signs: those of the positive
    sign come out, and the note says how many of how many (it failed: "175 of 342
    eigenpairs")."""
    code, results, _, _ = run(tmp_path, column("[0, 0, -1]", modes=36, elements=2), capsys)
    assert code == 0
    found = len(results["load_factors"])
    assert 0 < found < 36
    assert results["note"].startswith(f"found {found} of the 36 buckling load factors asked")


SWEEP = (
    MODAL_ROD.replace("elements = 2", "elements = 8")
    + """
[[sweep]]
key = ["beams.b.elements", "beams.b.degree"]
values = [[8, 2], [1, 1]]
"""
)


def test_a_sweep_member_with_too_many_modes_is_named_before_any_solve(tmp_path, capsys):
    """Member 1 (1 x P1: 14 unknowns, 6 free with mass) cannot have 30 modes: `check` and
    `run` refuse the sweep, naming the member, and nothing is solved (check said OK, run
    stopped at that member with exit 2)."""
    for command in ("check", "run"):
        code, _, _, err = run(tmp_path, SWEEP, capsys, command)
        assert code == 2
        if MPI.COMM_WORLD.rank == 0:
            assert "(sweep member 1: beams.b.elements = 1, beams.b.degree = 1)" in err
            assert "analysis.modes = 30" in err and "[1, 6]" in err
    assert not (Path(MPI.COMM_WORLD.bcast(str(tmp_path))) / "out").exists()


CANTILEVER = """
[material]
E = 210e9
rho = 7850

[[beams]]
name = "b"
curve = { shape = "line", start = [0, 0, 0], end = [2, 0, 0] }
section = { type = "rectangle", w = 0.05, h = 0.1 }
elements = 8
degree = 3

[[supports]]
at = "b:start"
fix = "all"

[analysis]
type = "modal"
"""


def test_target_hz_gives_the_modes_nearest_in_hz(tmp_path, capsys):
    """At 100 Hz the four nearest in ω² are 65.2, 129.2, 20.9 and 10.4 Hz; in Hz 181.8 Hz
    (82 Hz off) is nearer than 10.4 Hz (90 Hz off) and takes its place. Checked against the
    40 lowest modes of the same model, nearest in Hz first."""
    code, lowest, _, _ = run(tmp_path / "all", CANTILEVER + "modes = 40\n", capsys)
    assert code == 0
    f = np.array(lowest["frequencies_hz"])
    expected = f[np.argsort(np.abs(f - 100.0), kind="stable")[:4]]
    assert f.max() > 200 and 181 < expected[-1] < 182  # the case in point
    code, near, _, _ = run(tmp_path / "near", CANTILEVER + "modes = 4\ntarget_hz = 100\n", capsys)
    assert code == 0
    assert np.allclose(near["frequencies_hz"], expected, rtol=1e-8, atol=0)


def test_every_member_of_a_large_sweep_is_checked_before_any_solve(tmp_path, capsys):
    """72 members (beyond the 64 validated in full on reading, which then checks each value
    once): elements = 1 with modes = 30 (member 9) is a combination the reading does not
    build; `check` and `run` build every member and refuse it, naming it."""
    from beamfx.scene import load_scene_or_sweep

    text = SWEEP.replace("degree = 2", "degree = 1").replace("modes = 30", "modes = 4")
    text = text[: text.index("[[sweep]]")] + (
        '[[sweep]]\nkey = "beams.b.elements"\nvalues = [8, 1, 2, 3, 4, 5, 6, 7, 9]\n\n'
        '[[sweep]]\nkey = "analysis.modes"\nvalues = [4, 30, 5, 6, 7, 8, 9, 10]\n'
    )
    folder = _write(tmp_path, text)
    sweep = load_scene_or_sweep(folder / "scene.toml")  # reading alone passes
    assert len(sweep.members) == 72 and "scene" not in sweep.members[9].__dict__
    for command in ("check", "run"):
        code, _, _, err = run(tmp_path, text, capsys, command)
        assert code == 2
        if MPI.COMM_WORLD.rank == 0:
            assert "(sweep member 9: beams.b.elements = 1, analysis.modes = 30)" in err
    assert not (folder / "out").exists()
