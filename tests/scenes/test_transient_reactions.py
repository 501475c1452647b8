"""Transient support reactions (beamfx.analyses.transient_reactions) through ``beamfx run``:
reactions.csv at the output steps, balanced with the applied loads and the inertia forces.

Tolerance, derived: the step's residual is zero at the free dofs up to where Newton stopped,
‖F_free‖ (the ``free_residual`` column), and Σ reactions + Σ loads − Σ inertia is minus the sum
of those free rows by the rigid motions (the strain energy is invariant under them, up to
round-off); for the forces that sum is at most √N ‖F_free‖ (Cauchy–Schwarz over the N
unknowns), for the moments about the origin at most √N ‖F_free‖ (1 + max |x|). Round-off adds
a few ε of the largest force.
"""

import csv
import json
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from scenekit import spun_beam

from beamfx.runner import run_scene

CANTILEVER = """
[material]
E = 210e9
nu = 0.3
rho = 7850
[[beams]]
name = "b"
curve = { shape = "line", start = [0, 0, 0], end = [1, 0, 0] }
section = { type = "tube", d = 0.02, d_inner = 0.0 }
elements = 2
degree = 2
[[supports]]
at = "b:start"
fix = "all"
[[springs]]
at = "b:0.5"
stiffness = [0, 0, 2e3]
[[loads]]
at = "b:end"
force = [0, 300, 400]
moment = [10, 0, 0]
history = "where(t < 0.05, 0.5 * (1 - cos(2 * pi * t / 0.05)), 0)"
[analysis]
type = "transient"
t_end = 0.1
dt = 0.0025
output_every = 1
[[probes]]
name = "tip"
at = "b:end"
"""


def rows_of(folder):
    """reactions.csv as {column: array}, and the reaction points' names."""
    with (folder / "reactions.csv").open() as f:
        rows = list(csv.DictReader(f))
    data = {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}
    points = [k[:-3] for k in rows[0] if k.endswith("_fx")]
    return data, points


def vec(data, key):
    return np.stack([data[f"{key}{c}"] for c in "xyz"], axis=1)


def sums(data, points):
    """Σ reactions (force, moment about the origin) per row."""
    force, moment = 0.0, 0.0
    for p in points:
        f, x = vec(data, f"{p}_f"), vec(data, f"{p}_")
        force, moment = force + f, moment + vec(data, f"{p}_m") + np.cross(x, f)
    return force, moment


def check_balance(data, points, unknowns, length):
    """Σ reactions + Σ loads − Σ inertia within the bound of the module docstring, per row."""
    force, moment = sums(data, points)
    force_gap = force + vec(data, "applied_f_") - vec(data, "inertia_f_")
    moment_gap = moment + vec(data, "applied_m_") - vec(data, "inertia_m_")
    largest = max(np.abs(vec(data, "inertia_f_")).max(), np.abs(vec(data, "applied_f_")).max())
    bound = np.sqrt(unknowns) * data["free_residual"] + 1e-13 * largest
    assert np.all(np.linalg.norm(force_gap, axis=1) <= bound), (force_gap, bound)
    assert np.all(np.linalg.norm(moment_gap, axis=1) <= bound * (1 + length))
    return force_gap


