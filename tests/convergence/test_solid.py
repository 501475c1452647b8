"""The 3D solid of a beam: a coarse linear cantilever against beam theory, the face fit, and
the bad-input errors."""

import numpy as np
import pytest

pytest.importorskip("gmsh")

from scenekit import SOLID_SCENE

from beamfx.bench import schwab_meijaard_2009 as sm
from beamfx.bench._builders import straight
from beamfx.geometry import Arc
from beamfx.physics import sections
from beamfx.scene import SceneError
from beamfx.solid.geometry import SolidMesh, SweepError, check_sweep
from beamfx.spec import Beam


def _scene(scene_file, curve, section):
    return scene_file(SOLID_SCENE.format(curve=curve, section=section))


def test_coarse_cantilever_matches_beam_theory():
    """Tip force and end moments on a 2 x 4 x 25 Q2 hexahedral cantilever (SM 2.1).

    Bending by a moment is exact for Q2 up to the clamp's restraint of the Poisson
    contraction (a few 1e-4); the force adds the shear term F L/(k G A) of Timoshenko theory;
    torsion converges slower (warping restrained at the clamp, two cells across the
    thickness): 1 % at this mesh, against the Saint-Venant constant.
    """
    from beamfx.solid.solve import Solid, SolidSpec

    beam = Beam("b", straight(1.0), sm.S21, 1)
    loads = {"end": ((0, 0, sm.F), (sm.MX, sm.MY, 0))}
    solid = Solid(SolidSpec(beam, sm.E, sm.NU, loads=loads, mesh=SolidMesh(2)))
    report = solid.solve_static()
    assert report["load_steps"] == 1
    tip = solid.face_values("end")
    S = sections.rectangle(sm.E, sm.G, sm.RHO, 0.02, 0.01, nu=sm.NU)
    u_z = sm.THEORY_21["u_z"] + sm.F / S.GA_z
    assert tip["displacement"][2] == pytest.approx(u_z, rel=5e-4)
    assert tip["rotation_vector"][1] == pytest.approx(sm.THEORY_21["phi_y"], rel=5e-4)
    assert tip["rotation_vector"][0] == pytest.approx(sm.MX / S.GJ, rel=2e-2)
    assert abs(tip["displacement"][1]) < 1e-6 * abs(u_z)


def test_face_fit_of_a_rigid_motion():
    """The face fit returns a superposed rigid motion exactly: ū = a, θ = b (small)."""
    from beamfx.solid.solve import Solid, SolidSpec

    beam = Beam("b", straight(1.0), sm.S21, 1)
    solid = Solid(SolidSpec(beam, sm.E, sm.NU, mesh=SolidMesh(2, 4)))
    a, b = np.array([1e-3, -2e-3, 3e-3]), np.array([2e-3, 1e-3, -1e-3])
    c = solid.faces["end"]["c"]
    solid.u.interpolate(lambda x: a[:, None] + np.cross(b, (x.T - c)).T)
    v = solid.face_values("end")
    assert np.allclose(v["displacement"], a, atol=1e-12)
    assert np.allclose(v["rotation_vector"], b, atol=1e-12)


def test_tight_arc_cannot_be_swept():
    """Radius 0.1 towards section z, half-height h/2 = 0.15: no; towards y (w/2 = 0.05): yes."""
    section = sections.rectangle(1.0, 0.5, 1.0, 0.3, 0.1)
    beam = Beam("b", Arc((0, 0, 0), (1, 0, 0), (0, 0, 0.1), 90.0), section, 1)
    with pytest.raises(SweepError, match="intersect itself"):
        check_sweep(beam, SolidMesh())
    beam = Beam("b", Arc((0, 0, 0), (1, 0, 0), (0, 0.1, 0), 90.0), section, 1)
    check_sweep(beam, SolidMesh())


def test_tight_arc_error_names_file_and_key(tmp_path, scene_file):
    from beamfx.scene import load_scene
    from beamfx.solid.run import build, spec_from_scene

    path = _scene(
        scene_file,
        '{ shape = "arc", start = [0, 0, 0], start_tangent = [1, 0, 0], centre = [0, 0, 0.05], angle_deg = 90 }',
        '{ type = "rectangle", h = 0.2, w = 0.1 }',
    )
    spec = spec_from_scene(load_scene(path))
    with pytest.raises(SceneError, match=r"scene.toml: beams\[0\].curve: arc radius"):
        build(spec, str(path))


def test_too_coarse_section_names_the_option(tmp_path, scene_file):
    from beamfx.scene import load_scene
    from beamfx.solid.run import build, spec_from_scene

    path = _scene(
        scene_file,
        '{ shape = "line", start = [0, 0, 0], end = [1, 0, 0] }',
        '{ type = "circle", d = 0.02 }',
    )
    spec = spec_from_scene(load_scene(path), mesh=SolidMesh(1, None, "tetrahedron"))
    with pytest.raises(SceneError, match="--section-cells: section_cells = 1 does not resolve"):
        build(spec, str(path))
    spec = spec_from_scene(load_scene(path), mesh=SolidMesh(2, 1, "tetrahedron"))
    with pytest.raises(SceneError, match="--layers: .*too coarse along the centre line"):
        build(spec, str(path))
    spec = spec_from_scene(load_scene(path), mesh=SolidMesh(2, None, "hexahedron"))
    with pytest.raises(SceneError, match="hexahedra need a rectangular section"):
        build(spec, str(path))


