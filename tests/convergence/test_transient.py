"""Transient dynamics: temporal order, energy balance, steady spin, restart, bad input."""

import json
from dataclasses import replace

import numpy as np
import pytest
from scenekit import CLAMP, RHO, E, G, cantilever, flying_spaghetti, spun_beam

from beamfx.analyses.model import BeamModel
from beamfx.analyses.static import solve_static
from beamfx.analyses.transient import TransientFailed, TransientSettings, solve_transient
from beamfx.analyses.transient_run import motion_warnings
from beamfx.geometry import Line
from beamfx.io import evaluate_points
from beamfx.physics.kinematics import Kinematics
from beamfx.physics.sections import tube
from beamfx.scene import SceneError
from beamfx.scene.load import parse_scene
from beamfx.spec import Beam, Model, PointLoad, Support


def tip_after(model, settings):
    model.reset()
    result = solve_transient(model, settings)
    return np.array(evaluate_points(model, ["b:end"])["b:end"]["position"]), result


@pytest.mark.parametrize(
    "scheme",
    [
        {"scheme": "generalized_alpha", "rho_inf": 0.8},
        {"scheme": "hht", "hht_alpha": 0.1},
        {"scheme": "newmark"},
        {"scheme": "conserving"},
    ],
)
def test_second_order_in_time(scheme):
    """Tip position at t = 0.1 s after a smooth load pulse (tip deflection ~5 % of the length,
    geometrically nonlinear): the error against a 16 times finer step falls as h²."""
    model = BeamModel(cantilever(), extra_points=["b:end"])
    base = TransientSettings(t_end=0.1, dt=0.1, easy_iterations=99, **scheme)
    hs = [0.1 / 80, 0.1 / 160, 0.1 / 320]  # asymptotic from about 1/80 (1/40 gives 1.6)
    ref, _ = tip_after(model, replace(base, dt=hs[-1] / 8))
    errors = [np.linalg.norm(tip_after(model, replace(base, dt=h))[0] - ref) for h in hs]
    orders = np.diff(np.log(errors)) / np.diff(np.log(hs))
    assert np.all((orders > 1.85) & (orders < 2.3)), (errors, orders)


def test_energy_balance_and_numerical_dissipation():
    """Undamped: the work of the load equals kinetic plus strain energy up to the
    integrator's numerical dissipation. With ρ∞ = 1 (trapezoidal rule, energy-conserving for
    linear systems) that is small and falls with h; ρ∞ = 0.5 dissipates clearly more."""
    model = BeamModel(cantilever(), extra_points=["b:end"])
    settings = TransientSettings(t_end=0.1, dt=0.1, rho_inf=1.0, easy_iterations=99)
    residual = []
    for h in (0.1 / 40, 0.1 / 80):
        _, result = tip_after(model, replace(settings, dt=h))
        e = result.steps[-1].energy
        assert e["work_loads"] > 0.1  # the pulse did work
        residual.append(abs(e["numerical"]) / e["work_loads"])
    assert residual[0] < 1e-3
    assert residual[1] < 0.75 * residual[0], residual
    _, result = tip_after(model, replace(settings, dt=0.1 / 40, rho_inf=0.5))
    e = result.steps[-1].energy
    assert e["numerical"] > 5 * residual[0] * e["work_loads"]


def test_damped_motion_settles_to_the_static_answer():
    """A load switched on at t = 0 with stiffness-proportional damping: the motion dies out
    at the static deflection; the damping dissipates what the load put in minus the strain
    energy stored."""
    always = np.ones_like
    spec = cantilever(history=always)
    model = BeamModel(spec, extra_points=["b:end"])
    solve_static(model, steps=4)
    static = np.array(evaluate_points(model, ["b:end"])["b:end"]["position"])
    # a1 = 2ζ/ω1 with ζ = 1 on the first mode (ω1 ≈ 90 rad/s)
    settings = TransientSettings(t_end=0.6, dt=0.005, damping_stiffness=2 / 90, rho_inf=0.8)
    tip, result = tip_after(model, settings)
    assert np.linalg.norm(tip - static) < 1e-6 * np.linalg.norm(static)
    e = result.steps[-1].energy
    assert e["dissipated_damping"] > 0
    balance = e["work_loads"] - e["dissipated_damping"] - e["kinetic"] - e["strain"]
    assert abs(balance - e["numerical"]) < 1e-9 * e["work_loads"]
    assert abs(e["numerical"]) < 0.02 * e["dissipated_damping"]