@pytest.mark.parametrize(
    "scheme",
    [
        "",
        'scheme = "hht"',
        'scheme = "newmark"',
        'scheme = "conserving"',
        # its forms compile for about 2 min in a cold JIT cache (2 s warm)
        pytest.param("damping = { mass = 20.0, stiffness = 1e-4 }", marks=pytest.mark.slow),
    ],
)
def test_cantilever_reactions_balance_the_tip_load_and_the_inertia(tmp_path, scheme):
    """A clamped tube (and a spring to ground) under a tip force and moment pulse: every step
    is an output step; the balance holds at each, at t_{n+1} for every scheme (Arnold–Brüls
    form), with the damping forces counted with the inertia; the inertia force is a large part
    of it (leaving it out would miss by more than a third of the load)."""
    (tmp_path / "c.toml").write_text(
        CANTILEVER.replace("output_every = 1", f"output_every = 1\n{scheme}")
    )
    lines = []
    run = run_scene(tmp_path / "c.toml", tmp_path / "out", log=lines.append)
    data, points = rows_of(tmp_path / "out")
    assert points == ["b:start", "b:0.5"]
    assert len(data["step"]) == run["time_steps"] == 40
    check_balance(data, points, run["model"]["unknowns"], 1.0)
    applied = vec(data, "applied_f_")
    t = data["time"]
    pulse = np.where(t < 0.05, 0.5 * (1 - np.cos(2 * np.pi * t / 0.05)), 0.0)
    assert np.allclose(applied, pulse[:, None] * [0, 300, 400], rtol=0, atol=1e-9)
    inertia = np.linalg.norm(vec(data, "inertia_f_"), axis=1)
    assert inertia.max() > 0.3 * 500  # the inertia force: large against the load
    force, _ = sums(data, points)
    static_gap = np.linalg.norm(force + applied, axis=1)  # the balance without inertia
    assert static_gap.max() > 0.3 * 500
    # results.json: the last row, the largest balance residuals, the peaks of each point
    saved = json.loads((tmp_path / "out" / "results.json").read_text())
    last = saved["reactions"]["b:start"]
    assert np.allclose(last["force"], vec(data, "b:start_f")[-1], rtol=1e-11)
    balance = saved["reaction_balance"]
    assert balance["max_force"] == pytest.approx(data["balance_force"].max(), rel=1e-9)
    assert balance["max_force"] < 1e-8 and balance["max_moment"] < 1e-8
    history = saved["reaction_history"]
    assert history["csv"] == "reactions.csv" and history["rows"] == 40
    peak = np.linalg.norm(vec(data, "b:start_f"), axis=1)
    assert history["peaks"]["b:start"]["force"] == pytest.approx(peak.max(), rel=1e-9)
    assert history["peaks"]["b:start"]["force_time"] == pytest.approx(t[np.argmax(peak)])
    assert any("balance with the applied loads and the inertia forces" in x for x in lines)


SPIN = spun_beam(
    "where(t < 15, (6/15) * (t**2/2 + (15/(2*pi))**2 * (cos(2*pi*t/15) - 1)), 6*t - 45)",
    1.5,
    dt=0.0125,
    plane="xy",
).replace("dt = 0.0125", "dt = 0.0125\noutput_every = 2")


def test_spin_up_hub_torque_balances_the_inertia_and_does_the_work(tmp_path):
    """The spin-up (demos/scenes/spin_up.toml, its first 1.5 s): no load, so the hub's
    reaction balances the inertia forces alone, at the output steps (every 2nd step). The
    hub's torque about z times the hub's rate ψ'(t), integrated over the rows (trapezoidal
    rule on steps of 0.025 s: error ~ Δt² ω² / 12 ≈ 1e-3 with the first bending frequency
    ω ≈ 3.8 rad/s), is the work of the prescribed motion that the energy balance sums from the
    residual at every step (``work_supports``)."""
    (tmp_path / "s.toml").write_text(SPIN)
    run = run_scene(tmp_path / "s.toml", tmp_path / "out", log=lambda m: None)
    data, points = rows_of(tmp_path / "out")
    assert points == ["beam:start"]
    assert len(data["step"]) == 60
    assert np.all(vec(data, "applied_f_") == 0)
    check_balance(data, points, run["model"]["unknowns"], 10.0)
    t = np.r_[0.0, data["time"]]
    psi_d = (6 / 15) * (t - 15 / (2 * np.pi) * np.sin(2 * np.pi * t / 15))
    power = np.r_[0.0, data["beam:start_mz"]] * psi_d
    work = float(np.sum(0.5 * (power[1:] + power[:-1]) * np.diff(t)))
    assert work > 0
    assert work == pytest.approx(run["energy"]["work_supports"], rel=3e-3)
    assert np.allclose(vec(data, "inertia_m_")[:, 2], data["beam:start_mz"], rtol=1e-8)


