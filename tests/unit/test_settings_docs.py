"""The scene keys of every analysis are the fields of its Settings class: the docs' tables
name exactly those keys, and the reader refuses any other, naming file, key and choices."""

import dataclasses
import re
from pathlib import Path

import pytest

from beamfx.analyses.registry import analyses
from beamfx.scene import SceneError, parse_scene
from beamfx.settings import markdown_table, specs

DOCS = Path(__file__).parents[2] / "docs" / "scenes.md"


def _section_keys(title):
    """Backticked keys in the first column of the tables of a docs section."""
    text = DOCS.read_text()
    start = text.index(f"## `[{title}]`")
    end = text.find("\n## ", start + 1)
    keys = set()
    for line in text[start:end].splitlines():
        if line.startswith("| `"):
            keys |= set(re.findall(r"`([a-z_0-9]+)`", line.split("|")[1]))
    return keys


def test_docs_name_every_analysis_key_and_no_other():
    fields = {"type"} | {s.name for a in analyses().values() for s in specs(a.settings)}
    assert _section_keys("analysis") == fields


def test_docs_name_every_limits_key_and_no_other():
    from beamfx.scene.limits import Limits

    assert _section_keys("limits") == {s.name for s in specs(Limits)}


def test_docs_name_every_output_key_and_no_other():
    from beamfx.io.output import OutputSettings

    assert _section_keys("output") == {s.name for s in specs(OutputSettings)}


@pytest.mark.parametrize(
    "output, where, words",
    [
        ({"every": 0}, "output.every", "> 0"),
        ({"fields": ["u", "Q"]}, "output.fields", "'Q' is not allowed"),
        ({"formats": ["vtk"]}, "output.formats", "'vtu'"),
        ({"every": 2, "times": [1.0]}, "output.times", "not both"),
        ({"colour": "red"}, "output.colour", "unknown key"),
    ],
)
def test_bad_output_keys_are_named(output, where, words):
    with pytest.raises(SceneError) as e:
        parse_scene({**_scene({"type": "static"}), "output": output}, "s.toml")
    assert "s.toml" in str(e.value) and where in str(e.value) and words in str(e.value)


def test_docs_list_the_registered_types():
    text = DOCS.read_text()
    row = next(x for x in text.splitlines() if x.startswith("| `type` |") and "linear_static" in x)
    assert set(re.findall(r'`"([a-z_]+)"`', row.split("|")[2])) == set(analyses())


@pytest.mark.parametrize("name", sorted(analyses()))
def test_settings_are_frozen_and_tabulated(name):
    cls = analyses()[name].settings
    assert dataclasses.fields(cls)
    table = markdown_table(cls)
    for s in specs(cls):
        assert f"`{s.name}`" in table
    if all(s.default is not dataclasses.MISSING for s in specs(cls)):
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(cls(), specs(cls)[0].name, None)


def _scene(analysis):
    return {
        "beams": [
            {
                "name": "b",
                "curve": {"shape": "line", "start": [0, 0, 0], "end": [1, 0, 0]},
                "section": {"type": "circle", "d": 0.1},
            }
        ],
        "material": {"E": 2e11, "nu": 0.3, "rho": 7800},
        "supports": [{"at": "b:start", "fix": "all"}],
        "loads": [{"at": "b:end", "force": [0, 0, -1]}],
        "analysis": analysis,
    }


@pytest.mark.parametrize(
    "analysis, where, words",
    [
        ({"type": "modal", "modes": 0}, "analysis.modes", "> 0"),
        ({"type": "modal", "rotary_inertia": "some"}, "analysis.rotary_inertia", "'polar'"),
        ({"type": "buckling", "about": "x"}, "analysis.about", "'current'"),
        ({"type": "static", "modes": 3}, "analysis.modes", "unknown key"),
        ({"type": "transient", "t_end": 1.0}, "analysis.dt", "missing"),
        ({"type": "transient", "t_end": 1, "dt": 0.1, "rho_inf": 2}, "rho_inf", "in [0, 1]"),
        ({"type": "transient", "t_end": 1, "dt": 0.1, "damping": {"mass": -1}}, "mass", ">= 0"),
        ({"type": "transient", "t_end": 1, "dt": float("nan")}, "analysis.dt", "number"),
        ({"type": "arclength"}, "analysis.type", "target_load_factor"),
        ({"type": "arclength", "displacement_limit": ["uq", 1]}, "displacement_limit", "ux"),
        ({"type": "rotating", "speed_rad_s": 1, "axis": [0, 0, 0]}, "analysis.axis", "zero"),
        ({"type": "rotating", "speed_rad_s": 1, "hub": "c:end"}, "analysis.hub", "no beam"),
        ({"type": "dance"}, "analysis.type", "'static'"),
    ],
)
def test_bad_analysis_keys_are_named(analysis, where, words):
    with pytest.raises(SceneError) as e:
        parse_scene(_scene(analysis), "s.toml")
    assert "s.toml" in str(e.value) and where in str(e.value) and words in str(e.value)


def test_settings_read_from_the_table():
    scene = parse_scene(_scene({"type": "modal", "modes": 3, "target_hz": 2.5}), "s.toml")
    assert (scene.settings.modes, scene.settings.target_hz, scene.settings.prestress) == (
        3,
        2.5,
        True,
    )
    transient = {"type": "transient", "t_end": 2, "dt": 0.01, "damping": {"stiffness": 0.1}}
    s = parse_scene(_scene(transient), "s.toml").settings
    assert s.solver().damping_stiffness == 0.1 and s.solver().dt_min == pytest.approx(1e-5)
    assert s.frames_every == 2 and s.solver().output_every == 2  # 200 steps: about 100 frames
