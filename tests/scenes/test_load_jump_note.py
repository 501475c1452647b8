"""A load applied suddenly at t = 0 in a transient (beamfx.analyses.energy_balance): the
integrator starts at rest with zero acceleration, so the first step's trapezoidal work is
twice the work it did (a constant load); the log says so once before the march and the final
``energy`` carries a ``note``. A load ramped from 0, or a static start, gets neither.

Tolerance: the first step of generalized-α (ρ∞ = 0.9) under a constant tip force from rest
books half its trapezoidal work as "numerical" (measured 0.4991 on this cantilever; the
step's state is nearly linear, the rest is the stiffness change of finite kinematics).
"""

import csv
import json

import pytest

from beamfx.analyses.energy_balance import JUMP_NOTE, sudden_loads
from beamfx.runner import run_scene
from beamfx.scene.load import parse_scene

SCENE = """
[material]
E = 210e9
nu = 0.3
rho = 7850
[[beams]]
name = "b"
curve = { shape = "line", start = [0, 0, 0], end = [1, 0, 0] }
section = { type = "rectangle", h = 0.02, w = 0.02 }
elements = 4
degree = 2
[[supports]]
at = "b:start"
fix = "all"
[[loads]]
at = "b:end"
force = [0, 0, -100]
HISTORY
[analysis]
type = "transient"
t_end = 0.005
dt = 0.001
START
[model]
kinematics = "finite"
"""
RAMP = 'history = "where(t < 0.004, t / 0.004, 1)"'


def _run(scene_file, tmp_path, history="", start=""):
    text = SCENE.replace("HISTORY", history).replace("START", start)
    lines = []
    run = run_scene(scene_file(text), tmp_path / "out", log=lines.append)
    saved = json.loads((tmp_path / "out" / "results.json").read_text())
    with (tmp_path / "out" / "probes.csv").open() as f:
        rows = list(csv.DictReader(f))
    return run, saved, [x for x in lines if "t = 0" in x and x.startswith("note:")], rows


def test_constant_load_is_noted_in_the_log_and_the_energy(scene_file, tmp_path):
    run, saved, notes, rows = _run(scene_file, tmp_path)
    (line,) = notes  # once, before the march
    assert "the point load at 'b:end'" in line and "'numerical' includes" in line
    assert saved["energy"]["note"] == JUMP_NOTE == run["energy"]["note"]
    first = rows[1]  # step 1: half its trapezoidal work is booked as numerical
    share = float(first["numerical"]) / float(first["work_loads"])
    assert share == pytest.approx(0.5, abs=0.01)


@pytest.mark.parametrize("start", ["ramp", "static"])
def test_ramped_or_prestressed_load_has_no_note(scene_file, tmp_path, start):
    history, begin = (RAMP, "") if start == "ramp" else ("", 'start = "static"\nsteps = 2')
    run, saved, notes, rows = _run(scene_file, tmp_path, history, begin)
    assert notes == [] and "note" not in saved["energy"] and "note" not in run["energy"]
    first = rows[1]  # and no such share: a ramp starts with the integrator at rest
    if start == "ramp":
        assert abs(float(first["numerical"])) < 1e-2 * float(first["work_loads"])


def _spec(loads, gravity=""):
    text = SCENE.split("[[loads]]")[0] + loads + gravity
    text += '\n[analysis]\ntype = "transient"\nt_end = 1\ndt = 0.1\n'
    import tomllib

    return parse_scene(tomllib.loads(text)).model


def test_which_loads_jump():
    """Constant and non-zero-at-0 histories, distributed loads and gravity jump; a smooth
    ramp from 0 (its round-off included) does not, nor anything after a static start."""
    spec = _spec(
        """
[[loads]]
at = "b:end"
force = [0, 0, 1]
history = "(1 - cos(pi * t)) / 2"
[[loads]]
at = "b:0.5"
moment = [0, 1, 0]
history = "cos(t)"
[[loads]]
beam = "b"
force_per_length = [0, 1, 0]
"""
    )
    assert sudden_loads(spec, 1.0) == ["the point load at 'b:0.5'", "the distributed load on 'b'"]
    assert sudden_loads(spec, 1.0, start="static") == []
    spec = _spec('[[loads]]\nat = "b:end"\nforce = [0, 0, 1]\nhistory = "t"\n')
    assert sudden_loads(spec, 1.0) == []
    spec = _spec("[[loads]]\ngravity = [0, 0, -9.81]\n")
    assert sudden_loads(spec, 1.0) == ["gravity"]