SPIN = spun_beam(
    "where(t < 15, (6/15) * (t**2/2 + (15/(2*pi))**2 * (cos(2*pi*t/15) - 1)), 6*t - 45)",
    18.0,
    dt=0.0125,
    plane="xy",
)


def test_spin_up_reaches_the_centrifugal_stretch(tmp_path):
    """Spin-up (Simo & Vu-Quoc): after 15 s the beam spins at Ω = 6 rad/s; its tip's mean
    axial displacement in the hub frame is the stretch of a bar under its centrifugal load,
    u(L) = ρA Ω² L³ / (3 EA) (to O(strain) = 1e-4 relative, plus the residual vibration)."""
    from beamfx.runner import run_scene

    (tmp_path / "spin.toml").write_text(SPIN)
    run_scene(tmp_path / "spin.toml", tmp_path / "out", log=lambda m: None)
    data = np.genfromtxt(tmp_path / "out" / "probes.csv", delimiter=",", names=True)
    t = data["time"]
    psi = 6 * t - 45
    axial = np.cos(psi) * data["tip_x"] + np.sin(psi) * data["tip_y"] - 10.0
    late = t > 15.0
    expected = 1.2 * 36 * 10**3 / (3 * 2.8e7)
    assert np.mean(axial[late]) == pytest.approx(expected, rel=1e-3)
    # tip rotation relative to the hub: small, and the hub turned by 6*18 - 45 = 63 rad
    relative = data["tip_rot_z"][late] - psi[late]
    assert np.max(np.abs(relative)) < 0.01
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    assert results["time_steps"] == len(t) - 1


def test_restart_goes_on_where_the_run_stopped(tmp_path):
    """A run stopped at t = 0.04 and restarted to 0.08 equals one run to 0.08."""
    from scenekit import run_whole_and_restarted

    def scene(t_end):
        return SPIN.replace("t_end = 18.0", f"t_end = {t_end}").replace(
            "dt = 0.0125", "dt = 0.005\ncheckpoint_every = 3\noutput_every = 2"
        )

    whole, parts = run_whole_and_restarted(tmp_path, scene(2.0), scene(1.0))
    assert len(parts) == len(whole)
    assert np.allclose(parts["tip_y"], whole["tip_y"], rtol=0, atol=1e-12)
    results = json.loads((tmp_path / "parts" / "results.json").read_text())
    assert results["restarted_from"] == pytest.approx(1.0)
    pvd = (tmp_path / "parts" / "deformed.pvd").read_text()
    assert pvd.count("<DataSet") == (tmp_path / "whole" / "deformed.pvd").read_text().count(
        "<DataSet"
    )


def test_bad_history_names_the_key():
    data = {
        "beams": [{"name": "b", "curve": {"shape": "line", "start": [0, 0, 0], "end": [1, 0, 0]},
                   "section": {"type": "general", "EA": 1, "GA_y": 1, "GA_z": 1, "GJ": 1,
                               "EI_y": 1, "EI_z": 1}}],
        "supports": [{"at": "b:start", "fix": "all", "history": "sin(omega * t)"}],
    }  # fmt: skip
    with pytest.raises(SceneError, match=r"supports\[0\]\.history.*unknown name 'omega'"):
        parse_scene(data, "x.toml")
    data["supports"][0]["history"] = "1"
    data["analysis"] = {"type": "transient", "t_end": 1.0, "dt": 0.1, "rho_inf": 2.0}
    with pytest.raises(SceneError, match=r"analysis\.rho_inf.*\[0, 1\]"):
        parse_scene(data, "x.toml")


def test_discontinuous_prescribed_motion_warns():
    def model(history):
        sup = Support("b:start", CLAMP, displacement=(0.0, 0.01, 0.0), history=history)
        return replace(cantilever(), supports=(sup,))

    step = model(lambda t: np.where(np.asarray(t) < 0.5, 0.0, 1.0))
    kink = model(lambda t: np.maximum(np.asarray(t) - 0.5, 0.0))
    jolt = model(lambda t: np.sin(10 * np.asarray(t)))  # starts moving at once from rest
    smooth = model(lambda t: 1 - np.cos(10 * np.asarray(t)))
    assert "jumps" in motion_warnings(step, 1.0)[0]
    assert "inside the run" in motion_warnings(kink, 1.0)[0]
    assert "at t = 0" in motion_warnings(jolt, 1.0)[0]
    assert motion_warnings(smooth, 1.0) == []


