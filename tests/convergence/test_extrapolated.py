"""The scheme "extrapolated": Richardson's combination of runs at dt and dt/2 in lockstep."""

from dataclasses import replace

import numpy as np
import pytest
from scenekit import CLAMP, SPIN_HISTORY, cantilever, spun_beam

from beamfx.analyses.model import BeamModel
from beamfx.analyses.transient import TransientSettings, solve_transient
from beamfx.geometry import Line
from beamfx.io import evaluate_points
from beamfx.physics.kinematics import Kinematics
from beamfx.physics.sections import Section
from beamfx.scene import SceneError
from beamfx.scene.load import parse_scene
from beamfx.solvers.integrators import richardson
from beamfx.spec import Beam, Model, PointLoad, Support


def tip_history(model, settings, **kwargs):
    """[(t, tip position)] of every accepted step, and the result."""
    model.reset()
    out = []

    def on_step(r):
        position = evaluate_points(model, ["b:end"])["b:end"]["position"]
        out.append((r.time, np.array(position)))

    result = solve_transient(model, settings, on_step=on_step, **kwargs)
    return out, result


def planar():
    """The cantilever of scenekit in its xy plane (load in y)."""
    return cantilever(force=(0.0, 500.0, 0.0), kin=Kinematics(plane="xy"))


def final_tip(model, settings):
    return tip_history(model, settings)[0][-1][1]


def bump(t):
    """A load pulse on [0, 0.25] s that is C⁵ (sin⁶): a load with a jump in a low derivative
    excites the unresolved stiff modes (axial, shear) of the exact solution, whose error no
    extrapolation removes (measured with sin²: the error stalls near 1e-5)."""
    t = np.asarray(t, float)
    return np.where(t < 0.25, np.sin(np.pi * t / 0.25) ** 6, 0.0)


def soft_cantilever(plane):
    """1 m cantilever, 2 x P2, whose axial and shear modes are slow enough to be resolved
    (EA = GA = 20 EI/m², ρI = 0.5 ρA m²); tip load up to 30 in y (and 20 in z in 3D):
    deflection about 0.1 m, geometrically nonlinear."""
    section = Section(2e3, 2e3, 2e3, 100.0, 100.0, 100.0, 1.0, (1.0, 0.5, 0.5))
    beam = Beam("b", Line((0, 0, 0), (1.0, 0, 0)), section, 2, 2)
    force = (0.0, 30.0, 0.0) if plane == "xy" else (0.0, 30.0, 20.0)
    load = PointLoad("b:end", force, (0.0, 0.0, 0.0), "dead", bump)
    kin = Kinematics(plane="xy") if plane == "xy" else Kinematics()
    return Model((beam,), (Support("b:start", CLAMP),), (load,), kinematics=kin)


@pytest.mark.parametrize(
    "plane, rho_inf, least",
    [("xy", 1.0, 3.5), pytest.param("none", 0.9, 2.5, marks=pytest.mark.slow)],
)
def test_extrapolated_order(plane, rho_inf, least):
    """Tip position at t = 0.5 s. ρ∞ = 1: the trapezoidal rule is symmetric, its global error
    expands as e2 h² + e4 h⁴ + e6 h⁶, the combination removes e2 h², so the error falls as h⁴
    up to a relative O(h²) correction, which from 80 steps on moves the observed order by
    less than 0.5 (measured 3.9, 4.0). ρ∞ < 1 leaves an h³ term of the numerical damping:
    third order at least (measured 3.8, 4.1 in 3D with ρ∞ = 0.8: the term is small). The
    reference at h/2 of the finest adds at most 1/16 to its error (order -0.1)."""
    model = BeamModel(soft_cantilever(plane), extra_points=["b:end"])
    base = TransientSettings(t_end=0.5, dt=0.5, scheme="extrapolated", rho_inf=rho_inf)
    base = replace(base, easy_iterations=99, checkpoint_every=0)
    hs = [0.5 / 40, 0.5 / 80, 0.5 / 160]
    ref = final_tip(model, replace(base, dt=hs[-1] / 2))
    errors = [np.linalg.norm(final_tip(model, replace(base, dt=h)) - ref) for h in hs]
    orders = np.diff(np.log(errors)) / np.diff(np.log(hs))
    assert np.all(orders > least), (errors, orders)
    # the base scheme alone at the finest of these steps: second order, far behind
    plain = final_tip(model, replace(base, dt=hs[-1], scheme="generalized_alpha"))
    assert np.linalg.norm(plain - ref) > 100 * errors[-1], (plain - ref, errors)


