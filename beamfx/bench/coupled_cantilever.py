"""A cantilever with a fully coupled 6×6 section: linear tip response against the flexibility
integral of the section (the scene ``beamfx/scenes/coupled_cantilever.toml``).

Linear Timoshenko kinematics, constant C, section axes = global axes, clamp at s = 0, tip
force F and moment M at s = L. The resultant at s is r(s) = (F, M + (L − s) e1 × F), the
strains ε = C⁻¹ r, and θ' = κ, u' = γ + θ × e1 give, with G = C⁻¹,

    (∫γ, ∫κ) = G (F L, M L + ½ L² e1 × F),
    ∫(L − s)(γ, κ) ds = G (½ F L², ½ M L² + ⅓ L³ e1 × F),
    θ(L) = ∫κ,   u(L) = ∫γ + (∫(L − s) κ ds) × e1.

The tip of the quadratic and cubic elements is exact (to round-off), the linear element's
converges as h² (tests/convergence/test_coupled_sections.py checks the same by quadrature on a
skew, twisted beam).
"""

import tomllib
from importlib import resources

import numpy as np

from .registry import register
from .scenes import SceneCase

SCENE = "coupled_cantilever.toml"


def _data():
    return tomllib.loads(resources.files("beamfx.scenes").joinpath(SCENE).read_text())


def flexibility_tip(C, L, F, M):
    """(u(L), θ(L)) of the module doc (section axes)."""
    F, M, e1 = np.asarray(F, float), np.asarray(M, float), np.array([1.0, 0.0, 0.0])
    I0 = np.linalg.solve(C, np.r_[F * L, M * L + L**2 / 2 * np.cross(e1, F)])
    I1 = np.linalg.solve(C, np.r_[F * L**2 / 2, M * L**2 / 2 + L**3 / 3 * np.cross(e1, F)])
    return I0[:3] + np.cross(I1[3:], e1), I0[3:]


def reference():
    """The exact tip displacement and rotation of the shipped scene."""
    data = _data()
    C = np.array(data["beams"][0]["section"]["stiffness"], float)
    load = data["loads"][0]
    u, theta = flexibility_tip(C, 2.0, load["force"], load["moment"])
    return {**{f"u{a}": v for a, v in zip("xyz", u)}, **{f"r{a}": v for a, v in zip("xyz", theta)}}


def _scene(n, p):
    from ..scene.load import parse_scene

    data = _data()
    data["beams"][0].update(elements=n, degree=p)
    return parse_scene(data, SCENE)


def _tip(n, p):
    def read(result):
        tip = result.path[-1]["probes"]["tip"]
        u, th = tip["displacement"], tip["rotation_vector"]
        return {**{f"u{a}": v for a, v in zip("xyz", u)}, **{f"r{a}": v for a, v in zip("xyz", th)}}

    return [(_scene(n, p), read)]


register(
    SceneCase(
        "coupled_cantilever",
        "flexibility integral (exact)",
        "Cantilever with a fully coupled 6x6 section: linear tip displacement and rotation",
        _tip,
        lambda values: values,
        reference(),
        1e-10,
        tuple((n, p) for p in (1, 2, 3) for n in (1, 2, 4, 8, 16)),
        scale=None,
        note="Exact reference: the flexibility integral of the coupled section (module doc). "
        "P2 and P3 tips are exact to round-off on any mesh (the reduced rule integrates the "
        "section-force part, whose resultant is constant under tip loads, exactly); P1 "
        "converges as h².",
    )
)
