"""Support reactions (beamfx.analyses.reactions) through ``beamfx run``: they balance the
applied loads to the solver's tolerance in a cantilever, a two-support frame, a curved beam
under distributed load and gravity, and an arc-length run, and equal closed forms.

Tolerances: linear kinematics solve once by LU, so the balance is at round-off: the LU
residual is about ε‖K‖‖u‖, which exceeds ε‖f‖ by the ratio of axial to bending stiffness
(EA L²/EI = 12 L²/h² ≈ 5e3 for these beams), hence 1e-10 relative to the load scale; finite
kinematics stop Newton at an absolute residual of 1e-10 of the load vector's norm, which bounds
the balance (1e-9 relative: a few nodes' worth).
"""

import json

import numpy as np
import pytest

from beamfx.runner import run_scene

STEEL = """
[material]
E = 210e9
nu = 0.3
rho = 7850
"""

CANTILEVER = (
    STEEL
    + """
[[beams]]
name = "b"
curve = { shape = "line", start = [0, 0, 0], end = [2, 0, 0] }
section = { type = "rectangle", h = 0.1, w = 0.05 }
elements = 4
degree = 2

[[supports]]
at = "b:start"
fix = "all"

[[loads]]
at = "b:end"
force = [1e3, -2e3, 5e3]
moment = [100, 0, 300]

[[probes]]
name = "tip"
at = "b:end"

[model]
kinematics = "KIN"
condense = "CONDENSE"
plane = "none"

[analysis]
type = "static"
steps = 2
"""
)

PORTAL = (
    STEEL
    + """
[[beams]]
name = "left"
curve = { shape = "line", start = [0, 0, 0], end = [0, 0, 3] }
section = { type = "rectangle", h = 0.2, w = 0.1 }
orientation = [1, 0, 0]
elements = 4
[[beams]]
name = "top"
curve = { shape = "line", start = [0, 0, 3], end = [4, 0, 3] }
section = { type = "rectangle", h = 0.2, w = 0.1 }
orientation = [0, 0, 1]
elements = 4
[[beams]]
name = "right"
curve = { shape = "line", start = [4, 0, 3], end = [4, 0, 0] }
section = { type = "rectangle", h = 0.2, w = 0.1 }
orientation = [1, 0, 0]
elements = 4

[[supports]]
at = "left:start"
fix = "all"
[[supports]]
at = "right:end"
fix = "pinned"

[[loads]]
at = "top:0.25"
force = [2e4, 3e3, -5e4]
[[loads]]
beam = "top"
force_per_length = [0, 0, -1e4]
[[loads]]
gravity = [0, 0, -9.81]

[model]
kinematics = "KIN"
plane = "none"

[analysis]
type = "static"
steps = 2
"""
)

# a quarter circle in the horizontal plane, clamped at one end and held vertically at the
# other, under its weight and a distributed load in section axes (radial)
CURVED = (
    STEEL
    + """
[[beams]]
name = "arc"
curve = { shape = "arc", start = [0, 0, 0], start_tangent = [1, 0, 0], centre = [0, 2, 0], angle_deg = 90 }
section = { type = "tube", d = 0.1, d_inner = 0.08 }
elements = 6
degree = 3

[[supports]]
at = "arc:start"
fix = "all"
[[supports]]
at = "arc:end"
fix = ["uz"]

[[loads]]
gravity = [0, 0, -9.81]
[[loads]]
beam = "arc"
force_per_length = [0, 0, 2e3]
axes = "section"
[[loads]]
at = "arc:0.5"
force = [0, 0, -3e3]
kind = "follower"

[model]
kinematics = "KIN"

[analysis]
type = "static"
steps = 3
"""
)


def _quiet(*args, **kwargs):
    pass


def _run(scene_file, tmp_path, text, **subs):
    for key, value in subs.items():
        text = text.replace(key, value)
    lines = []
    run = run_scene(scene_file(text), tmp_path / "out", log=lines.append)
    saved = json.loads((tmp_path / "out" / "results.json").read_text())
    assert saved["reactions"] == json.loads(json.dumps(run["reactions"]))
    return run, lines


def _tolerance(kin):
    return 1e-10 if kin == "linear" else 1e-9