def test_lockstep_is_the_combination_of_two_runs():
    """What the scheme shows at each step is exactly 4/3 q(dt/2) − 1/3 q(dt) of two plain
    generalized-α runs (ρ∞ = 0.8), at every shared time (to the Newton tolerance)."""
    model = BeamModel(planar(), extra_points=["b:end"])
    base = TransientSettings(t_end=0.06, dt=0.002, rho_inf=0.8, checkpoint_every=0)
    base = replace(base, easy_iterations=99)
    both, result = tip_history(model, replace(base, scheme="extrapolated"))
    coarse, _ = tip_history(model, base)
    fine, _ = tip_history(model, replace(base, dt=0.001))
    assert len(both) == len(coarse) == 31 and len(fine) == 61  # t = 0 and the steps
    assert result.newton_iterations >= 3 * 30  # three solves per step
    for (t, x), (tc, xc), (tf, xf) in zip(both, coarse, fine[::2]):
        assert abs(t - tc) < 1e-12 and abs(t - tf) < 1e-12
        assert np.linalg.norm(x - richardson(xc, xf)) < 1e-10, (t, x, xc, xf)


def test_restart_goes_on_with_both_copies():
    """A restart from a checkpoint of the scheme resumes both copies: the final state equals
    the one of the run without a stop."""
    model = BeamModel(planar(), extra_points=["b:end"])
    settings = TransientSettings(t_end=0.04, dt=0.002, scheme="extrapolated", rho_inf=0.9)
    settings = replace(settings, easy_iterations=99, checkpoint_every=10)
    saved = []

    def keep(header, arrays):
        saved.append((header, {k: np.array(v, copy=True) for k, v in arrays.items()}))

    straight = tip_history(model, settings, checkpoint=keep)[0][-1][1]
    first = saved[0]
    assert first[0]["step"] == 10 and "fine_q_n" in first[1] and "coarse_v_n" in first[1]
    model.reset()
    solve_transient(model, settings, saved=first)
    again = np.array(evaluate_points(model, ["b:end"])["b:end"]["position"])
    assert np.linalg.norm(again - straight) < 1e-12, (again, straight)


@pytest.mark.parametrize(
    "damping", [(0.0, 0.0), (0.1, 1e-4)], ids=["undamped", "mass-and-stiffness"]
)
def test_restart_is_bit_identical(damping):
    """A run restarted from a checkpoint takes the same floating-point operations as the run
    without a stop: every unknown and the energy balance end bit for bit the same. With
    stiffness damping each copy's strain history (ε_n, ε_{n−1}, ε̇_n and the last step) is
    part of its state: restored from the shown state's instead, the copies' first step
    after the restart was a backward difference from the wrong strains (5e-8 off)."""
    model = BeamModel(planar(), extra_points=["b:end"])
    a0, a1 = damping
    settings = TransientSettings(t_end=0.04, dt=0.002, scheme="extrapolated", rho_inf=0.9)
    settings = replace(settings, checkpoint_every=7, damping_mass=a0, damping_stiffness=a1)
    saved = []

    def keep(header, arrays):
        saved.append((header, {k: np.array(v, copy=True) for k, v in arrays.items()}))

    model.reset()
    whole = solve_transient(model, settings, checkpoint=keep)
    straight = model.w.x.array.copy()
    assert saved[0][0]["step"] == 7
    model.reset()
    again = solve_transient(model, settings, saved=saved[0])
    assert np.array_equal(model.w.x.array, straight), np.abs(model.w.x.array - straight).max()
    assert again.steps[-1].energy == whole.steps[-1].energy, (again.steps[-1], whole.steps[-1])
    if a1:
        assert whole.steps[-1].energy["dissipated_damping"] > 0


