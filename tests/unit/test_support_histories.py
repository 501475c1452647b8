"""Supports with one schedule per part (``displacement_history``, ``rotation_history``): the
reader, its refusals, the jump warnings; and the measures of ``beamfx.bench.pai_spin_ramp``."""

import math

import numpy as np
import pytest

from beamfx.analyses.transient_run import motion_warnings
from beamfx.bench import pai_spin_ramp as ps
from beamfx.scene import SceneError, parse_scene


def _data(**support):
    data = ps.scene_data("pai_spin_ramp.toml")
    sup = {"at": "strip:start", "fix": "all", **support}
    data["supports"] = [{k: v for k, v in sup.items() if v is not None}]
    return data


def test_each_part_gets_its_own_history():
    model = parse_scene(ps.scene_data("pai_spin_ramp.toml"), "x.toml").model
    sup = model.supports[0]
    t = np.array([0.5, 3.0])
    assert sup.history is None and sup.timed
    assert np.allclose(sup.history_of(1)(t), np.where(t < 2, 0.0, np.pi * (t - 2) ** 2))
    ramp = np.where(t < 1, (1 - np.cos(np.pi * t)) / 2, 1.0)
    assert np.allclose(sup.history_of(0)(t), np.sin(2 * np.pi * 4.5 * t) * ramp)
    assert [name for name, _ in sup.histories()] == ["displacement_history", "rotation_history"]


def test_one_history_still_scales_both():
    data = _data(displacement=[0, 0, 0.01], rotation=[0, 0, 1], history="t**2")
    sup = parse_scene(data, "x.toml").model.supports[0]
    assert sup.history_of(0) is sup.history_of(1) is sup.history


@pytest.mark.parametrize(
    "support, words",
    [
        ({"rotation_history": "t**2"}, ["rotation_history", "no prescribed rotation"]),
        (
            {"rotation": [0, 0, 1], "displacement_history": "t**2"},
            ["displacement_history", "no prescribed displacement"],
        ),
        (
            {"rotation": [0, 0, 1], "rotation_history": "t**2", "history": "t"},
            ["rotation_history", "not both"],
        ),
        (
            {"displacement": [0, 0, 0.01], "displacement_history": "t**2", "axes": "local"},
            ["displacement_history", "axes = 'global'"],
        ),
        (
            {"rotation": [0, 0, 1], "rotation_history": "omega * t"},
            ["rotation_history", "unknown name 'omega'"],
        ),
        (
            {"displacement": [0, 0, 0.01], "displacement_history": "1 / (t - 5)"},
            ["supports[0].displacement_history", "not finite at t = 5"],
        ),
    ],
)
def test_bad_part_histories_are_refused(support, words):
    with pytest.raises(SceneError) as info:
        parse_scene(_data(**support), "x.toml")
    for word in words:
        assert word in str(info.value)


def test_jumps_are_found_per_part():
    smooth = "where(t < 2, 0, pi*(t - 2)**2)"
    shake = "sin(2*pi*4.5*t) * where(t < 1, (1 - cos(pi*t))/2, 1)"
    fine = _data(displacement=[0, 0, 0.02], rotation=[0, 0, 1])
    fine["supports"][0].update(displacement_history=shake, rotation_history=smooth)
    assert motion_warnings(parse_scene(fine, "x.toml").model, 10.0) == []
    fine["supports"][0]["rotation_history"] = "where(t < 2, 0, 2*pi*(t - 2))"  # spin jumps
    (warning,) = motion_warnings(parse_scene(fine, "x.toml").model, 10.0)
    assert "inside the run" in warning and "rotation_history 'where(t < 2, 0, 2*pi" in warning
    fine["supports"][0]["displacement_history"] = "sin(2*pi*4.5*t)"  # moves at once
    warnings = motion_warnings(parse_scene(fine, "x.toml").model, 10.0)
    assert len(warnings) == 2 and "displacement_history" in warnings[0]
    assert "at t = 0" in warnings[0]


def test_crossing_is_within_its_bound():
    from scipy.optimize import brentq

    def f(spin):
        return 1.8 + 0.1 * spin**2 + 0.02 * spin**3  # a smooth rising curve

    spins = np.linspace(3.0, 4.0, 101)
    target = f(3.5) + 1e-3  # between two samples
    spin, bound = ps.crossing(spins, f(spins), target)
    exact = brentq(lambda s: f(s) - target, 3.0, 4.0, xtol=1e-14)
    assert abs(spin - exact) <= bound and 0 < bound < 1e-5
    with pytest.raises(ValueError, match="does not pass"):
        ps.crossing(spins, f(spins), 99.0)


def test_twist_sees_only_the_turn_about_the_tangent():
    t0 = np.asarray(ps.TIP_TANGENT0)
    angle = 0.3
    vectors = np.array(
        [
            angle * t0,  # twist about the tip's tangent
            [angle, 0.0, 0.0],  # flap: about the chord
            [0.0, 0.0, 5.0],  # a turn of the hub about z
        ]
    )
    assert np.allclose(ps.tip_twist(vectors), [angle, 0.0, 0.0], atol=1e-12)
    R = ps.rotation_matrices(vectors)
    assert np.allclose(R @ np.transpose(R, (0, 2, 1)), np.eye(3), atol=1e-14)


def test_rotating_frame_and_envelope():
    t = np.linspace(0.0, 10.0, 10001)
    psi = ps.spin_angle(t)
    inertial = np.column_stack([-0.4 * np.sin(psi), 0.4 * np.cos(psi), 0.1 + 0 * t])
    assert np.allclose(ps.to_rotating(t, inertial), [0.0, 0.4, 0.1], atol=1e-12)
    assert ps.spin_hz(10.0) == pytest.approx(8.0) and ps.spin_angle(1.0) == 0.0
    _, amp = ps.envelope(t, 0.03 * np.sin(2 * math.pi * 4.5 * t))
    assert np.allclose(amp, 0.03, rtol=1e-3)