@pytest.mark.parametrize("kin", ["linear", "finite"])
def test_cantilever_reaction_is_minus_the_tip_load(scene_file, tmp_path, kin):
    """Statically determinate: force −F, moment −(M + x_tip × F) about the clamp (x_tip the
    current tip position for finite kinematics); the log prints the balance."""
    run, lines = _run(scene_file, tmp_path, CANTILEVER, KIN=kin, CONDENSE="none")
    r = run["reactions"]["b:start"]
    F, M = np.array([1e3, -2e3, 5e3]), np.array([100, 0, 300.0])
    tip = np.array([2.0, 0, 0]) if kin == "linear" else np.asarray(run["probes"]["tip"]["position"])
    assert np.allclose(r["force"], -F, rtol=0, atol=1e-9 * np.abs(F).max())
    assert np.allclose(r["moment"], -(M + np.cross(tip, F)), rtol=0, atol=1e-8 * 1e4)
    bal = run["reaction_balance"]
    assert bal["force"] < _tolerance(kin) and bal["moment"] < _tolerance(kin)
    assert np.allclose(bal["applied_force"], F)
    assert any(line.startswith("reactions: 1 point(s); balance") for line in lines)
    path = run["path"]
    assert len(path) == (1 if kin == "linear" else 2)
    assert np.allclose(path[-1]["reactions"]["b:start"]["force"], r["force"])


@pytest.mark.parametrize("kin", ["linear", "finite"])
def test_an_end_moment_alone_balances_on_the_moment_over_the_length(scene_file, tmp_path, kin):
    """No force anywhere: the force balance is measured against M/L (it divided the
    round-off reaction force by 1e-300 and said 2e289, the blind test's finding)."""
    text = CANTILEVER.replace("force = [1e3, -2e3, 5e3]\n", "")
    run, _ = _run(scene_file, tmp_path, text, KIN=kin, CONDENSE="none")
    bal = run["reaction_balance"]
    assert bal["applied_force"] == [0.0, 0.0, 0.0]
    assert bal["force"] < _tolerance(kin) and bal["moment"] < _tolerance(kin)
    r = run["reactions"]["b:start"]
    assert np.allclose(r["moment"], [-100, 0, -300.0], rtol=1e-9)


def test_condensed_cantilever_reaction_from_the_statics_of_its_loads(scene_file, tmp_path):
    """The statically condensed model: the clamp's reaction is the statics of the loads at the
    computed tip (dead loads: −λ F, −λ(M + x × F)), so it balances them at round-off; the
    section moment recovered from the curvature lies within its discretisation error of it
    (``recovered_moment_gap``)."""
    run, lines = _run(scene_file, tmp_path, CANTILEVER, KIN="finite", CONDENSE="auto")
    assert run["model"]["condensed"]
    r = run["reactions"]["b:start"]
    F, M = np.array([1e3, -2e3, 5e3]), np.array([100, 0, 300.0])
    tip = np.asarray(run["probes"]["tip"]["position"])
    assert np.allclose(r["force"], -F, rtol=0, atol=1e-9 * 5e3)
    exact = -(M + np.cross(tip, F))
    m_scale = np.linalg.norm(tip) * np.linalg.norm(F) + np.linalg.norm(M)
    assert np.allclose(r["moment"], exact, rtol=0, atol=1e-12 * m_scale)
    bal = run["reaction_balance"]
    assert np.allclose(bal["applied_force"], F, rtol=1e-14, atol=0)
    assert np.allclose(bal["applied_moment"], -exact, rtol=1e-12, atol=0)
    assert bal["force"] < 1e-14 and bal["moment"] < 1e-14
    assert 1e-8 < bal["recovered_moment_gap"] < 1e-3  # the recovery's discretisation error
    assert any("statics of the loads" in line and "balance" in line for line in lines)


@pytest.mark.parametrize("kin", ["linear", "finite"])
def test_two_support_frame_balances_point_distributed_and_gravity_loads(scene_file, tmp_path, kin):
    """A portal frame (clamped and pinned feet): statically indeterminate, the reactions come
    from the residual; their sum balances a point load, a distributed load and the weight."""
    run, _ = _run(scene_file, tmp_path, PORTAL, KIN=kin)
    reactions = run["reactions"]
    assert set(reactions) == {"left:start", "right:end"}
    assert np.allclose(reactions["right:end"]["moment"], 0.0, atol=1e-9)
    weight = 7850 * 0.2 * 0.1 * 10 * 9.81
    applied = np.array([2e4, 3e3, -5e4 - 4e4 - weight])
    total = sum(np.asarray(r["force"]) for r in reactions.values())
    assert np.allclose(total, -applied, rtol=0, atol=1e-9 * np.abs(applied).max())
    bal = run["reaction_balance"]
    assert np.allclose(bal["applied_force"], applied, rtol=1e-12)
    assert bal["force"] < _tolerance(kin) and bal["moment"] < _tolerance(kin)


