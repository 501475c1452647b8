"""Every bench case times the model a user's scene gets (issue 15): its scenes go through the
scene builder's :func:`beamfx.scene.load.choose_model`, the one ``beamfx run`` uses, unless the
case says why not (``own_model``). No solves: the scenes are only built."""

import tomllib

import pytest

from beamfx.bench import all_cases
from beamfx.bench.scenes import setting_scene
from beamfx.scene import load


@pytest.fixture
def chosen(monkeypatch):
    """What every call of the scene builder's choice returned: {id(model): (model, trim,
    condense)}."""
    calls = {}
    original = load.choose_model

    def spy(*args, **kwargs):
        out = original(*args, **kwargs)
        calls[id(out[0])] = out
        return out

    monkeypatch.setattr(load, "choose_model", spy)
    return calls


def bench_scenes(case, setting):
    """The scenes the bench runs for one setting of ``case``."""
    if hasattr(case, "scenes"):  # a case of several scenes
        return case.scenes(*setting[:2])
    return [setting_scene(case, setting)]


CASES = all_cases()


@pytest.mark.parametrize("case_id", sorted(CASES))
def test_every_bench_scene_gets_the_model_beamfx_run_picks(case_id, chosen):
    case = CASES[case_id]
    if case.own_model:  # an opt-out says why, in words the report prints
        assert len(case.own_model.split()) >= 5
        return
    for setting in case.settings:
        for scene in bench_scenes(case, setting):
            assert id(scene.model) in chosen, f"{case_id} {setting}: model not chosen"
            model, trim, condense = chosen[id(scene.model)]
            assert scene.model is model
            assert (scene.trimming, scene.condense) == (trim, condense)


ELASTICA = """
[[beams]]
name = "b"
curve = {{ shape = "line", start = [0, 0, 0], end = [1, 0, 0] }}
section = {{ type = "general", EA = 1e7, GA_y = 1e7, GA_z = 1e7, GJ = 1, EI_y = 1, EI_z = 1 }}
elements = 4
degree = 3
[[supports]]
at = "b:start"
fix = "all"
[[loads]]
at = "b:end"
force = [0, 0, {k}]
[analysis]
type = "static"
steps = 10
[[probes]]
name = "tip"
at = "b:end"
"""


@pytest.mark.parametrize("k", [1, 5, 10])
def test_the_elastica_case_gets_the_scene_files_model(k):
    """The Mattiasson case and the same cantilever written as a scene file: the same model."""
    bench = setting_scene(CASES[f"mattiasson_k{k}"], (4, 3))
    user = load.parse_scene(tomllib.loads(ELASTICA.format(k=float(k))), "elastica.toml")
    assert user.model.kinematics.plane == "xz" and user.condense  # planar condensed
    assert bench.model == user.model
    assert (bench.trimming, bench.condense) == (user.trimming, user.condense)


def test_the_report_names_each_cases_model_and_why_a_case_keeps_its_own():
    from beamfx.bench.model_choice import MOVED, case_model_line, model_cell

    rows = [{"formulation": "planar condensed"}, {"formulation": "planar condensed"}]
    assert model_cell({"own_model": ""}, rows[0]) == "planar condensed"
    assert model_cell({"own_model": "it compares two models"}, rows[0]) == "own"
    line = case_model_line({"own_model": "it compares two models", "rows": rows})
    assert "it compares two models" in line
    assert case_model_line({"own_model": "", "rows": rows}).endswith("(planar condensed).")
    named = {name for cases, *_ in MOVED for name in cases.split(", ")}
    assert named <= set(CASES)  # the intro's table names registered cases only
    assert not any(CASES[name].own_model for name in named)
