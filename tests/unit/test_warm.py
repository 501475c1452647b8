"""``beamfx warm``: the scenes it finds, how it shortens them, and that a warmed cache serves
the full run of a scene without compiling anything."""

import json
import os
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import pytest

from beamfx.runner import check_scene
from beamfx.scene import load_scene
from beamfx.warm import DEGREES, grid, scene_sources, shortened

ROOT = Path(__file__).resolve().parents[2]

SHAKEN = """[material]
E = 210e9
nu = 0.3
rho = 7850

[[beams]]
name = "arm"
curve = { shape = "line", start = [0, 0, 0], end = [0, 0, 0.5] }
section = { type = "rectangle", h = 0.002, w = 0.03 }
elements = 4
degree = 1

[[supports]]
at = "arm:start"
fix = "all"
displacement = [0.002, 0, 0]
history = "1 - cos(2*pi*5*t)"

[analysis]
type = "transient"
t_end = 0.02
dt = 0.002

[[probes]]
name = "tip"
at = "arm:end"
"""


def test_grid_scenes_are_valid_and_cover_every_degree(tmp_path):
    sources = grid(tmp_path)
    assert len(sources) == len({s.name for s in sources})
    degrees = set()
    for s in sources:
        scene = check_scene(s.path)
        degrees |= {b.degree for b in scene.model.beams}
    assert degrees == set(DEGREES)
    planes = {check_scene(s.path).model.kinematics.plane for s in sources}
    assert planes == {None, "xz"}


def test_markdown_toml_blocks_become_scene_files_beside_the_geo_blocks(tmp_path):
    doc = tmp_path / "doc.md"
    doc.write_text(
        "text\n```toml\na = 1\n```\n```geo\n// arc.geo\nPoint(1) = {0, 0, 0};\n```\n"
        "```toml-error\nb = 2\n```\n```toml\nc = 3\n```\n"
    )
    out = tmp_path / "out"
    out.mkdir()
    sources = scene_sources([doc], out)
    assert [s.name for s in sources] == ["doc.md:2", "doc.md:12"]
    assert [s.path.read_text() for s in sources] == ["a = 1\n", "c = 3\n"]
    assert (out / "arc.geo").read_text().startswith("// arc.geo")


def test_folders_give_their_toml_files():
    sources = scene_sources([ROOT / "demos" / "scenes"], None)
    names = {s.path.name for s in sources}
    frames = {"dome.toml", "lattice.toml", "tower.toml", "star_dome.toml", "lattice_buckling.toml"}
    assert names == {"prestress_sweep.toml", "spin_up.toml", "channel_cantilever.toml"} | frames


def test_shortened_cuts_only_the_time_loop(tmp_path):
    path = tmp_path / "shaken.toml"
    path.write_text(SHAKEN)
    scene = load_scene(path)
    short = shortened(scene)
    ts, ts0 = short.settings, scene.settings
    assert ts.t_end == pytest.approx(3 * ts0.dt)
    assert replace(ts, t_end=ts0.t_end) == ts0
    assert replace(short, settings=ts0) == scene
    static = load_scene(ROOT / "beamfx" / "scenes" / "bend45.toml")
    assert shortened(static) == static


def _beamfx(cache, *args):
    """``beamfx *args`` in a fresh process with the JIT cache under ``cache``."""
    env = dict(os.environ, XDG_CACHE_HOME=str(cache), PYTHONPATH=str(ROOT))
    cmd = [sys.executable, "-m", "beamfx.cli", *map(str, args)]
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr
    return done


def _kernels(cache):
    """Compiled kernels under ``cache``: the JIT folder, and its sibling of the kernels built
    with BEAMFX_JIT_CFLAGS (the test suite's, see beamfx.solvers.forms)."""
    return len(list(cache.rglob("*.so")))


def test_a_warmed_cache_serves_the_full_run(tmp_path):
    """Warm a transient (cut to 3 of its 10 steps) into an empty cache; the full run then
    compiles nothing: every kernel file it needs is already there."""
    path = tmp_path / "shaken.toml"
    path.write_text(SHAKEN)
    cache = tmp_path / "cache"
    _beamfx(cache, "warm", "--only", path)
    warmed = _kernels(cache)
    assert warmed > 0
    _beamfx(cache, "run", path, "--out", tmp_path / "out")
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    assert (results["time_steps"], results["stopped_by"]) == (10, "t_end")  # the full run
    assert _kernels(cache) == warmed