@pytest.mark.parametrize("kin", ["linear", "finite"])
def test_curved_beam_balances_section_axes_follower_and_gravity_loads(scene_file, tmp_path, kin):
    """Quarter circle: radial distributed load in section axes, a follower force, gravity."""
    run, _ = _run(scene_file, tmp_path, CURVED, KIN=kin)
    bal = run["reaction_balance"]
    assert bal["force"] < _tolerance(kin) and bal["moment"] < _tolerance(kin)
    # the vertical support at the end carries only a vertical force and no moment
    end = run["reactions"]["arc:end"]
    assert np.allclose(end["force"][:2], 0.0, atol=1e-12) and np.allclose(end["moment"], 0.0)
    if kin == "linear":  # weight and the section-axes load (the section z is vertical here);
        # the loads act on the P3 geometry of 6 cells, whose length is the arc's to ~2e-6
        length = np.pi
        area = np.pi / 4 * (0.1**2 - 0.08**2)
        vertical = -7850 * area * length * 9.81 + 2e3 * length - 3e3
        assert bal["applied_force"][2] == pytest.approx(vertical, rel=1e-5)


def test_arclength_reactions_balance_along_the_path(tmp_path):
    """The shallow arch's snap-through (built-in scene, fewer steps): the pinned supports'
    reactions balance the radial load at the last point of the path."""
    from dataclasses import replace
    from importlib import resources

    from beamfx.scene import load_scene

    path = resources.files("beamfx") / "scenes" / "shallow_arch_snap.toml"
    scene = load_scene(path)
    scene = replace(scene, settings=replace(scene.settings, max_steps=6))
    run = run_scene(path, tmp_path / "out", log=_quiet, scene=scene)
    bal = run["reaction_balance"]
    assert bal["force"] < 1e-9 and bal["moment"] < 1e-9
    assert set(run["reactions"]) == {"arch:start", "arch:end"}
    path = run["path"]
    assert path[-1]["reactions"] == run["reactions"]
    assert len(path) == 7 and all("reactions" in p for p in path[1:])  # the start has none
    for r in run["reactions"].values():  # pinned about x: no moment about x
        assert abs(r["moment"][0]) < 1e-9 * np.abs(bal["applied_force"]).max()


ROLLER = (
    STEEL
    + """
[[beams]]
name = "b"
curve = { shape = "line", start = [0, 0, 0], end = [3, 0, 4] }
section = { type = "rectangle", h = 0.1, w = 0.05 }
elements = 4
[[supports]]
at = "b:start"
fix = "pinned"
[[supports]]
at = "b:end"
fix = ["uy", "uz"]
axes = "local"
[[springs]]
at = "b:0.5"
stiffness = [0, 2e5, 0]
rotational = [1e3, 0, 0]
[[loads]]
at = "b:0.25"
force = [1e3, 2e3, -3e3]
[model]
kinematics = "KIN"
plane = "none"
[analysis]
type = "static"
steps = 2
"""
)


@pytest.mark.parametrize("kin", ["linear", "finite"])
def test_local_roller_and_springs_react_with_their_spring_force(scene_file, tmp_path, kin):
    """A support in local axes (stiff penalty springs normal to the member) and a spring to
    ground react with their spring forces; with the pin they balance the load. The roller's
    force is normal to the member (it slides along it). Tolerance: the roller's springs are
    1e9 times stiffer than the beam, which raises the residual floor of the solve by about as
    much (Newton stops there, at ~3e-7 of the load); the balance is as good as the final
    residual |F| allows: Σ forces within a few |F|, Σ moments within a few |F| times the
    member's length (5)."""
    run, _ = _run(scene_file, tmp_path, ROLLER, KIN=kin)
    reactions = run["reactions"]
    assert set(reactions) == {"b:start", "b:end", "b:0.5"}
    bal = run["reaction_balance"]
    residual = max(run["load_steps"][-1]["residuals"][-1], 1e-12)
    load = np.linalg.norm([1e3, 2e3, -3e3])  # the force scale; the moment scale is > 1.2 load
    assert bal["force"] * load < 3 * residual
    assert bal["moment"] * 1.2 * load < 3 * 5 * residual
    roller = np.asarray(reactions["b:end"]["force"])
    axis = np.array([3.0, 0, 4]) / 5
    assert abs(roller @ axis) < 1e-6 * np.linalg.norm(roller) and np.linalg.norm(roller) > 100
    spring = reactions["b:0.5"]
    assert abs(spring["force"][1]) > 0 and spring["force"][0] == spring["force"][2] == 0
