"""Shape and polygon sections through the scene: the channel cantilever of demos/scenes twists
under a load through its centroid as the linear exact flexibility of its coupled section says,
and bad input names the file and the key."""

import tomllib
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("sectionproperties")

from beamfx.bench.coupled_cantilever import flexibility_tip
from beamfx.physics import shape_sections as ss
from beamfx.physics.matrix_sections import MatrixSection
from beamfx.runner import run_scene
from beamfx.scene.load import parse_scene
from beamfx.scene.table import SceneError

DEMO = Path(__file__).resolve().parents[2] / "demos" / "scenes" / "channel_cantilever.toml"


def _data(**section):
    data = tomllib.loads(DEMO.read_text())
    if section:
        data["beams"][0]["section"] = section
    return data


def _section(**section):
    return parse_scene(_data(**section), "shapes.toml").model.beams[0].section


def test_the_channel_twists_under_a_load_through_its_centroid_as_the_flexibility_says(tmp_path):
    data = _data()
    sec = data["beams"][0]["section"]
    params = {k: sec[k] for k in ("b", "d", "n_r", "r", "t_f", "t_w")}
    props = ss.shape_properties(
        "channel_section", tuple(sorted(params.items())), 0.3, sec["mesh_size"]
    )
    E, G, L = sec["E"], sec["E"] / 2.6, 2.0
    F = np.array(data["loads"][0]["force"], float)
    C, _ = ss.shape_matrices(props, E, G, sec["rho"], props.centroid)
    u_ref, theta_ref = flexibility_tip(C, L, F, np.zeros(3))
    # the twist alone: the torque about the shear centre, (c - s) × F, over GJ
    dy = props.centroid[0] - props.shear_centre[0]
    assert theta_ref[0] == pytest.approx(dy * F[2] * L / (G * props.J), rel=1e-12)
    assert 0.05 < dy < 0.07  # the shear centre 6 cm behind the centroid
    run = run_scene(DEMO, tmp_path / "out", log=lambda m: None)
    tip = run["probes"]["tip"]
    u, theta = np.array(tip["displacement"]), np.array(tip["rotation_vector"])
    # quadratic elements are exact under tip loads (beamfx/bench/coupled_cantilever.py)
    assert np.allclose(theta, theta_ref, rtol=1e-8, atol=1e-10 * abs(theta_ref).max())
    assert np.allclose(u, u_ref, rtol=1e-8, atol=1e-10 * abs(u_ref).max())
    # an open section is weak in torsion: the twist (-0.0093 rad) dwarfs the bending rotation
    assert theta[0] < 0 and abs(theta[0]) > 10 * abs(theta[1])


RECT = {"type": "polygon", "E": 70e9, "nu": 0.33, "rho": 2700.0, "mesh_size": 2e-5}
SQUARE = [[0.0, 0.0], [0.05, 0.0], [0.05, 0.1], [0.0, 0.1]]


def test_a_polygon_is_the_built_in_shape_and_is_analysed_once():
    poly = _section(**RECT, points=SQUARE)
    shape = _section(**{**RECT, "type": "shape"}, shape="rectangular_section", b=0.05, d=0.1)
    assert isinstance(poly, MatrixSection) and isinstance(shape, MatrixSection)
    # the same triangles (the polygon is the shape's outline): the same matrices
    assert np.allclose(poly.stiffness, shape.stiffness, rtol=1e-9, atol=1e-9 * poly.stiffness.max())
    assert np.allclose(poly.mass, shape.mass, rtol=1e-9, atol=1e-12)
    hits = ss.polygon_properties.cache_info().hits
    about_corner = _section(**RECT, points=SQUARE, reference=[0.0, 0.0])
    assert ss.polygon_properties.cache_info().hits == hits + 1
    C = about_corner.stiffness[0]
    EA = 70e9 * 0.005
    assert C[0, 0] == pytest.approx(EA) and C[0, 4] == pytest.approx(EA * 0.05)  # ∫ z
    assert C[0, 5] == pytest.approx(-EA * 0.025)  # -∫ y


def test_a_hole_takes_its_area_away():
    hole = [[0.01, 0.01], [0.04, 0.01], [0.04, 0.09], [0.01, 0.09]]
    sec = _section(**RECT, points=SQUARE, holes=[hole])
    assert sec.stiffness[0][0, 0] == pytest.approx(70e9 * (0.005 - 0.03 * 0.08))


@pytest.mark.parametrize(
    ("section", "key", "message"),
    [
        ({"shape": "h_section", "d": 0.2}, "shape", "'h_section' is not allowed; allowed: "),
        ({"shape": "i_section", "d": 0.2, "b": 0.1, "t_f": 0.01, "t_w": 0.0, "r": 0.0}, "t_w", "> 0"),
        ({"shape": "i_section", "d": 0.2, "b": 0.1, "t_f": 0.01, "r": 0.0}, "t_w", "missing"),
        ({"shape": "channel_section", "d": 0.2, "b": 0.1, "t_f": 0.01, "t_w": 0.006, "r": -1.0}, "r", "must be >= 0"),
        ({"shape": "i_section", "d": 0.2, "b": 0.1, "t_f": 0.15, "t_w": 0.006, "r": 0.0}, "t_f", r"needs 2·t_f \+ 2·r < d \(given t_f = 0.15, r = 0, d = 0.2\)"),
        # a web wider than the flanges was built without complaint
        ({"shape": "i_section", "d": 0.2, "b": 0.1, "t_f": 0.01, "t_w": 0.12, "r": 0.0}, "t_w", r"= 0.12: the i_section needs t_w \+ 2·r < b"),
        ({"shape": "rectangular_hollow_section", "d": 0.2, "b": 0.1, "t": 0.06, "r_out": 0.0}, "t", r"needs 2·t < b"),
        ({"shape": "rectangular_section", "b": 1, "d": 1, "color": 1}, "color", "unknown key"),
        # sectionproperties 2.0.3's warping system is singular on this hexagon's mesh
        ({"shape": "circular_section", "d": 0.1, "n": 6, "mesh_size": 2e-5}, "shape", "analysis failed"),
        ({"type": "polygon", "points": [[0, 0], [1, 1], [1, 0], [0, 1]]}, "points", "not a valid polygon: Self-intersection"),
        ({"type": "polygon", "points": [[0, 0], [1, 1]]}, "points", "at least 3 points"),
        # points on one line: shapely says "Self-intersection"
        ({"type": "polygon", "points": [[0, 0], [1, 1], [2, 2]]}, "points", "zero area: the points lie on one line"),
        ({"type": "polygon", "points": SQUARE, "holes": [[[0, 0]]]}, "holes", "hole 1: expected"),
        ({"type": "polygon", "points": SQUARE, "reference": "middle"}, "reference", "not allowed"),
        ({"type": "polygon", "points": SQUARE, "reference": [1, 2, 3]}, "reference", r"expected \[y, z\]"),
    ],
)  # fmt: skip
def test_bad_input_names_the_file_and_the_key(section, key, message):
    table = {"type": "shape", "E": 1e9, **section}
    with pytest.raises(
        SceneError, match=rf"shapes\.toml: beams\[0\]\.section\.{key}[: =].*({message})"
    ):
        _section(**table)


def test_without_a_material_the_section_needs_its_own_modulus():
    with pytest.raises(SceneError, match=r"beams\[0\]\.section\.E: missing"):
        _section(type="polygon", points=SQUARE)
