"""Matrix (6×6) sections: conventions, offsets, interpolation and the scene keys' errors."""

import numpy as np
import pytest

from beamfx.physics import matrix_sections as ms
from beamfx.physics.sections import rectangle
from beamfx.scene.load import parse_scene
from beamfx.scene.table import SceneError

DIAG = [1e6, 3e5, 4e5, 2e3, 5e3, 8e3]


def test_beamdyn_order_maps_to_beamfx_order_and_back():
    """BeamDyn (shear 1, shear 2, extension, bending 1, bending 2, torsion) with its x1, x2
    the section's y, z: its diagonal (GA_y, GA_z, EA, EI_y, EI_z, GJ) is ours permuted."""
    EA, GAy, GAz, GJ, EIy, EIz = DIAG
    bd = np.diag([GAy, GAz, EA, EIy, EIz, GJ])
    assert np.allclose(np.diag(ms.from_beamdyn(bd)), DIAG)
    A = np.arange(36.0).reshape(6, 6)
    assert np.array_equal(ms.to_beamdyn(ms.from_beamdyn(A)), A)
    # extension-twist coupling K36 (BeamDyn) is our (1, 4)
    bd[2, 5] = bd[5, 2] = 7.0
    assert ms.from_beamdyn(bd)[0, 3] == 7.0


def test_offset_stiffness_is_the_energy_of_the_centre_strains():
    """½ εᵀ C ε equals the energy of the strains at the tension and shear centres."""
    rng = np.random.default_rng(0)
    t, s = (0.02, -0.01), (-0.03, 0.015)
    C = ms.offset_stiffness(*DIAG, tension=t, shear=s)
    for _ in range(5):
        e = rng.normal(size=6)
        Gamma, K = e[:3], e[3:]
        et = Gamma + np.cross(K, [0, *t])  # strains of the fibres at the centres
        es = Gamma + np.cross(K, [0, *s])
        EA, GAy, GAz, GJ, EIy, EIz = DIAG
        energy = EA * et[0] ** 2 + GAy * es[1] ** 2 + GAz * es[2] ** 2
        energy += GJ * K[0] ** 2 + EIy * K[1] ** 2 + EIz * K[2] ** 2
        assert np.isclose(e @ C @ e, energy, rtol=1e-12)
    assert np.allclose(ms.offset_stiffness(*DIAG), np.diag(DIAG))


def test_offset_mass_is_the_kinetic_energy_of_the_offset_rigid_section():
    """vᵀ M v = m |u̇ + ω × ξ|² + ω·J_c ω (section axes), and M is positive definite."""
    rng = np.random.default_rng(1)
    m, Jc, xi = 3.0, np.array([0.2, 0.05, 0.15]), np.array([0.0, 0.1, -0.2])
    M = ms.offset_mass(m, Jc, xi[1:])
    for _ in range(5):
        u, w = rng.normal(size=3), rng.normal(size=3)
        v = u + np.cross(w, xi)
        assert np.isclose(np.r_[u, w] @ M @ np.r_[u, w], m * v @ v + w @ (Jc * w), rtol=1e-12)
    ms.check_mass(M)
    assert np.linalg.eigvalsh(M).min() > 0


def test_section_matrices_of_a_rectangle_are_its_diagonals():
    s = rectangle(70e9, 26e9, 2700.0, 0.04, 0.02)
    C, M = s.matrices()
    assert np.array_equal(np.diag(C), s.stiffnesses())
    assert np.array_equal(np.diag(M), [s.rho_A] * 3 + list(s.rho_I))
    ms.check_stiffness(C)
    ms.check_mass(M)


def test_station_interpolation_is_entrywise_linear_and_clamped():
    C0, C1 = np.diag(DIAG), 2 * np.diag(DIAG)
    C1[0, 3] = C1[3, 0] = 100.0
    sec = ms.MatrixSection([C0, C1], np.zeros((2, 6, 6)), (0.0, 1.0), 4.0)
    C, _ = sec.matrices_at([0.0, 1.0, 4.0, 5.0])
    assert np.allclose(C[1], 0.75 * C0 + 0.25 * C1)
    assert np.array_equal(C[2], C1) and np.array_equal(C[3], C1)


@pytest.mark.parametrize(
    "matrix, message",
    [
        (np.diag([1.0, 1, 1, 1, 1, -1]), "not positive definite"),
        (np.diag([1.0, 1, 1, 1, 1, 1]) + np.eye(6, k=1), "not symmetric: entry"),
        (np.full((6, 6), np.nan), "not finite"),
    ],
)
def test_bad_stiffness_is_refused(matrix, message):
    with pytest.raises(ValueError, match=message):
        ms.check_stiffness(matrix)


def test_bad_mass_blocks_are_refused():
    M = ms.offset_mass(2.0, [1.0, 0.5, 0.5], (0.1, 0.0))
    bad = M.copy()
    bad[1, 1] = 3.0
    with pytest.raises(ValueError, match="m·I"):
        ms.check_mass(bad)
    bad = M.copy()
    bad[0, 4] = bad[4, 0] = 5.0  # symmetric, but the coupling block is no longer skew
    with pytest.raises(ValueError, match="skew"):
        ms.check_mass(bad)


SCENE = """
[[beams]]
name = "b"
curve = {{ shape = "line", start = [0, 0, 0], end = [2, 0, 0] }}
section = {section}
[[supports]]
at = "b:start"
fix = "all"
[analysis]
type = "static"
"""