def test_a_step_newton_cannot_take_stops_cleanly(tmp_path):
    """A huge sudden load with two Newton iterations allowed: cut-backs down to dt_min, then
    a clear error with the residual history, and the last good state checkpointed."""
    spec = cantilever(history=np.ones_like, force=(0.0, 0.0, 5e5))
    model = BeamModel(spec, extra_points=["b:end"])
    settings = TransientSettings(t_end=0.01, dt=0.01, dt_min=0.002)
    saved = []
    with pytest.raises(TransientFailed, match=r"(?s)from t = 0\b.*dt_min.*residuals"):
        solve_transient(
            model, settings, options={"snes_max_it": 2}, checkpoint=lambda *s: saved.append(s)
        )
    assert saved and saved[-1][0]["t"] == 0.0 and saved[-1][0]["step"] == 0


@pytest.mark.parametrize("rho_inf", [1.0, 0.8])
def test_flying_spaghetti_keeps_its_momentum(rho_inf):
    """Free flight after the pulse: the linear momentum is the impulse (20, 0, 0) and stays
    so to round-off (the inertia forces sum to zero each step; with ρ∞ < 1 the auxiliary
    acceleration carries the end of the pulse over a few steps, so check from t = 10 s);
    the angular momentum and the energy are not exactly conserved by generalized-α but stay
    within 1e-3 over 25 s of free flight, with no drift or blow-up (the beam turns about
    twice; its slowest flexible mode has a period of about 2.5 s)."""
    model = BeamModel(flying_spaghetti(), extra_points=["b:end"])
    settings = TransientSettings(t_end=30.0, dt=0.05, rho_inf=rho_inf, checkpoint_every=0)
    records = []
    solve_transient(model, settings, on_step=records.append)
    free = [r for r in records if r.time > 10.0]
    p = np.array([r.energy["linear_momentum"] for r in free])
    assert np.allclose(p, [20.0, 0.0, 0.0], rtol=0, atol=1e-9 * 20)
    E = np.array([r.energy["kinetic"] + r.energy["strain"] for r in free])
    L = np.array([r.energy["angular_momentum"][2] for r in free])
    assert np.all(np.isfinite(E))
    assert np.ptp(E) < 1e-3 * E[0] and np.ptp(L) < 1e-3 * abs(L[0])
    assert abs(E[-1] - E[0]) < 1e-4 * E[0]  # no drift


def test_tip_mass_swings_at_its_frequency():
    """A heavy tip mass on a light cantilever, released from a small static deflection:
    the tip oscillates at ω = sqrt(3EI/(m L³)) (beam mass 1e-4 of m shifts it by ~1e-5)."""
    from beamfx.spec import PointMass

    section = replace(tube(E, G, RHO, 0.02), rho_A=1e-4, rho_I=(1e-10, 1e-10, 1e-10))
    beam = Beam("b", Line((0, 0, 0), (1.0, 0, 0)), section, 4, 3)
    m = 1.0
    spec = Model(
        (beam,),
        (Support("b:start", CLAMP),),
        (PointLoad("b:end", (0.0, 0.0, 1.0), history=lambda t: (np.asarray(t) <= 0) * 1.0),),
        point_masses=(PointMass("b:end", m),),
        kinematics=Kinematics(plane="xz"),
    )
    model = BeamModel(spec, extra_points=["b:end"])
    solve_static(model, steps=1)  # the static deflection under 1 N at t = 0
    omega = np.sqrt(3 * section.EI_y / (m * 1.0**3))
    period = 2 * np.pi / omega
    z = []

    def record(r):
        z.append((r.time, evaluate_points(model, ["b:end"])["b:end"]["displacement"][2]))

    settings = TransientSettings(t_end=3 * period, dt=period / 200, rho_inf=1.0)
    solve_transient(model, settings, on_step=record)
    t, uz = np.array(z).T
    up = np.nonzero((uz[:-1] < 0) & (uz[1:] >= 0))[0]  # upward zero crossings
    crossings = t[up] - uz[up] * (t[up + 1] - t[up]) / (uz[up + 1] - uz[up])
    measured = 2 * np.pi / np.mean(np.diff(crossings))
    # the trapezoidal rule lengthens the period by (ωh)²/12 = 8e-5 at 200 steps per period
    assert measured == pytest.approx(omega, rel=3e-4)


