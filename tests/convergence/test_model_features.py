"""Model features of the scene format: non-prismatic sections, semitangential moments,
rotational springs, supports in local axes, the planar model, mixed degrees, T-joints."""

import tomllib

import numpy as np
import pytest

from beamfx.analyses.checks import check_supported, connected_beams, end_contacts, joint_breaks
from beamfx.analyses.model import BeamModel
from beamfx.analyses.static import solve_static
from beamfx.io import evaluate_points
from beamfx.scene import parse_scene

STEEL = """
[material]
E = 210e9
nu = 0.3
"""


def scene(text):
    return parse_scene(tomllib.loads(text), "test.toml")


def solve(text, points, steps=10):
    s = scene(text)
    model = BeamModel(s.model, extra_points=points)
    solve_static(model, steps=steps)
    return model, evaluate_points(model, points)


def cantilever(section, load, extra="", elements=8, degree=3, model="", end="[1, 0, 0]"):
    return f"""{STEEL}
[[beams]]
name = "b"
curve = {{ shape = "line", start = [0, 0, 0], end = {end} }}
section = {section}
elements = {elements}
degree = {degree}

[[supports]]
at = "b:start"
fix = "all"

[[loads]]
at = "b:end"
{load}
{extra}
[model]
{model}
"""


def test_tapered_cantilever_matches_the_integrated_euler_bernoulli_deflection():
    """EI(s) = EI0 (1 - s/(2L)): w(L) = ∫ P (L - s)² / EI(s) ds (shear-rigid, small load)."""
    EI0, P = 2.0e4, 1.0
    section = (
        '{ type = "general", EA = 1e9, GA_y = 1e9, GA_z = 1e9, GJ = 1e4, '
        f'EI_y = "{EI0} * (1 - 0.5 * s / L)", EI_z = 1e4 }}'
    )
    text = cantilever(section, f"force = [0, 0, {P}]", model='kinematics = "linear"\nshear = false')
    s = np.linspace(0, 1, 20001)
    f = P * (1 - s) ** 2 / (EI0 * (1 - 0.5 * s))
    exact = np.sum((f[1:] + f[:-1]) / 2 * np.diff(s))
    for n, tol in ((4, 1e-4), (16, 1e-6)):
        _, v = solve(text.replace("elements = 8", f"elements = {n}"), ["b:end"])
        assert abs(v["b:end"]["displacement"][2] - exact) < tol * exact
    # a prismatic section with the mean stiffness would be 12 % off: the variation is used
    assert abs(P / (3 * EI0 * 0.75) - exact) > 0.05 * exact


def test_tabulated_tube_is_the_same_as_its_expression():
    tab = '{ type = "tube", d = { s = [0, 1], values = [0.05, 0.03] }, d_inner = 0.02 }'
    expr = '{ type = "tube", d = "0.05 - 0.02 * s", d_inner = 0.02 }'
    a = solve(cantilever(tab, "force = [0, 0, 100]"), ["b:end"])[1]["b:end"]["position"]
    b = solve(cantilever(expr, "force = [0, 0, 100]"), ["b:end"])[1]["b:end"]["position"]
    assert np.allclose(a, b, atol=1e-12)


def _tangent_asymmetry(kind):
    text = cantilever(
        '{ type = "rectangle", h = 0.02, w = 0.01 }',
        f'moment = [40, 30, 20]\nkind = "{kind}"',
    )
    import dolfinx.fem.petsc as fp

    from beamfx.solvers.forms import compile_form

    model, _ = solve(text, ["b:end"], steps=4)
    A = fp.assemble_matrix(compile_form(model.J), bcs=model.bcs)
    A.assemble()
    At = A.copy()
    At.transpose()
    return (A - At).norm()


def test_semitangential_moment_is_conservative_and_a_fixed_moment_is_not():
    """Semitangential moments have a potential (−M·ψ): symmetric tangent at a deformed state."""
    dead, semitangential = _tangent_asymmetry("dead"), _tangent_asymmetry("semitangential")
    assert dead > 1.0  # of the order of the moment (|M| = 54 N m)
    assert semitangential < 1e-6 * dead  # round-off (‖K‖ is about 1e11)


