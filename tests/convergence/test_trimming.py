"""Model trimming: the scene builder picks the planar model for plane problems, and the planar
model gives the answer of the full one (to the discretisation error: quaternion and angle
fields interpolate rotations differently; to the solver tolerance for linear kinematics, where
the rotation-vector and angle fields coincide)."""

import copy
import tomllib
from pathlib import Path

import numpy as np
import pytest

from beamfx.scene import SceneError, parse_scene

ROLLUP = """
[[beams]]
name = "b"
curve = { shape = "line", start = [0, 0, 0], end = [10, 0, 0] }
section = { type = "general", EA = 1770e3, GA_y = 1770e3, GA_z = 1770e3, GJ = 8.16e3, EI_y = 86.9e3, EI_z = 215e3 }
elements = 8
degree = 4
[[supports]]
at = "b:start"
fix = "all"
[[loads]]
at = "b:end"
moment = [0, -54600.88018, 0]   # 2π EI_y / L about -y: one full loop towards +z
[analysis]
steps = 8
[[probes]]
name = "tip"
at = "b:end"
"""

ARC = """
[material]
E = 1e7
nu = 0.0
[[beams]]
name = "a"
curve = { shape = "arc", start = [0, 0, 0], start_tangent = [0, 1, 0], centre = [100, 0, 0], angle_deg = 45 }
section = { type = "rectangle", h = 1.0, w = 2.0 }
elements = 8
degree = 4
[[supports]]
at = "a:start"
fix = "all"
[[loads]]
at = "a:end"
force = [3000, 2000, 0]
[[probes]]
name = "tip"
at = "a:end"
"""


def scene(text, **edits):
    """Parse ``text`` after setting ``edits`` ({"model.plane": "none", ...}) in its data."""
    data = copy.deepcopy(tomllib.loads(text))
    for path, value in edits.items():
        *tables, key = path.split(".")
        d = data
        for t in tables:
            d = d.setdefault(t, {}) if not t.isdigit() else d[int(t)]
        d[key] = value
    return parse_scene(data, "t.toml")


def tip(sc):
    from beamfx.analyses.model import BeamModel
    from beamfx.analyses.static import solve_static
    from beamfx.io.probes import evaluate_points

    at = sc.probes["tip"]
    model = BeamModel(sc.model, extra_points=[at])
    solve_static(model, steps=sc.steps)
    return np.array(evaluate_points(model, [at])[at]["position"]), model.unknowns()


def test_rollup_is_trimmed_and_agrees_with_the_full_model():
    planar, full = scene(ROLLUP), scene(ROLLUP, **{"model.plane": "none"})
    assert planar.model.kinematics.plane == "xz" and planar.trimming.automatic
    assert full.model.kinematics.plane is None and not full.trimming.automatic
    x_p, n_p = tip(planar)
    x_f, n_f = tip(full)
    assert n_p * 7 == n_f * 3  # 3 instead of 7 unknowns per node
    # exact: the beam closes into a circle, the tip returns to the clamp (L = 10)
    assert np.linalg.norm(x_p) < 1e-6 * 10 and np.linalg.norm(x_f) < 1e-6 * 10
    assert np.linalg.norm(x_p - x_f) < 1e-6 * 10


def test_planar_arc_under_in_plane_load_agrees_with_the_full_model():
    planar, full = scene(ARC), scene(ARC, **{"model.plane": "none"})
    assert planar.model.kinematics.plane == "xy"
    x_p, _ = tip(planar)
    x_f, _ = tip(full)
    # a large deflection (tens of units); the two discretisations agree to ~1e-7 of it
    assert np.linalg.norm(x_p - np.array([29.289, 70.711, 0.0])) > 10
    assert np.linalg.norm(x_p - x_f) < 1e-6 * 100


def test_linear_planar_equals_linear_full_to_solver_tolerance():
    planar = scene(ARC, **{"analysis.type": "linear_static"})
    full = scene(ARC, **{"analysis.type": "linear_static", "model.plane": "none"})
    assert planar.model.kinematics.plane == "xy" and not planar.model.kinematics.finite
    x_p, _ = tip(planar)
    x_f, _ = tip(full)
    assert np.linalg.norm(x_p - x_f) < 1e-9 * np.linalg.norm(x_f)


