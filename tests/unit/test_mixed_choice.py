"""The choice of the formulation (beamfx.analyses.mixed): the ``[model] formulation`` key and
the automatic choice by stiffness ratio, without a solve."""

import json
import tomllib
from dataclasses import replace

import pytest

from beamfx.analyses.mixed import RATIO_LIMIT, choose_formulation, stiffness_ratio
from beamfx.bench._builders import cantilever, straight
from beamfx.physics import sections
from beamfx.physics.kinematics import Kinematics
from beamfx.runner import default_scene_path
from beamfx.scene import SceneError, parse_scene

RECT = sections.rectangle(210e9, 80e9, 7850.0, 0.02, 0.02, nu=0.3)
BASE = tomllib.loads(default_scene_path().read_text())


FULL = Kinematics()


def _spec(L, kin=FULL):
    return cantilever(straight(L), RECT, 4, 3, force=(0, 0, 1.0), kinematics=kin)


def test_the_ratio_of_a_rectangle_is_12_slenderness_squared():
    # EA L²/EI = 12 (L/h)² for a square (EA is the largest of EA, GA)
    assert stiffness_ratio(_spec(2.0)) == pytest.approx(12 * (2.0 / 0.02) ** 2, rel=1e-12)


@pytest.mark.parametrize(
    "L, kin, analysis, chosen",
    [
        (2.0, Kinematics(), "modal", "displacement"),  # ratio 1.2e5
        (60.0, Kinematics(), "buckling", "mixed"),  # ratio 1.08e8 ≥ 1e8
        (60.0, Kinematics(), "transient", "displacement"),  # not a mixed analysis
        (2.0, Kinematics(shear=False), "static", "mixed"),  # a penalty model
        (2.0, Kinematics(stretch=False), "linear_static", "mixed"),
        (2.0, Kinematics(shear=False), "rotating", "mixed"),
        (2.0, Kinematics(), "rotating", "displacement"),  # ratio 1.2e5
        (60.0, Kinematics(), "rotating", "mixed"),
        (2.0, Kinematics(shear=False), "arclength", "mixed"),
        (2.0, Kinematics(), "arclength", "displacement"),  # ratio 1.2e5
    ],
)
def test_auto_choice(L, kin, analysis, chosen):
    name, why = choose_formulation(_spec(L, kin), analysis)
    assert name == chosen, why
    if kin.shear and kin.stretch and analysis in ("modal", "buckling", "rotating"):
        assert (stiffness_ratio(_spec(L, kin)) >= RATIO_LIMIT) == (name == "mixed")


def test_a_condensed_model_keeps_its_own_formulation():
    name, why = choose_formulation(_spec(2.0, Kinematics(shear=False)), "static", condensed=True)
    assert name == "displacement" and "condensed" in why


def test_mixed_is_refused_where_the_analysis_does_not_take_it():
    with pytest.raises(ValueError, match="mixed formulation solves the analyses"):
        choose_formulation(_spec(2.0), "transient", "mixed")


def _scene(model=None, analysis=None):
    data = json.loads(json.dumps(BASE))
    if model is not None:
        data.setdefault("model", {}).update(model)
    if analysis is not None:
        data["analysis"] = analysis
    return parse_scene(data, "my.toml")


def test_the_scene_key_and_the_reason():
    stated = _scene({"formulation": "mixed"})
    assert stated.model.formulation == "mixed" and not stated.condense
    assert stated.trimming.formulation == "stated: [model] formulation = 'mixed'"
    auto = _scene()
    assert auto.model.formulation == "displacement" and auto.trimming.formulation
    rigid = _scene({"shear": False, "condense": "none"})
    assert rigid.model.formulation == "mixed" and "shear-rigid" in rigid.trimming.formulation


def test_a_bad_formulation_names_the_key():
    with pytest.raises(SceneError, match="formulation"):
        _scene({"formulation": "hybrid"})
    with pytest.raises(SceneError, match="model.formulation"):
        _scene({"formulation": "mixed"}, {"type": "transient", "t_end": 0.1, "dt": 0.01})


def test_the_spec_default_is_the_displacement_form():
    assert replace(_spec(2.0)).formulation == "displacement"
