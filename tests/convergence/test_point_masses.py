"""Point masses and rotary inertias ([[masses]]): modal analysis against closed-form theory,
objectivity of the rotary part, the kinetic energy for transients, and bad input."""

from dataclasses import replace

import numpy as np
import pytest
import ufl
from scipy.optimize import brentq

from beamfx.analyses.modal import solve_modes
from beamfx.analyses.model import BeamModel
from beamfx.analyses.static import solve_static
from beamfx.bench._builders import CLAMP, straight
from beamfx.physics import sections
from beamfx.physics.inertia import point_kinetic_energy, point_mass_form
from beamfx.physics.kinematics import Kinematics, displacement, spatial_virtual_rotation
from beamfx.scene import SceneError
from beamfx.scene.load import parse_scene
from beamfx.spec import Beam, Model, PointMass, Support

E, NU = 210e9, 0.3
G = E / (2 * (1 + NU))
NO_INERTIA = ((0.0, 0.0, 0.0),) * 3
RIGID = Kinematics(shear=False)  # Euler-Bernoulli limit: penalty 1e8 EI/L^2


def shaft(L, rho_A, d=0.02):
    """Circular steel section whose mass per length (and section inertia with it) is rho_A."""
    s = sections.tube(E, G, 7850.0, d, d_inner=0.0, nu=NU)
    return replace(s, rho_A=rho_A, rho_I=tuple(np.array(s.rho_I) * rho_A / s.rho_A))


def tip_body(section, L, n, p, mass, inertia=NO_INERTIA, kin=RIGID):
    return Model(
        beams=(Beam("b", straight(L), section, n, p),),
        supports=(Support("b:start", CLAMP),),
        kinematics=kin,
        point_masses=(PointMass("b:end", mass, inertia),),
    )


def test_tip_mass_on_a_nearly_massless_cantilever():
    """ω = sqrt(3EI/(m L³)). With beam mass ratio μ = ρAL/m = 1e-6 the beam adds 33/140 of
    its mass (Rayleigh): −½·(33/140)μ = −1.2e-7 in ω; the shear-rigid penalty 1e8 EI/L² adds
    −1.5e-8. Cubic elements represent the static tip-load deflection exactly, so the
    discretisation adds nothing: 5e-7 bounds the sum. Both bending planes (a pair)."""
    m, L = 2.0, 1.0
    s = shaft(L, 1e-6 * m / L)
    r = solve_modes(BeamModel(tip_body(s, L, 2, 3, m)), n_modes=2, rotary="polar")
    theory = np.sqrt(3 * s.EI_y / (m * L**3))
    assert np.allclose(r.omega, theory, rtol=5e-7, atol=0), r.omega / theory - 1


def test_tip_mass_on_a_cantilever_of_equal_mass():
    """Exact Euler-Bernoulli frequency of a cantilever with a tip mass m = ρAL:
    1 + cos β cosh β + (m/ρAL) β (cos β sinh β − sin β cosh β) = 0, ω = β² sqrt(EI/(ρA L⁴)).
    Cubic elements: the eigenvalue error falls as h^6 (1.7e-6 with one element), below 1e-6
    at 2 and 4 elements, above the penalty's conditioning floor (~1e-7)."""
    m, L = 2.0, 1.0
    s = shaft(L, m / L)
    ratio = m / (s.rho_A * L)

    def f(b):
        return (
            1
            + np.cos(b) * np.cosh(b)
            + ratio * b * (np.cos(b) * np.sinh(b) - np.sin(b) * np.cosh(b))
        )

    exact = brentq(f, 0.5, 1.8) ** 2 * np.sqrt(s.EI_y / s.rho_A) / L**2
    for n in (2, 4):
        r = solve_modes(BeamModel(tip_body(s, L, n, 3, m)), n_modes=2, rotary="polar")
        assert np.allclose(r.omega, exact, rtol=1e-6, atol=0), (n, r.omega / exact - 1)