def test_planar_transient_spin_up_agrees_with_the_full_model():
    """The angle field and the quaternion field interpolate the rotation differently: the two
    models differ by the discretisation error in space, which falls with the element size."""
    from beamfx.analyses.model import BeamModel
    from beamfx.analyses.transient import solve_transient
    from beamfx.io.probes import evaluate_points

    text = (Path(__file__).parents[2] / "demos/scenes/spin_up.toml").read_text()
    text = text.replace('plane = "xy"', "").replace("t_end = 18.0", "t_end = 4.0")
    differences = []
    text = text.replace("dt = 0.0125", "dt = 0.1")
    for n in (4, 8):
        tips = []
        for plane in ("auto", "none"):
            sc = scene(text.replace("elements = 4", f"elements = {n}"), **{"model.plane": plane})
            assert sc.model.kinematics.plane == ("xy" if plane == "auto" else None)
            model = BeamModel(sc.model, extra_points=["beam:end"])
            solve_transient(model, sc.settings.solver())
            tips.append(np.array(evaluate_points(model, ["beam:end"])["beam:end"]["position"]))
        assert np.linalg.norm(tips[0] - [10, 0, 0]) > 1  # the hub has turned the beam
        differences.append(np.linalg.norm(tips[0] - tips[1]))
    assert differences[0] < 1e-4 * 10
    assert differences[1] < differences[0] / 4, differences


@pytest.mark.parametrize(
    "edits, why",
    [
        ({}, "leaves the plane"),  # the 45° bend: a vertical load on a horizontal arc
        ({"analysis.type": "modal"}, "out-of-plane modes"),
    ],
)
def test_3d_scenes_keep_the_full_model(edits, why):
    text = (Path(__file__).parents[2] / "beamfx/scenes/bend45.toml").read_text()
    if edits:  # a plane problem (in-plane load), but a modal analysis
        text = text.replace("force = [0, 0, 600]", "force = [600, 0, 0]")
    sc = scene(text, **edits)
    assert sc.model.kinematics.plane is None
    assert why in sc.trimming.reason


@pytest.mark.parametrize(
    "edits, trimmed",
    [
        ({"beams.0.twist_deg": 30.0}, False),  # principal axes skew to the plane
        ({"beams.0.twist_deg": 90.0}, True),  # h now along the plane: still principal
        ({"beams.0.section": {"type": "circle", "d": 1.0}, "beams.0.twist_deg": 30.0}, True),
        ({"supports.0.displacement": [0, 0, 0.1], "supports.0.fix": "all"}, False),
        ({"supports.0.rotation": [0, 0.1, 0], "supports.0.fix": "all"}, False),
        (
            {
                "masses": [
                    {"at": "a:end", "mass": 1.0, "inertia": [[1, 0, 0.2], [0, 1, 0], [0.2, 0, 1]]}
                ]
            },
            False,
        ),
        ({"masses": [{"at": "a:end", "mass": 1.0, "inertia": [1, 2, 3]}]}, True),
        ({"loads": [{"at": "a:end", "moment": [0, 0, 5.0]}]}, True),
        ({"loads": [{"at": "a:end", "moment": [1.0, 0, 0]}]}, False),
        ({"loads": [{"gravity": [0, -9.81, 0]}]}, True),
        ({"loads": [{"force_per_length": [0, 0, 1.0]}]}, False),
    ],
)
def test_what_keeps_a_scene_planar(edits, trimmed):
    sc = scene(ARC, **edits)
    assert (sc.model.kinematics.plane == "xy") is trimmed, sc.trimming.reason


def test_plane_key_values_and_errors():
    assert scene(ARC, **{"model.plane": "xy"}).trimming[:3] == (
        "xy",
        False,
        "stated: [model] plane = 'xy'",
    )
    with pytest.raises(
        SceneError, match=r"model.plane: 'z' is not allowed; allowed: \['auto', 'none'"
    ):
        scene(ARC, **{"model.plane": "z"})
    with pytest.raises(SceneError, match="model.plane: planar model \\(xz\\)"):
        scene(ARC, **{"model.plane": "xz"})  # the arc is in xy