def test_error_control_carries_the_spin_up_through_large_steps():
    """At dt = 0.05 s with fixed-size steps the spin-up fails near t = 14 s (the axial mode,
    ω ≈ 760 rad/s, is aliased at ωh ≈ 38 and grows through the nonlinear coupling). With a
    local error tolerance the same largest step runs through: the estimate shortens the steps
    where the motion needs it, and the late stretch matches the centrifugal stretch by hand
    (ρAΩ²L³/3EA; the converged model differs from it by 2e-4)."""
    from beamfx.bench.transient import HAND_STRETCH, _run, spin_up_measure, spin_up_model

    settings = TransientSettings(t_end=18.0, dt=0.05, tolerance=1e-5, checkpoint_every=0)
    _, history, result = _run(spin_up_model(4, 2), settings, "b:end")
    steps = np.array([r.dt for r in result.steps])
    assert steps.min() < 0.25 * settings.dt and np.isclose(steps.max(), settings.dt)
    stretch = spin_up_measure(history)["stretch_mean_15_18"]
    assert stretch == pytest.approx(HAND_STRETCH, rel=2e-3)


def test_error_control_error_falls_with_the_tolerance():
    """The cantilever pulse with error control: ten times smaller a tolerance gives a clearly
    smaller error (a second-order method under local error control: about 10^(2/3))."""
    model = BeamModel(cantilever(), extra_points=["b:end"])
    base = TransientSettings(t_end=0.1, dt=0.01, checkpoint_every=0)
    ref, _ = tip_after(model, replace(base, dt=0.1 / 2560))
    errors, steps = [], []
    for tol in (1e-4, 1e-5, 1e-6):
        tip, result = tip_after(model, replace(base, tolerance=tol))
        errors.append(np.linalg.norm(tip - ref))
        steps.append(len(result.steps))
    assert errors[0] > 3 * errors[1] > 9 * errors[2], errors
    assert steps[0] < steps[1] < steps[2]


def test_gravity_swings_a_tip_mass_about_its_static_sag():
    """A heavy tip mass on a light cantilever (beam mass 1e-4 of it), at rest when gravity
    comes on: the tip swings between 0 and twice the static sag m g L³/3EI (u = −u_s (1 − cos
    ωt)). The trapezoidal rule (rho_inf = 1) keeps the amplitude of a linear oscillator; the
    sampled lowest point misses the true one by at most (π/100)²/2 = 5e-4 at 100 steps per
    period, the beam's mass shifts it by ~1e-4: 1e-3 allowed. Without the weight of the mass
    the tip would barely move (the beam's own weight: 4e-5 of that sag)."""
    from beamfx.spec import PointMass

    section = replace(tube(E, G, RHO, 0.02), rho_A=1e-4, rho_I=(1e-10, 1e-10, 1e-10))
    beam = Beam("b", Line((0, 0, 0), (1.0, 0, 0)), section, 4, 3)
    m, g = 1.0, 9.81
    spec = Model(
        (beam,),
        (Support("b:start", CLAMP),),
        point_masses=(PointMass("b:end", m),),
        gravity=(0.0, 0.0, -g),
        kinematics=Kinematics(finite=False, plane="xz"),
    )
    model = BeamModel(spec, extra_points=["b:end"])
    omega = np.sqrt(3 * section.EI_y / m)
    sag = m * g / (3 * section.EI_y)
    z = []

    def record(r):
        z.append(evaluate_points(model, ["b:end"])["b:end"]["displacement"][2])

    period = 2 * np.pi / omega
    solve_transient(model, TransientSettings(t_end=period, dt=period / 100, rho_inf=1.0), record)
    assert abs(min(z) / (-2 * sag) - 1) < 1e-3, (min(z), -2 * sag)