def test_scene_keys_are_checked():
    """A tolerance with the fixed-grid scheme, or an unknown scheme, is refused naming the
    file and the key."""
    import tomllib

    text = spun_beam("6 * t", 1.0).replace('type = "transient"', 'type = "transient"\nKEYS')
    bad = tomllib.loads(text.replace("KEYS", 'scheme = "extrapolated"\ntolerance = 1e-5'))
    with pytest.raises(SceneError, match=r"^spin\.toml: .*tolerance.*fixed grid"):
        parse_scene(bad, "spin.toml")
    typo = tomllib.loads(text.replace("KEYS", 'scheme = "extrapolate"'))
    with pytest.raises(SceneError, match=r"^spin\.toml: .*scheme.*'extrapolated'"):
        parse_scene(typo, "spin.toml")
    good = tomllib.loads(text.replace("KEYS", 'scheme = "extrapolated"\nrho_inf = 0.8'))
    settings = parse_scene(good, "spin.toml").settings.solver()
    assert settings.scheme == "extrapolated" and settings.parameters().name.startswith("extra")


def test_scene_run_writes_the_combined_history(tmp_path):
    """``beamfx run`` of a scene with the scheme: results.json names it, probes.csv has a row
    per step of dt (the substeps are not rows). The energy balance's works are trapezoidal
    sums over the shown steps, second order: what it leaves ("numerical") is their
    quadrature error, measured -8.8 J of 10025 J at dt = 0.025, and falls by 4 when dt
    halves (3.5 to 4.5: the trapezoidal rule's h² term with a relative h² correction)."""
    import json

    from beamfx.cli import main

    numerical = []
    for dt in (0.025, 0.0125):
        text = spun_beam(SPIN_HISTORY, 0.5, dt=dt, plane="xy")
        text = text.replace(f"dt = {dt!r}", f'dt = {dt!r}\nscheme = "extrapolated"\nrho_inf = 0.8')
        (tmp_path / "spin.toml").write_text(text)
        out = tmp_path / f"out{dt}"
        assert main(["run", str(tmp_path / "spin.toml"), "--out", str(out)]) in (0, None)
        results = json.loads((out / "results.json").read_text())
        assert results["scheme"].startswith("extrapolated (Richardson h, h/2) generalized-α")
        rows = np.genfromtxt(out / "probes.csv", delimiter=",", names=True)
        assert len(rows) == round(0.5 / dt) + 1 and np.allclose(np.diff(rows["time"]), dt)
        assert rows[-1]["work_supports"] > 5000.0
        numerical.append(rows[-1]["numerical"])
    assert 3.5 < numerical[0] / numerical[1] < 4.5, numerical


def test_cut_back_steps_keep_both_copies_on_one_grid():
    """Newton limited to 2 iterations fails at the larger steps: the step is cut back and
    regrown for both copies together, the run reaches t_end, and the combined answer stays
    far more accurate than the base scheme's under the same limit."""
    model = BeamModel(soft_cantilever("xy"), extra_points=["b:end"])
    base = TransientSettings(t_end=0.5, dt=0.05, scheme="extrapolated", rho_inf=0.8)
    base = replace(base, checkpoint_every=0)
    ref = final_tip(model, replace(base, dt=0.5 / 160, easy_iterations=99))
    limit = {"snes_max_it": 2}
    history, result = tip_history(model, base, options=limit)
    assert sum(r.cutbacks for r in result.steps) > 0
    times = [t for t, _ in history]
    assert abs(times[-1] - 0.5) < 1e-12 and np.all(np.diff(times) > 0)
    plain = tip_history(model, replace(base, scheme="generalized_alpha"), options=limit)[0]
    error, plain_error = (np.linalg.norm(h[-1][1] - ref) for h in (history, plain))
    assert error < plain_error / 10, (error, plain_error)
