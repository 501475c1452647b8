"""Steady states of a speed sweep continued from the previous speed (issue 16): the same
states and frequencies as solved from rest, in fewer Newton iterations."""

import tomllib
from importlib import resources

import numpy as np
import pytest

from beamfx.analyses.campbell import campbell
from beamfx.analyses.model import BeamModel
from beamfx.analyses.rotating import RotatingFrame, solve_steady
from beamfx.analyses.rotating_path import SpeedPath
from beamfx.scene.load import parse_scene

L = 0.479  # the Pai strip's length (m)


def pai_frame(elements=4, degree=2):
    """The pre-curved Pai strip under gravity (beamfx/scenes/pai_rotating.toml), coarse."""
    text = resources.files("beamfx.scenes").joinpath("pai_rotating.toml").read_text()
    data = tomllib.loads(text)
    data["beams"][0].update(elements=elements, degree=degree)
    data["model"] = {"plane": "none", "condense": "none"}
    scene = parse_scene(data, "pai_rotating.toml")
    model = BeamModel(scene.model)
    return model, RotatingFrame(model, (0.0, 0.0, 1.0), (0.0, 0.0, 0.0)), scene.settings.speeds


def tip(model):
    """The strip's tip position (the node farthest from the clamp along y)."""
    from beamfx.analyses.dofs import subspace_dofs

    x = model.W.sub(0).collapse()[0].tabulate_dof_coordinates()
    i = int(np.argmax(x[:, 1]))
    u = [model.w.x.array[subspace_dofs(model.W, 0, c)][i] for c in range(3)]
    return x[i] + np.array(u)


def test_continued_steady_states_are_the_ones_solved_from_rest():
    """Each speed from the previous one's state: the tip agrees with the solve from rest to
    the convergence test's tolerance (residual about 1e-8 of the force scale: 1e-7 L, as the
    static check of test_rotating), and the sweep takes far fewer Newton iterations."""
    model, frame, speeds = pai_frame()
    speeds = speeds[:4]
    path, continued, its_path = SpeedPath(), [], 0
    for speed in speeds:
        its_path += solve_steady(frame, speed, steps=1, path=path).newton_iterations
        continued.append(tip(model))
    rest, its_rest = [], 0
    for speed in speeds:
        its_rest += solve_steady(frame, speed, steps=10).newton_iterations
        rest.append(tip(model))
    frame.destroy()
    assert np.abs(np.array(continued) - np.array(rest)).max() < 1e-7 * L
    assert np.array(continued)[-1, 2] > np.array(continued)[0, 2] + 0.05  # spinning lifts it
    assert 2 * its_path < its_rest, (its_path, its_rest)


def test_continued_sweep_keeps_the_frequencies():
    """The Campbell diagram continued and from rest: the same frequencies to the eigen solver's
    accuracy (a relative change of 1e-13 in the state moves them by about 1e-7 on this
    strip: pep_tol 1e-10 on a badly scaled quadratic problem), so 1e-6."""
    _, frame, speeds = pai_frame()
    speeds = speeds[:3]
    a = campbell(frame, speeds, n_modes=2, steps=1, continued=True)
    b = campbell(frame, speeds, n_modes=2, steps=1, continued=False)
    frame.destroy()
    assert a.stopped_by is None and a.failure is None
    assert np.allclose(a.frequencies_hz, b.frequencies_hz, rtol=1e-6, atol=0)
    its = [sum(s.newton_iterations for s in r.steady) for r in (a, b)]
    assert its[0] < its[1], its


@pytest.mark.parametrize("speeds", [(0.0, 2000.0), (0.0, 1000.0, 12000.0)])
def test_a_continuation_converges_below_the_divergence_speed_and_stops_past_it(speeds):
    """The radial rod of test_rotating (divergence at (π/2) sqrt(E/ρ)/L ≈ 8.1e3 rad/s for
    steel, L = 1 m) continued from 1000 rad/s to 12000 rad/s: no steady state (a folded
    centre line, or the tangent losing definiteness), never a steady state returned."""
    from beamfx.analyses.rotating_checks import NoSteadyState
    from beamfx.bench._builders import CLAMP, straight
    from beamfx.physics import sections
    from beamfx.physics.kinematics import Kinematics
    from beamfx.spec import Beam, Model, Support

    section = sections.rectangle(2.1e11, 2.1e11 / 2.6, 7850.0, 0.02, 0.04)
    spec = Model(
        beams=(Beam("b", straight(1.0), section, 4, 3),),
        supports=(Support("b:start", CLAMP),),
        kinematics=Kinematics(),
    )
    frame = RotatingFrame(BeamModel(spec))
    path = SpeedPath()
    for speed in speeds[:-1]:
        solve_steady(frame, speed, path=path)
    if speeds[-1] < 8.1e3:
        solve_steady(frame, speeds[-1], path=path)
        assert path.states[-1][0] == speeds[-1]
    else:
        with pytest.raises(NoSteadyState):
            solve_steady(frame, speeds[-1], path=path)
    frame.destroy()


def test_a_numerical_failure_of_a_continuation_names_the_speeds_and_is_not_a_stop():
    """Newton with no preconditioner (the 'linear solve' is the identity) fails from 0 to
    100 rad/s: a numerical failure (the tangent is positive definite at the last converged
    state, the one at 0 rad/s). Cut-backs to 1e-4 of the speed step did not help, so the
    remedy is neither load steps nor speeds in between but the model and solver options."""
    from beamfx.analyses.rotating_checks import NoSteadyState
    from beamfx.bench._builders import CLAMP, straight
    from beamfx.physics import sections
    from beamfx.physics.kinematics import Kinematics
    from beamfx.solvers.snes import SolveFailed
    from beamfx.spec import Beam, Model, Support

    section = sections.rectangle(2.1e11, 2.1e11 / 2.6, 7850.0, 0.02, 0.04)
    spec = Model(
        beams=(Beam("b", straight(1.0), section, 4, 3),),
        supports=(Support("b:start", CLAMP),),
        kinematics=Kinematics(),
    )
    frame = RotatingFrame(BeamModel(spec))
    path = SpeedPath()
    solve_steady(frame, 0.0, path=path)
    with pytest.raises(SolveFailed) as caught:
        solve_steady(frame, 100.0, options={"pc_type": "none"}, path=path)
    frame.destroy()
    e = caught.value
    assert not isinstance(e, NoSteadyState)
    assert e.details["speed_rad_s"] == 0.0 and "stays positive definite" in e.details["tangent"]
    assert e.remedy.startswith("not a smaller step") and "[solver] options" in e.remedy
    assert "steps =" not in e.remedy and "more speeds" not in e.remedy
    assert str(e).count(e.remedy) == 1 and "continuing the steady state from 0 to 100" in str(e)


def test_a_continuation_failure_asks_for_speeds_where_it_would_ask_for_load_steps():
    """The load-step remedy of a failed continuation becomes one of intermediate speeds."""
    from beamfx.analyses.rotating_path import _explain
    from beamfx.solvers.convergence import remedy
    from beamfx.solvers.snes import SolveFailed

    fix = remedy("divergence", 40)
    error = SolveFailed(f"Newton failed; remedy: {fix}", (), "divergence", fix)
    _explain(error, 0.0, 100.0)
    assert error.remedy == "smaller load steps: more speeds between 0 and 100 rad/s in speeds_rad_s"
    assert str(error).count(error.remedy) == 1 and "from 0 to 100 rad/s" in str(error)
