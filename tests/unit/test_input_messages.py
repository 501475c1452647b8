"""Messages a blind tester found wrong or missing: each names the file and the key, says what
is allowed, and reads as a sentence."""

import json
import tomllib

import numpy as np
import pytest

from beamfx.runner import default_scene_path
from beamfx.scene import SceneError, parse_scene

BASE = tomllib.loads(default_scene_path().read_text())


def error_of(edit):
    data = json.loads(json.dumps(BASE))
    edit(data)
    with pytest.raises(SceneError) as e:
        parse_scene(data, "my.toml")
    return str(e.value)


def test_a_negative_torsion_constant_says_it_must_be_positive():
    message = error_of(lambda d: d["beams"][0]["section"].update(torsion=-1))
    assert message.startswith("my.toml: beams[0].section.torsion: -1 is not allowed")
    assert "or a number J > 0" in message


def test_a_bad_mass_matrix_reads_as_a_sentence():
    """It read "the matrix its translational block ..."."""
    C = (np.eye(6) * 1e4).tolist()
    M = np.diag([1.0, 1.0, 2.0, 0.1, 0.1, 0.1]).tolist()
    section = {"type": "matrix", "stiffness": C, "mass": M}
    message = error_of(lambda d: d["beams"][0].update(section=section))
    assert (
        "my.toml: beams[0].section.mass: the matrix has a translational block (rows and "
        "columns 1-3) that is not m·I" in message
    )
    section["mass"] = [C, C]
    section["stiffness"] = [C, C]
    section["stations"] = [0, 1]
    M = np.eye(6)
    M[0, 4] = M[4, 0] = 0.5  # symmetric: not skew
    section["mass"] = [np.eye(6).tolist(), M.tolist()]
    message = error_of(lambda d: d["beams"][0].update(section=section))
    assert "mass: station 2 (s/L = 1) has a translation-rotation block" in message


@pytest.mark.parametrize(
    ("scheme", "key", "words"),
    [
        ("hht", "rho_inf", "is a parameter of scheme = 'generalized_alpha' or 'extrapolated'"),
        ("hht", "rho_inf", "(it takes 'hht_alpha')"),
        ("generalized_alpha", "hht_alpha", "not of scheme = 'generalized_alpha'"),
        ("newmark", "rho_inf", "(it has no parameter)"),
    ],
)
def test_a_parameter_of_another_time_scheme_is_refused(scheme, key, words):
    """``rho_inf`` with ``scheme = "hht"`` was silently ignored."""
    analysis = {"type": "transient", "t_end": 1.0, "dt": 0.1, "scheme": scheme, key: 0.1}
    message = error_of(lambda d: d.update(analysis=analysis))
    assert message.startswith(f"my.toml: analysis.{key}: ") and words in message


def test_each_scheme_takes_its_own_parameter():
    for scheme, key in (("hht", "hht_alpha"), ("generalized_alpha", "rho_inf")):
        data = json.loads(json.dumps(BASE))
        data["analysis"] = {"type": "transient", "t_end": 1.0, "dt": 0.1, "scheme": scheme}
        data["analysis"][key] = 0.1
        assert getattr(parse_scene(data, "my.toml").settings, key) == 0.1