def test_semitangential_moment_in_its_plane_rolls_up_like_a_fixed_one():
    """Bending in one plane: ψ = φ e_y, so the semitangential moment is the fixed one."""
    M = 2 * np.pi * 1.0 / 1.0 * 0.75  # 3/4 of a full circle
    section = '{ type = "general", EA = 1e6, GA_y = 1e6, GA_z = 1e6, GJ = 1, EI_y = 1, EI_z = 1 }'
    tips = [
        solve(cantilever(section, f'moment = [0, {-M}, 0]\nkind = "{k}"'), ["b:end"])[1]["b:end"]
        for k in ("dead", "semitangential")
    ]
    assert np.allclose(tips[0]["position"], tips[1]["position"], atol=1e-9)


@pytest.mark.parametrize("plane", ["xz", "none"])
def test_moments_with_a_potential_in_the_planar_model(plane):
    """In the plane xz the semitangential moment is the fixed one (ψ = φ e_y), and a
    quasitangential moment on an arm along z is M cos φ (the arm turns, the force stays), so
    the tip angle of the pure bending solves φ = (M L/EI) cos φ: with M L/EI = 1, φ = 0.739085.
    The planar model's angle field is exact for pure bending (φ linear); the quaternion
    field of the 3D model interpolates it to the discretisation error."""
    section = '{ type = "general", EA = 1e6, GA_y = 1e6, GA_z = 1e6, GJ = 1, EI_y = 1, EI_z = 1 }'
    model = f'plane = "{plane}"'
    tips = {
        k: solve(
            cantilever(section, f'moment = [0, -1.0, 0]\nkind = "{k}"{arm}', model=model), ["b:end"]
        )[1]["b:end"]
        for k, arm in (
            ("dead", ""),
            ("semitangential", ""),
            ("quasitangential", "\narm = [0, 0, 1]"),
        )
    }
    tol = 1e-9 if plane == "xz" else 1e-5
    assert np.allclose(tips["dead"]["position"], tips["semitangential"]["position"], atol=tol)
    phi = abs(tips["quasitangential"]["rotation_vector"][1])
    assert phi == pytest.approx(0.7390851332, abs=tol)


def test_rotational_spring_at_a_pinned_root():
    """Pinned root with rotational spring k_r: tip deflection P L³/(3EI) + P L²/k_r."""
    EI, k_r, P = 1.0e4, 5.0e3, 1.0
    section = f'{{ type = "general", EA = 1e9, GA_y = 1e9, GA_z = 1e9, GJ = 1e4, EI_y = {EI}, EI_z = 1e4 }}'
    text = cantilever(
        section,
        f"force = [0, 0, {P}]",
        extra=f'[[springs]]\nat = "b:start"\nrotational = [{k_r}, {k_r}, {k_r}]\n',
        model='kinematics = "linear"\nshear = false',
    ).replace('fix = "all"', 'fix = "pinned"')
    _, v = solve(text, ["b:end"])
    exact = P / (3 * EI) + P / k_r
    assert abs(v["b:end"]["displacement"][2] - exact) < 1e-7 * exact


def _propped(direction, axes):
    """Clamped at the start; at the end, the displacement normal to the beam in the xy plane
    is held (in local axes that is uy); a distributed load pushes along that normal."""
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    normal = np.cross([0, 0, 1], d)
    fix = '["uy"]'  # local y is the in-plane normal; global y for the x-aligned beam
    return (
        f"""{STEEL}
[[beams]]
name = "b"
curve = {{ shape = "line", start = [0, 0, 0], end = {list(d)} }}
section = {{ type = "circle", d = 0.05 }}
elements = 8
degree = 3

[[supports]]
at = "b:start"
fix = "all"

[[supports]]
at = "b:end"
fix = {fix}
axes = "{axes}"

[[loads]]
beam = "b"
force_per_length = {list(1e4 * normal)}
""",
        d,
        normal,
    )


