"""Matrix (6×6) sections through ``beamfx run``: a matrix section built from a rectangle's
matrices gives the rectangle's answers (round-off) in every analysis, and bad input names the
file, the key and the station."""

import numpy as np
import pytest

from beamfx.physics.sections import rectangle
from beamfx.runner import run_scene

E, NU, RHO = 70e9, 0.33, 2700.0
H, W = 0.04, 0.02

SCENE = """
[material]
E = {E}
nu = {nu}
rho = {rho}

[[beams]]
name = "b"
curve = {{ shape = "line", start = [0, 0, 0], end = [1.2, 0.3, 0.1] }}
section = {section}
elements = 4
degree = 3
twist_deg = 20

[[supports]]
at = "b:start"
fix = "all"

[[loads]]
at = "b:end"
force = [{P}, 300, -200]
moment = [15, 5, 0]

[[probes]]
name = "tip"
at = "b:end"

[output]
dir = "{out}"
formats = ["vtu"]

[analysis]
{analysis}
"""

ANALYSES = {
    "linear_static": 'type = "linear_static"',
    "static": 'type = "static"\nsteps = 4',
    "modal": 'type = "modal"\nmodes = 6',
    "buckling": 'type = "buckling"\nmodes = 2',
    "rotating": 'type = "rotating"\naxis = [0, 0, 1]\nspeeds_rad_s = [0, 40]\nmodes = 4',
    "transient": 'type = "transient"\nt_end = 2e-3\ndt = 5e-4',
}


def _matrix(A):
    return "[" + ", ".join("[" + ", ".join(repr(float(x)) for x in row) + "]" for row in A) + "]"


def _sections():
    C, M = rectangle(E, E / (2 * (1 + NU)), RHO, H, W, nu=NU).matrices()
    geometric = f'{{ type = "rectangle", h = {H}, w = {W} }}'
    matrix = f'{{ type = "matrix", stiffness = {_matrix(C)}, mass = {_matrix(M)} }}'
    return geometric, matrix


def _run(tmp_path, scene_file, section, analysis, name):
    P = -500.0 if analysis == "buckling" else 1000.0
    text = SCENE.format(
        E=E, nu=NU, rho=RHO, section=section, P=P, out=tmp_path / name, analysis=ANALYSES[analysis]
    )
    return run_scene(scene_file(text, f"{name}.toml"), log=lambda *a, **k: None)


def _numbers(x):
    """Every number of a result, flattened (dict keys in sorted order)."""
    if isinstance(x, dict):
        return [v for k in sorted(x) for v in _numbers(x[k])]
    if isinstance(x, (list, tuple)):
        return [v for item in x for v in _numbers(item)]
    if isinstance(x, (int, float)) and not isinstance(x, bool):
        return [float(x)]
    return []


KEYS = {
    "linear_static": ["probes"],
    "static": ["probes"],
    "modal": ["frequencies_hz"],
    "buckling": ["load_factors"],
    "rotating": ["frequencies_hz"],
    "transient": ["probes"],
}


#: the nonlinear static states agree to Newton's tolerance only (residual 1e-10 of the loads):
#: the tip resultants, from the derivatives of the fields, to 4e-9 of the largest one
ATOL = {"static": 1e-7}


@pytest.mark.parametrize("analysis", list(ANALYSES))
def test_a_matrix_section_from_a_rectangle_gives_the_rectangles_answers(
    tmp_path, scene_file, analysis
):
    geometric, matrix = _sections()
    a = _run(tmp_path, scene_file, geometric, analysis, "geometric")
    b = _run(tmp_path, scene_file, matrix, analysis, "matrix")
    for key in KEYS[analysis]:
        x, y = np.array(_numbers(a[key])), np.array(_numbers(b[key]))
        assert len(x) == len(y) and len(x) > 0, key
        assert np.allclose(x, y, rtol=1e-9, atol=ATOL.get(analysis, 1e-12) * np.abs(x).max()), (
            key,
            x,
            y,
        )


def test_the_shipped_coupled_cantilever_scene_gives_the_flexibility_integral(tmp_path):
    """beamfx/scenes/coupled_cantilever.toml as a user runs it (4 × P2): the tip is exact."""
    from importlib import resources

    from beamfx.bench.coupled_cantilever import reference

    path = resources.files("beamfx.scenes").joinpath("coupled_cantilever.toml")
    results = run_scene(str(path), tmp_path / "out", log=lambda *a, **k: None)
    tip = results["probes"]["tip"]
    ref = reference()
    got = {
        **dict(zip(["ux", "uy", "uz"], tip["displacement"])),
        **dict(zip(["rx", "ry", "rz"], tip["rotation_vector"])),
    }
    for k, v in ref.items():
        assert abs(got[k] - v) < 1e-11 * abs(v), (k, got[k], v)


HUB = """
[material]
E = 70e9
rho = 2700

[[beams]]
name = "blade"
curve = {{ shape = "line", start = [0, 0, 0], end = [1, 0, 0] }}
section = {{ type = "rectangle", h = 0.02, w = 0.05 }}
elements = 6
degree = 3
{stub}
[[supports]]
at = "{clamp}"
fix = "all"

[analysis]
type = "rotating"
axis = [0, 0, 1]
speeds_rad_s = [0, 60]
modes = 4
{hub}
[output]
dir = "{out}"
formats = ["vtu"]
"""


def test_a_hub_off_the_beam_is_a_point_anywhere(tmp_path, scene_file):
    """hub = [x, y, z] off every beam: the blade clamped 1.5 m from the axis spins faster in
    flap than with the hub at its root, and translating blade and hub together changes
    nothing (round-off)."""
    runs = {}
    for name, x0, hub in (
        ("root", 0.0, ""),
        ("off", 0.0, "hub = [-1.5, 0, 0]"),
        ("moved", 1.5, "hub = [0, 0, 0]"),
    ):
        text = HUB.format(stub="", clamp="blade:start", hub=hub, out=tmp_path / name)
        text = text.replace(
            "start = [0, 0, 0], end = [1, 0, 0]", f"start = [{x0}, 0, 0], end = [{x0 + 1}, 0, 0]"
        )
        runs[name] = run_scene(scene_file(text, f"{name}.toml"), log=lambda *x, **k: None)
    f = {k: np.array(r["frequencies_hz"]) for k, r in runs.items()}
    assert runs["off"]["hub"] == {"at": None, "position": [-1.5, 0.0, 0.0]}
    assert np.allclose(f["off"][0], f["root"][0], rtol=1e-12)  # at rest the hub plays no part
    assert f["off"][1, 0] > 1.2 * f["root"][1, 0] > 1.2 * f["root"][0, 0]
    assert np.allclose(f["off"], f["moved"], rtol=1e-9), (f["off"], f["moved"])