def test_point_inertia_in_torsion():
    """A short shaft (L = 0.1) with a disc of polar inertia J at its end: ω = sqrt(GJ_t/(L J)).
    Torsion is linear along the shaft, exact with any element; the shaft's own polar inertia
    (ratio 1e-6 to J) lowers ω by a sixth of that, 1.7e-7. Bending has (almost) no mass, so
    the torsional mode is the lowest."""
    L, J = 0.1, 1e-3
    s = shaft(L, 1.0)
    s = shaft(L, s.rho_A * 1e-6 * J / (s.rho_I[0] * L))
    inertia = ((J, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    r = solve_modes(BeamModel(tip_body(s, L, 2, 2, 0.0, inertia, Kinematics())), n_modes=1)
    theory = np.sqrt(s.GJ / (L * J))
    assert abs(r.omega[0] / theory - 1) < 5e-7, r.omega[0] / theory - 1


def test_rotary_inertia_turns_with_the_section():
    """A beam turned rigidly by its clamp (rotation vector (0.3, -0.5, 0.7) rad, a static solve)
    has the frequencies of the unturned beam, because J = R J0 Rᵀ turns with it. The check is
    sensitive: permuting J0's axes changes the frequencies by percents."""
    s = replace(
        sections.rectangle(E, G, 7850.0, 0.02, 0.01, nu=NU), rho_A=1e-3, rho_I=(0.0, 0.0, 0.0)
    )
    J0 = np.diag([2e-3, 5e-3, 1e-2])

    def omegas(J, rotation=(0.0, 0.0, 0.0)):
        spec = Model(
            beams=(Beam("b", straight(0.3), s, 4, 3),),
            supports=(Support("b:start", CLAMP, rotation=rotation),),
            point_masses=(PointMass("b:end", 1.0, tuple(map(tuple, J))),),
        )
        model = BeamModel(spec)
        if any(rotation):
            solve_static(model, steps=4)
        return solve_modes(model, n_modes=4).omega

    straight_beam = omegas(J0)
    assert np.allclose(omegas(J0, (0.3, -0.5, 0.7)), straight_beam, rtol=1e-8)
    assert np.max(np.abs(omegas(J0[::-1, ::-1]) / straight_beam - 1)) > 1e-2


def test_point_kinetic_energy_is_half_the_point_mass_form():
    """2 T(u̇, ω) = zᵀ M z for a velocity field z about a turned state: the kinetic energy a
    transient adds at the point agrees with the point's part of the modal mass form."""
    import dolfinx.fem
    import dolfinx.fem.petsc

    J0 = ((3e-3, 1e-4, 0.0), (1e-4, 2e-3, 0.0), (0.0, 0.0, 1e-3))
    model = BeamModel(tip_body(shaft(1.0, 1.0), 1.0, 2, 2, 1.5, J0, Kinematics()))
    rng = np.random.default_rng(1)
    model.w.x.array[:] = rng.normal(size=model.w.x.array.size)
    z = dolfinx.fem.Function(model.W)
    z.x.array[:] = rng.normal(size=z.x.array.size)
    kin, rot = model.kin, ufl.split(model.w)[1]
    z_u, z_rot = ufl.split(z)
    v = ufl.split(ufl.TestFunction(model.W))
    dw = ufl.split(ufl.TrialFunction(model.W))

    def kinetic(pm):
        omega = spatial_virtual_rotation(kin, rot, z_rot)
        return point_kinetic_energy(kin, rot, displacement(kin, z_u), omega, pm.mass, pm.inertia)

    def mass(pm):
        return point_mass_form(kin, rot, v, dw, pm.mass, pm.inertia)

    two_T = 2 * dolfinx.fem.assemble_scalar(
        dolfinx.fem.form(model.discretisation.point_mass_terms(kinetic))
    )
    M = dolfinx.fem.petsc.assemble_matrix(
        dolfinx.fem.form(model.discretisation.point_mass_terms(mass))
    )
    M.assemble()
    y = M.createVecLeft()
    M.mult(z.vector, y)
    assert two_T > 0 and abs(two_T - y.dot(z.vector)) < 1e-12 * two_T, (two_T, y.dot(z.vector))


SCENE = """
[material]
E = 210e9
rho = 7850

[[beams]]
name = "b"
curve = {{ shape = "line", start = [0, 0, 0], end = [1, 0, 0] }}
section = {{ type = "circle", d = 0.02 }}

[[supports]]
at = "b:start"
fix = "all"

[[masses]]
{mass}
"""


def scene(mass):
    import tomllib

    return parse_scene(tomllib.loads(SCENE.format(mass=mass)), "scene.toml")


def test_masses_are_parsed():
    m = scene('at = "b:end"\nmass = 2.0\ninertia = [1e-3, 2e-3, 3e-3]').model.point_masses
    assert m == (PointMass("b:end", 2.0, ((1e-3, 0.0, 0.0), (0.0, 2e-3, 0.0), (0.0, 0.0, 3e-3))),)
    full = "at = 'b:0.5'\ninertia = [[2.0, 0.5, 0], [0.5, 1.0, 0], [0, 0, 1.0]]"
    assert scene(full).model.point_masses[0].inertia[0] == (2.0, 0.5, 0.0)


@pytest.mark.parametrize(
    "body, message",
    [
        ('at = "b:end"\nmass = -2.0', "scene.toml: masses[0].mass: must not be negative, got -2.0"),
        ('at = "tip:end"\nmass = 2.0', "scene.toml: masses[0].at: 'tip:end' names no beam"),
        ('at = "b:end"', "scene.toml: masses[0].mass: give a positive 'mass'"),
        ('at = "b:end"\nmass = 1.0\ninertia = [1, 2]', "scene.toml: masses[0].inertia: expected"),
        (
            'at = "b:end"\ninertia = [[1, 2, 0], [0, 1, 0], [0, 0, 1]]',
            "scene.toml: masses[0].inertia: must be symmetric",
        ),
        (
            'at = "b:end"\ninertia = [1, -1, 1]',
            "scene.toml: masses[0].inertia: must be positive semi-definite",
        ),
        ('at = "b:end"\nmass = 1.0\nmas = 2', "scene.toml: masses[0].mas: unknown key"),
    ],
)
def test_bad_masses_name_the_key(body, message):
    with pytest.raises(SceneError) as e:
        scene(body)
    assert str(e.value).startswith(message), str(e.value)


def bracket(mass, kin, n=8, gravity=(0.0, 0.0, -9.81), inertia=NO_INERTIA):
    """docs/scenes.md's bracket: steel 20 x 10 mm (h along z), 0.5 m, a body at its tip."""
    s = sections.rectangle(E, G, 7850.0, 0.02, 0.01, nu=NU)
    masses = (PointMass("b:end", mass, inertia),) if mass else ()
    spec = Model(
        beams=(Beam("b", straight(0.5), s, n, 3),),
        supports=(Support("b:start", CLAMP),),
        kinematics=kin,
        point_masses=masses,
        gravity=gravity,
    )
    return spec, s


def tip_sag(spec):
    from beamfx.io import evaluate_points

    model = BeamModel(spec, extra_points=["b:end"])
    solve_static(model, steps=1)
    return -(evaluate_points(model, ["b:end"])["b:end"]["position"][2] - 0.0)


def timoshenko_sag(s, L, q, P):
    """Tip deflection of a Timoshenko cantilever under a uniform load q and a tip force P."""
    return (
        q * L**4 / (8 * s.EI_y) + q * L**2 / (2 * s.GA_z) + P * L**3 / (3 * s.EI_y) + P * L / s.GA_z
    )


@pytest.mark.parametrize("kin", [Kinematics(finite=False), Kinematics()], ids=["linear", "finite"])
def test_gravity_weighs_the_point_masses(kin):
    """The docs' 2 kg motor on the 0.5 m bracket sags 6.7e-4 m under gravity (8.6e-5 m of it the
    bracket's own weight): Timoshenko's tip deflection under q = ρA g and P = m g. Its rotary
    inertia adds no weight (the mass centre is the point). Cubic elements give the linear
    Timoshenko cantilever's tip exactly (measured 1e-11: round-off; 1e-9 allowed); finite
    kinematics differ by O((w/L)²) = (1.3e-3)² = 1.8e-6 (measured -1.8e-6; 5e-6 allowed).
    Without the mass's weight the sag would be the bracket's alone (-87 %)."""
    L, m, g = 0.5, 2.0, 9.81
    spec, s = bracket(m, kin, inertia=((1e-3, 0.0, 0.0), (0.0, 2e-3, 0.0), (0.0, 0.0, 2e-3)))
    hand = timoshenko_sag(s, L, s.rho_A * g, m * g)
    assert abs(hand - 6.7e-4) < 1e-5 and abs(timoshenko_sag(s, L, s.rho_A * g, 0) - 8.6e-5) < 1e-6
    total = tip_sag(spec)
    tol = 5e-6 if kin.finite else 1e-9
    assert abs(total / hand - 1) < tol, (total, hand, total / hand - 1)