def test_reaction_rows_at_every_step_when_asked(tmp_path):
    """``[output] reaction_rows = "steps"``: a row of reactions.csv at every time step, those
    of the frame steps the default run's rows to the last digit; the ParaView reactions stay
    at the frames."""
    short = SPIN.replace("output_every = 2", "output_every = 4").replace(
        "t_end = 1.5", "t_end = 0.5"
    )
    (tmp_path / "frames.toml").write_text(short)
    (tmp_path / "steps.toml").write_text(short + '\n[output]\nreaction_rows = "steps"\n')
    for name in ("frames", "steps"):
        run_scene(tmp_path / f"{name}.toml", tmp_path / name, log=lambda m: None)
    lines = {
        n: (tmp_path / n / "reactions.csv").read_text().splitlines() for n in ("frames", "steps")
    }
    assert len(lines["frames"]) == 1 + 10 and len(lines["steps"]) == 1 + 40
    assert lines["steps"][0] == lines["frames"][0]
    assert lines["steps"][4::4] == lines["frames"][1:]  # steps 4, 8, ..., 40
    for name in ("frames", "steps"):
        root = ET.parse(tmp_path / name / "reactions.pvd").getroot()
        assert [d.get("file") for d in root.iter("DataSet")] == [
            f"reactions_{k:04d}.vtu" for k in range(4, 41, 4)
        ]


def test_restart_cuts_and_continues_the_series(tmp_path):
    """A run stopped at t = 0.25 s and restarted to 0.5 s writes the rows and peaks of one
    run to 0.5 s (rows past the checkpoint are cut away first)."""
    quiet = {"log": lambda m: None}
    short = SPIN.replace("t_end = 1.5", "t_end = 0.25").replace(
        "\noutput_every", "\ncheckpoint_every = 4\noutput_every"
    )
    (tmp_path / "a.toml").write_text(short.replace("t_end = 0.25", "t_end = 0.5"))
    (tmp_path / "b.toml").write_text(short)
    whole = run_scene(tmp_path / "a.toml", tmp_path / "whole", **quiet)
    run_scene(tmp_path / "b.toml", tmp_path / "parts", **quiet)
    with (tmp_path / "parts" / "reactions.csv").open("a") as f:
        f.write("99,0.3,1,2,3\n")  # a row cut short by a killed run: dropped
    parts = run_scene(tmp_path / "a.toml", tmp_path / "parts", restart=True, **quiet)
    a, _ = rows_of(tmp_path / "whole")
    b, _ = rows_of(tmp_path / "parts")
    assert np.array_equal(a["step"], b["step"]) and len(a["step"]) == 20
    assert np.allclose(b["beam:start_mz"], a["beam:start_mz"], rtol=1e-9, atol=1e-12)
    peaks = [r["reaction_history"]["peaks"]["beam:start"] for r in (parts, whole)]
    assert peaks[0] == pytest.approx(peaks[1], rel=1e-9)
    assert parts["reaction_history"]["rows"] == 20
    # the largest balance residual (relative) is at the first steps: read back from the file
    first = a["balance_force"][:10].max()
    assert first > a["balance_force"][10:].max()
    assert parts["reaction_balance"]["max_force"] == pytest.approx(first, rel=1e-9)


def test_free_flight_inertia_force_is_the_rate_of_the_momentum(tmp_path):
    """The flying spaghetti (no support; tests/scenes/test_free_body.py), its first second
    with trapezoidal steps: Σ loads = Σ inertia forces at every step, and the inertia force
    is the rate of the linear momentum that the energy balance integrates independently
    (∫ ρA u̇ ds): the trapezoidal rule with a constant translational mass gives
    P_{n+1} − P_n = h (I_n + I_{n+1}) / 2 exactly, so to round-off."""
    from test_free_body import SPAGHETTI

    scene = SPAGHETTI.replace("t_end = 5.5", "t_end = 1.0\noutput_every = 1")
    (tmp_path / "f.toml").write_text(scene)
    run = run_scene(tmp_path / "f.toml", tmp_path / "out", log=lambda m: None)
    data, points = rows_of(tmp_path / "out")
    assert points == [] and len(data["step"]) == 20
    check_balance(data, points, run["model"]["unknowns"], 10.0)
    lines = (tmp_path / "out" / "probes.jsonl").read_text().splitlines()
    momentum = np.array([json.loads(x)["energy"]["linear_momentum"] for x in lines])
    inertia = np.vstack([np.zeros(3), vec(data, "inertia_f_")])  # at rest at t = 0
    steps = np.diff(np.r_[0.0, data["time"]])[:, None]
    predicted = steps * 0.5 * (inertia[1:] + inertia[:-1])
    assert np.abs(predicted).max() > 0.1  # the force moved the body
    assert np.allclose(np.diff(momentum, axis=0), predicted, rtol=0, atol=1e-12 * 8)
