"""Structures without supports: a free-free modal analysis and a free flight from rest run as
scenes; the analyses that need supports still refuse them, naming the file."""

import numpy as np
import pytest

from beamfx.runner import run_scene
from beamfx.scene import SceneError

FREE_BEAM = """
[[beams]]
name = "b"
curve = {{ shape = "line", start = [0, 0, 0], end = [2, 0, 0] }}
section = {{ type = "general", EA = 2e11, GA_y = 1e8, GA_z = 1e8, GJ = 1e4, EI_y = 1e4, EI_z = 4e4, rho_A = 2.0, rho_I = [1.2e-3, 4e-4, 8e-4] }}
elements = 8
degree = 3

[model]
shear = false

[analysis]
type = "{analysis}"
{keys}
"""

SPAGHETTI = """
# Simo & Vu-Quoc (1986): a free beam thrown by a force and a moment at one end
[[beams]]
name = "b"
curve = { shape = "line", start = [6, 0, 0], end = [0, 8, 0] }
section = { type = "general", EA = 1e4, GA_y = 1e4, GA_z = 1e4, GJ = 500, EI_y = 500, EI_z = 500, rho_A = 1, rho_I = [20, 10, 10] }
elements = 4
degree = 2

[[loads]]
at = "b:start"
force = [8, 0, 0]
moment = [0, 0, 80]
history = "max(0, min(t / 2.5, (5 - t) / 2.5))"

[analysis]
type = "transient"
t_end = 5.5
dt = 0.05
scheme = "conserving"
"""


def _quiet(*args, **kwargs):
    pass


def test_free_free_modes_are_six_rigid_then_the_free_free_beam(scene_file, tmp_path):
    """Euler-Bernoulli free-free bending (shear-rigid, no bending rotary inertia):
    ω = (4.7300408)² sqrt(EI/(ρA L⁴)), the weak axis first; 8 x P3 is converged far below
    the tolerance (the modal cases of the bench)."""
    path = scene_file(
        FREE_BEAM.format(analysis="modal", keys='modes = 8\nrotary_inertia = "polar"')
    )
    run = run_scene(path, tmp_path / "out", log=_quiet)
    assert run.converged and run.result.rigid_body_modes == 6
    omega = np.array(run.result.omega_rad_s)
    elastic = omega[6:]
    # the rigid modes' ω² are the round-off of a singular K: eps times its largest stiffness
    # (EA and the shear-rigid penalty, ~1e8 EI/L²), ~1e-7 of the first elastic ω² here
    assert np.all(omega[:6] ** 2 < 1e-5 * elastic[0] ** 2)
    exact = 4.730040745**2 * np.sqrt(1e4 / (2.0 * 2.0**4))
    assert elastic[0] == pytest.approx(exact, rel=1e-6)
    assert elastic[1] == pytest.approx(2 * exact, rel=1e-6)  # EI_z = 4 EI_y


def test_a_free_structure_flies_from_rest_with_the_impulse_of_its_load(scene_file, tmp_path):
    """The energy-momentum conserving scheme keeps the linear momentum equal to the impulse of
    the force, ∫ 8 hat(t) dt = 20 (exact for the piecewise-linear hat on this grid); the scene
    is a plane problem, so the planar model is chosen."""
    run = run_scene(scene_file(SPAGHETTI), tmp_path / "out", log=_quiet)
    assert run.converged
    assert run.model["plane"] == "xy"
    momentum = run.result.energy["linear_momentum"]
    assert momentum[0] == pytest.approx(20.0, rel=1e-9)
    assert abs(momentum[1]) < 1e-9 * 20.0


@pytest.mark.parametrize(
    ("analysis", "keys"),
    [("static", ""), ("buckling", ""), ("modal", "")],
)
def test_analyses_that_need_supports_refuse_a_free_structure(scene_file, analysis, keys):
    text = FREE_BEAM.format(analysis=analysis, keys=keys)
    if analysis != "modal":
        text += '\n[[loads]]\nat = "b:end"\nforce = [-1, 0, 0]\n'
    else:  # a pre-stressed modal analysis needs the static solve
        text += '\n[[loads]]\nat = "b:end"\nforce = [1, 0, 0]\n'
    with pytest.raises(SceneError, match=r"scene\.toml: supports: none given"):
        run_scene(scene_file(text), log=_quiet)