@pytest.mark.slow
def test_neo_hookean_small_load_matches_linear():
    """At a small load the neo-Hookean and St Venant–Kirchhoff solids give the linear answer."""
    from beamfx.solid.solve import Solid, SolidSpec

    beam = Beam("b", straight(1.0), sm.S21, 1)
    tips = {}
    for material in ("linear", "svk", "neo-hookean"):
        spec = SolidSpec(
            beam,
            sm.E,
            sm.NU,
            loads={"end": ((0, 0, 1.0), (0, 0, 0))},
            material=material,
            mesh=SolidMesh(2),
        )
        solid = Solid(spec)
        solid.solve_static(steps=1)
        tips[material] = solid.face_values("end")["displacement"][2]
    assert tips["svk"] == pytest.approx(tips["linear"], rel=1e-3)
    assert tips["neo-hookean"] == pytest.approx(tips["linear"], rel=1e-3)


def test_scaling_projection_reproduces_its_measurements():
    """The projection of the 231k solid to more ranks returns the 2-rank measurement at 2
    ranks, halves a perfectly scaling part per doubling, and never undercuts perfect scaling."""
    from beamfx.bench.solid_scaling import project

    def run(ranks, assembly, setup, cg, its):
        parts = {"assembly": assembly, "gamg_setup": setup, "cg": cg, "other": 0.0}
        return {"ranks": ranks, "seconds_in_solve": parts, "krylov_iterations": its}

    one, two = run(1, 3.0, 12.0, 36.0, 200), run(2, 1.5, 6.0, 24.0, 250)
    low, high = project(one, two, 2)
    assert low == pytest.approx(31.5) and high == pytest.approx(31.5)
    perfect = run(2, 1.5, 6.0, 18.0, 200)
    assert project(one, perfect, 8) == pytest.approx((25.5 / 4, 25.5 / 4))
    for p in (4, 8, 16):
        low, high = project(one, two, p)
        assert 31.5 * 2 / p <= low < high


def test_turned_section_is_the_unturned_one_turned():
    """A rectangle turned by twist_deg = 30 about a straight centre line is the same mesh
    turned, so its tip flexibility is R C Rᵀ, with C the unturned one (measured by a force
    along y and one along z) and R the turn of (e2, e3): exact up to round-off. The vertical
    force then moves the tip sideways too, as the beam says (same sign and size)."""
    from beamfx.solid.solve import Solid, SolidSpec

    S = sections.rectangle(sm.E, sm.G, 0.0, 0.2, 0.1, nu=sm.NU)
    F = 1e6

    def tip(twist_deg, force):
        beam = Beam("b", straight(2.0), S, 1, 2, None, twist_deg)
        solid = Solid(SolidSpec(beam, sm.E, sm.NU, loads={"end": (force, (0, 0, 0))}))
        solid.solve_static()
        return np.asarray(solid.face_values("end")["displacement"])

    C = np.column_stack([tip(0, (0, F, 0))[1:], tip(0, (0, 0, F))[1:]]) / F
    c, s_ = np.cos(np.radians(30)), np.sin(np.radians(30))
    R = np.array([[c, -s_], [s_, c]])  # columns: e2, e3 turned about x, in (y, z)
    expected = R @ C @ R.T @ [0, F]
    turned = tip(30, (0, 0, F))
    assert np.allclose(turned[1:], expected, rtol=1e-7, atol=1e-9 * np.abs(expected).max())
    assert turned[1] > 0.3 * turned[2]  # the sideways part is real
    # Euler-Bernoulli: d_y/d_z = cs(1/EI_z - 1/EI_y)/(s²/EI_z + c²/EI_y); shear flexibility
    # (F L/kGA against F L³/3EI: 0.8 % here in the stiff direction) changes it by about 1 %
    ratio = c * s_ * (1 / S.EI_z - 1 / S.EI_y) / (s_**2 / S.EI_z + c**2 / S.EI_y)
    assert turned[1] / turned[2] == pytest.approx(ratio, rel=2e-2)


def test_section_turning_against_an_arc_is_refused():
    """An arc whose orientation vector is neither its axis nor in its plane: the beam's section
    turns against the arc, the revolved solid's would not. Named, not built."""
    from beamfx.solid.geometry import frame_turn_deg
    from beamfx.spec import Beam

    arc = Arc((0, 0, 0), (1, 0, 0), (0, 1, 0), 90)
    section = sections.rectangle(2e11, 8e10, 0.0, 0.2, 0.1)
    assert frame_turn_deg(Beam("b", arc, section, 4, 2)) < 1e-9  # default: z, the axis
    assert frame_turn_deg(Beam("b", arc, section, 4, 2, (0, 1, 0))) < 1e-9  # in the plane
    tilted = Beam("b", arc, section, 4, 2, (0, 1, 1))
    assert frame_turn_deg(tilted) > 1.0
    with pytest.raises(SweepError, match="section axes turn") as e:
        check_sweep(tilted, SolidMesh())
    assert e.value.key == "orientation"
