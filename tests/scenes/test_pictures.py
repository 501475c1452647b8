"""``beamfx run --png``: pictures of small scenes exist, have their size and show a beam; a
missing or failing renderer leaves the solve and says which pictures were skipped."""

import sys
from importlib.util import find_spec

import numpy as np
import pytest
from scenekit import SHAKEN, SOLID_SCENE

from beamfx.io import pictures
from beamfx.runner import run_scene

# general section (no outline): drawn as its centre line
STATIC = """
[[beams]]
name = "b"
curve = { shape = "line", start = [0, 0, 0], end = [1, 0, 0] }
section = { type = "general", EA = 1e7, GA_y = 1e7, GA_z = 1e7, GJ = 1, EI_y = 1, EI_z = 1 }
elements = 4
[[supports]]
at = "b:start"
fix = "all"
[[loads]]
at = "b:end"
force = [0, 0, 2]
[analysis]
type = "static"
steps = 4
[[probes]]
name = "tip"
at = "b:end"
"""

needs_pyvista = pytest.mark.skipif(find_spec("pyvista") is None, reason="pyvista not installed")


def _quiet(messages):
    return lambda m: messages.append(m)


def _image(path):
    """(height, width, 3) pixels of a PNG or of the frames of a GIF (frames, h, w, 3)."""
    import imageio.v3 as iio

    pixels = iio.imread(path, index=None if path.suffix == ".gif" else 0)
    return np.asarray(pixels)[..., :3]


def _assert_shows_a_beam(path, size=pictures.SIZE):
    assert path.stat().st_size > 5000, path
    rgb = _image(path)
    assert rgb.shape[-3:-1] == (size[1], size[0])
    frame = rgb.reshape(-1, *rgb.shape[-3:])[-1]
    background = np.all(frame == 255, axis=-1)  # white
    coloured = np.ptp(frame.astype(int), axis=-1) > 40  # the viridis beam, not grey or black
    assert 0.002 < 1 - background.mean() < 0.6, path
    assert coloured.mean() > 0.001, path
    assert frame.std() > 5, path


def _scene(scene_file, analysis, keys):
    return scene_file(SHAKEN.replace('"ANALYSIS"', f'"{analysis}"\n{keys}'))


def test_picture_plan_names_one_picture_per_mode_and_the_gif_of_a_transient():
    modal = pictures.picture_plan({"analysis": "modal", "frequencies_hz": [1.5, 7.0]})
    assert [p["file"] for p in modal] == ["mode_01.png", "mode_02.png"]
    assert modal[1]["frames"] == [1] and "7 Hz" in modal[1]["label"]
    buckling = pictures.picture_plan({"analysis": "buckling", "load_factors": [3.25]})
    assert "load factor 3.25" in buckling[0]["label"]
    transient = pictures.picture_plan({"analysis": "transient"}, animate=True)
    assert [p["file"] for p in transient] == ["deformed.png", "animation.gif"]
    assert transient[1]["frames"] == "all"
    static = pictures.picture_plan({"analysis": "static"}, animate=True)  # no GIF of a static
    assert [(p["file"], p["frames"]) for p in static] == [("deformed.png", [-1])]


@needs_pyvista
@pytest.mark.parametrize(
    "analysis, keys, files",
    [
        ("modal", "modes = 2", ["mode_01.png", "mode_02.png"]),
        ("transient", "t_end = 0.1\ndt = 0.01\noutput_every = 2", ["deformed.png"]),
    ],
)
def test_pictures_of_modes_and_of_a_transient(tmp_path, analysis, keys, files, scene_file):
    messages = []
    out = tmp_path / "out"
    results = run_scene(_scene(scene_file, analysis, keys), out, log=_quiet(messages), png=True)
    assert results["pictures"] == {"written": files, "skipped": {}}
    assert (out / "undeformed.vtu").is_file()
    for name in files:
        _assert_shows_a_beam(out / name)
        assert any(str(out / name) in m for m in messages)


@needs_pyvista
@pytest.mark.skipif(find_spec("imageio") is None, reason="imageio not installed")
def test_animation_of_a_transient(tmp_path, scene_file):
    out = tmp_path / "out"
    keys = "t_end = 0.1\ndt = 0.01\noutput_every = 2"
    results = run_scene(
        _scene(scene_file, "transient", keys), out, log=lambda m: None, animate=True
    )
    assert results["pictures"]["written"] == ["deformed.png", "animation.gif"]
    frames = _image(out / "animation.gif")
    assert len(frames) >= 6  # t = 0, 0.02, ..., 0.1
    assert not np.array_equal(frames[1], frames[-1])  # the beam moves
    _assert_shows_a_beam(out / "animation.gif", pictures.GIF_SIZE)


@needs_pyvista
def test_a_beam_without_section_outline_is_drawn_as_its_centre_line(tmp_path):
    (tmp_path / "s.toml").write_text(STATIC)
    out = tmp_path / "out"
    results = run_scene(tmp_path / "s.toml", out, log=lambda m: None, png=True)
    assert results["pictures"]["written"] == ["deformed.png"]
    assert not (out / "undeformed.vtu").exists()
    _assert_shows_a_beam(out / "deformed.png")


def test_without_pyvista_the_run_says_which_pictures_it_skipped(tmp_path, monkeypatch, scene_file):
    monkeypatch.setitem(sys.modules, "pyvista", None)  # import pyvista -> ImportError
    messages = []
    out = tmp_path / "out"
    results = run_scene(
        _scene(scene_file, "modal", "modes = 2"), out, log=_quiet(messages), png=True
    )
    assert len(results["frequencies_hz"]) == 2  # the solve ran
    assert (out / "results.json").is_file()
    skipped = results["pictures"]["skipped"]
    assert set(skipped) == {"mode_01.png", "mode_02.png"}
    assert "pyvista is not installed" in skipped["mode_01.png"]
    assert any("pictures skipped (mode_01.png, mode_02.png)" in m for m in messages)
    assert not list(out.glob("*.png"))


def test_a_crashing_renderer_does_not_stop_the_run(tmp_path, monkeypatch):
    monkeypatch.setattr(pictures, "CHILD", "import os; os.abort()")
    messages = []
    (tmp_path / "s.toml").write_text(STATIC)
    results = run_scene(tmp_path / "s.toml", tmp_path / "out", log=_quiet(messages), png=True)
    reason = results["pictures"]["skipped"]["deformed.png"]
    assert "the renderer failed (exit status" in reason
    assert any("pictures skipped (deformed.png)" in m for m in messages)


@needs_pyvista
def test_picture_of_the_solid_and_the_beam(tmp_path):
    """``beamfx solid --png``: the solid coloured by |u| and the beam's centre line in red."""
    from beamfx.solid.picture import FILE
    from beamfx.solid.run import run_solid

    line = '{ shape = "line", start = [0, 0, 0], end = [1, 0, 0] }'
    section = '{ type = "rectangle", h = 0.2, w = 0.1 }'
    scene = SOLID_SCENE.format(curve=line, section=section)
    (tmp_path / "scene.toml").write_text(scene.replace("[0, 0, 1e4]", "[0, 0, 1e8]"))
    out = tmp_path / "out"
    results = run_solid(tmp_path / "scene.toml", out, log=lambda *a: None, png=True)
    assert results["pictures"]["written"] == [FILE]
    _assert_shows_a_beam(out / FILE)
    r, g, b = np.moveaxis(_image(out / FILE).astype(int), -1, 0)
    assert ((r > 60) & (r > 2 * g) & (r > 2 * b)).mean() > 2e-4  # the beam line: red hue