def test_support_in_local_axes_is_the_rotated_global_one():
    """A propped cantilever along x (global uy) and the same turned by 30° (local uy)."""
    text, _, _ = _propped([1, 0, 0], "global")
    ref = solve(text, ["b:0.5"])[1]["b:0.5"]["displacement"]
    c, s = np.cos(np.pi / 6), np.sin(np.pi / 6)
    text, d, normal = _propped([c, s, 0], "local")
    check_supported(scene(text).model)
    u = np.asarray(solve(text, ["b:0.5"])[1]["b:0.5"]["displacement"])
    assert abs(u @ normal - ref[1]) < 1e-7 * abs(ref[1])
    assert abs(u @ d - ref[0]) < 1e-7 * abs(ref[1])


def test_planar_model_matches_the_3d_model_with_fewer_unknowns():
    """A quarter-circle arch under an in-plane tip force, xz plane: planar vs full 3D."""
    text = f"""{STEEL}
[[beams]]
name = "a"
curve = {{ shape = "arc", start = [0, 0, 0], start_tangent = [1, 0, 0], centre = [0, 0, 1], angle_deg = 90 }}
section = {{ type = "rectangle", h = 0.05, w = 0.03 }}
elements = 8
degree = 3

[[supports]]
at = "a:start"
fix = "all"

[[loads]]
at = "a:end"
force = [-4e4, 0, -2e4]
moment = [0, 1e3, 0]
"""
    full, vf = solve(text + '[model]\nplane = "none"\n', ["a:end"])
    planar, vp = solve(text + '[model]\nplane = "xz"\n', ["a:end"])
    assert planar.unknowns() == 3 * full.unknowns() // 7
    assert np.allclose(vf["a:end"]["position"], vp["a:end"]["position"], atol=1e-9)
    assert abs(vf["a:end"]["angle"] - vp["a:end"]["angle"]) < 1e-8
    assert vf["a:end"]["angle"] > 0.3  # a large rotation
    with pytest.raises(ValueError, match="out-of-plane"):
        scene(
            text.replace("force = [-4e4, 0, -2e4]", "force = [0, 1, 0]") + '[model]\nplane = "xz"\n'
        )


def test_beams_of_different_degree_share_the_highest():
    text = f"""{STEEL}
[[beams]]
name = "a"
curve = {{ shape = "line", start = [0, 0, 0], end = [1, 0, 0] }}
section = {{ type = "circle", d = 0.05 }}
degree = 2

[[beams]]
name = "b"
curve = {{ shape = "line", start = [1, 0, 0], end = [1, 1, 0] }}
section = {{ type = "circle", d = 0.05 }}
degree = 3

[[supports]]
at = "a:start"
fix = "all"
"""
    model = BeamModel(scene(text).model)
    assert model.degree == 3 and model.discretisation.raised_degree == ["a"]


def test_t_joint_connects_and_separate_beams_need_their_own_supports():
    text = f"""{STEEL}
[[beams]]
name = "a"
curve = {{ shape = "line", start = [0, 0, 0], end = [1, 0, 0] }}
section = {{ type = "circle", d = 0.05 }}
elements = 3

[[beams]]
name = "b"
curve = {{ shape = "line", start = [0.5, 0, 0], end = [0.5, 1, 0] }}
section = {{ type = "circle", d = 0.05 }}

[[supports]]
at = "b:end"
fix = "all"

[[loads]]
at = "a:end"
force = [0, 0, 1e3]
"""
    s = scene(text)
    assert connected_beams(s.model) == [[0, 1]]
    # b's start lies on a at s = 0.5 (the only contact): found and placed exactly
    assert end_contacts(s.model) == [(1, 0, 0.5)] and joint_breaks(s.model) == [(0, 0.5)]
    check_supported(s.model)
    # the T-joint is a mesh vertex, so the load on "a" is carried by "b" to its support
    _, v = solve(text, ["a:end", "b:end"])
    assert v["a:end"]["displacement"][2] > 0
    assert np.isclose(np.linalg.norm(v["b:end"]["section_force"]), 1e3, rtol=1e-6)
    apart = scene(text.replace("start = [0.5, 0, 0]", "start = [0.5, 0.1, 0]"))
    with pytest.raises(ValueError, match="free on beams \\['a'\\]"):
        check_supported(apart.model)