def _rows(A):
    return "[" + ", ".join("[" + ", ".join(repr(float(x)) for x in r) + "]" for r in A) + "]"


def _parse(section):
    import tomllib

    return parse_scene(tomllib.loads(SCENE.format(section=section)), "blade.toml")


def test_a_matrix_scene_reads_both_conventions_alike():
    C = ms.offset_stiffness(*DIAG, tension=(0.01, 0.02))
    a = _parse(f'{{ type = "matrix", stiffness = {_rows(C)} }}')
    b = _parse(
        f'{{ type = "matrix", convention = "beamdyn", stiffness = {_rows(ms.to_beamdyn(C))} }}'
    )
    sa, sb = a.model.beams[0].section, b.model.beams[0].section
    assert np.allclose(sa.stiffness, sb.stiffness) and not sa.mass.any()


def test_offset_keys_make_a_matrix_section():
    sec = '{ type = "general", EA = 1e6, GA_y = 3e5, GA_z = 4e5, GJ = 2e3, EI_y = 5e3, EI_z = 8e3, rho_A = 2, rho_I = [0.1, 0.04, 0.06], elastic_centre = [0.01, 0.02], mass_centre = [0, -0.05] }'
    s = _parse(sec).model.beams[0].section
    assert isinstance(s, ms.MatrixSection)
    assert np.allclose(s.stiffness[0], ms.offset_stiffness(*DIAG, tension=(0.01, 0.02)))
    assert np.allclose(s.mass[0], ms.offset_mass(2.0, [0.1, 0.04, 0.06], (0.0, -0.05)))


@pytest.mark.parametrize(
    "section, message",
    [
        ('{{ type = "matrix", stiffness = {I}, stations = [0, 0.5, 1] }}', "3 matrices|1 matrices"),
        (
            '{{ type = "matrix", stiffness = [{I}, {B}], stations = [0, 1] }}',
            "station 2 \\(s/L = 1\\) is not positive definite",
        ),
        ('{{ type = "matrix", stiffness = [{I}, {I}], stations = [0, 0] }}', "must increase"),
        ('{{ type = "matrix", stiffness = [{I}], stations = [0] }}', "at least two stations"),
        ('{{ type = "matrix", stiffness = [{I}, {I}], stations = [0, 0.8] }}', "from 0 to 1"),
        ('{{ type = "matrix", stiffness = [[1, 2], [3, 4]] }}', "6×6"),
        (
            '{{ type = "matrix", stiffness = {I}, mass = {B} }}',
            "mass: the matrix is not positive semi|mass: the matrix its",
        ),
        ('{{ type = "rectangle", h = 1, w = 1, shear_centre = [1] }}', "shear_centre"),
    ],
)
def test_bad_matrix_sections_name_the_file_key_and_station(section, message):
    I = _rows(np.diag(DIAG))
    B = _rows(np.diag([1.0, 1, 1, 1, 1, -1]))
    text = section.format(I=I, B=B)
    with pytest.raises(SceneError, match="blade.toml: beams\\[0\\].section") as e:
        _parse(text.replace("{{", "{").replace("}}", "}"))
    assert __import__("re").search(message, str(e.value)), str(e.value)


TWIST = """
[[beams]]
name = "b"
curve = {{ shape = "line", start = [0, 0, 0], end = [4, 0, 0] }}
section = {{ type = "general", EA = 1, GA_y = 1, GA_z = 1, GJ = 1, EI_y = 1, EI_z = 1 }}
twist_deg = {twist}
[[supports]]
at = "b:start"
fix = "all"
"""


@pytest.mark.parametrize(
    "twist, at_1",
    [("13.5", 13.5), ('"10 * s / L"', 2.5), ("{ s = [0, 2, 4], values = [0, 20, 0] }", 10.0)],
)
def test_twist_deg_is_a_number_an_expression_or_a_table_of_s(twist, at_1):
    import tomllib

    from beamfx.geometry.frames import section_axes_at

    beam = parse_scene(tomllib.loads(TWIST.format(twist=twist)), "blade.toml").model.beams[0]
    value = beam.twist_deg(np.array([1.0]))[0] if callable(beam.twist_deg) else beam.twist_deg
    assert np.isclose(value, at_1)
    frame = section_axes_at(beam.curve, 1.0, beam.orientation, beam.twist_deg)
    assert np.isclose(np.degrees(np.arctan2(frame[2, 1], frame[1, 1])), at_1)


def test_a_bad_twist_expression_names_the_key():
    import tomllib

    with pytest.raises(SceneError, match="beams\\[0\\].twist_deg: .*unknown name 'x'"):
        parse_scene(tomllib.loads(TWIST.format(twist='"x * 2"')), "blade.toml")


def test_a_bad_hub_names_the_key():
    import tomllib

    text = (
        TWIST.format(twist="0") + '[analysis]\ntype = "rotating"\nspeed_rad_s = 1\nhub = [1, 2]\n'
    )
    with pytest.raises(SceneError, match="analysis.hub: expected a named point or \\[x, y, z\\]"):
        parse_scene(tomllib.loads(text), "blade.toml")
    text = text.replace("hub = [1, 2]", "hub = [-1.5, 0, 0]")
    assert parse_scene(tomllib.loads(text), "blade.toml").settings.hub == (-1.5, 0.0, 0.0)
