# # The pre-curved Pai strip shaken at its root while its spin ramps up
#
# Howcroft et al. (2016), section 4.3, "rotating_plus_base": the titanium strip of
# `beamfx/scenes/pai_rotating.toml` (479 × 50.8 × 0.45 mm, pre-curved down to a 30° arc,
# clamped at a hub) settles under gravity at rest; its clamp then moves up and down by ±2 cm
# at 4.5 Hz while the hub's spin about the vertical through the clamp ramps from 0 at 2 s to
# 8 Hz at 10 s. Centrifugal stiffening raises the first (flap) frequency through 4.5 Hz on the
# way: the strip passes through resonance.
#
# Run `python demos/pai_spin_ramp.py --full [--out DIR]` for docs/pai_beam.md: the Campbell
# sweep on three meshes and the 10 s run at dt = 2.5 and 1.25 ms (about 3 minutes on a quiet
# core), the figure pai_spin_ramp.png and tip_history.csv (the tip in the inertial and the
# rotating frame, and its twist, against time). Without `--full` (as the tests run it) a
# sparse sweep on one mesh and the first 0.2 s of the spin ramp on 4 elements at dt = 10 ms.
# The runs' folders (and with `--full` the figure and the CSV) go into results/pai_spin_ramp/
# (results/pai_spin_ramp_short/ without `--full`) under the current folder, or DIR (or
# $BEAMFX_DEMO_OUT/<that name>: the tests set it to a temporary one).

import os
import sys
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

from beamfx.bench import pai_spin_ramp as ps
from beamfx.io import log
from beamfx.runner import run_scene

argv = sys.argv[1:] if __name__ == "__main__" else []
FULL = "--full" in argv or os.environ.get("BEAMFX_DEMO_FULL") == "1"
OUT = Path(argv[argv.index("--out") + 1]) if "--out" in argv else None
NAME = "pai_spin_ramp" if FULL else "pai_spin_ramp_short"
OUT = OUT or Path(os.environ.get("BEAMFX_DEMO_OUT", "results")) / NAME
comm = MPI.COMM_WORLD
OUT = Path(comm.bcast(str(OUT), root=0))
log(f"pai_spin_ramp demo: writes into {OUT}")
SCENE = Path(ps.__file__).parents[1] / "scenes" / "pai_spin_ramp.toml"
quiet = lambda *a, **k: None

# ## Mode 1 against spin
# The rotating analysis finds the steady state at each spin and the frequencies of small
# motions about it in the rotating frame. A sweep every 0.25 Hz, and every 0.01 Hz over
# 3.80–4.00 Hz; the crossing of 4.5 Hz is interpolated linearly in the fine steps.

campbell = {}
SHORT_HZ = (0.0, 1.0, 2.0, 3.0, 3.8, 3.85, 3.9, 3.95, 4.0, 4.05, 6.0, 8.0)
for n, p in ((8, 3), (16, 3), (32, 3)) if FULL else ((8, 3),):
    speeds = None if FULL else SHORT_HZ  # default: ps.sweep_hz(), 53 speeds
    scene = ps.campbell_scene(n, p, speeds_hz=speeds)
    run = run_scene("pai_rotating", OUT / f"campbell_{n}x{p}", log=quiet, scene=scene)
    spins, f1 = ps.lowest(run.result)
    spin, bound = ps.crossing(spins, f1)
    campbell[(n, p)] = run.result
    log(
        f"{n} x P{p}: f1 = {f1[0]:.5f} Hz at rest, {f1[-1]:.5f} Hz at 8 Hz; f1 = 4.5 Hz at "
        f"{spin:.5f} Hz spin (interpolation bound {bound:.1e} Hz)"
    )
assert 3.8 < spin < 4.0 and bound < 1e-4
assert np.all(np.diff(f1) > 0)  # centrifugal stiffening

# ## The run
# The scene file holds the whole manoeuvre: the clamp's displacement [0, 0, 0.02] with its own
# `displacement_history` (4.5 Hz, amplitude ramped in over 1 s) and its rotation [0, 0, 1]
# with `rotation_history` ψ(t) = π (t − 2)²; it starts from the static state under gravity.
# The probes stream to probes.csv as the run goes.

runs = {}
for dt in (0.0025, 0.00125) if FULL else (0.01,):
    scene = ps.ramp_scene(dt=dt) if FULL else ps.ramp_scene(elements=4, dt=dt, t_end=2.2)
    folder = OUT / f"run_dt{dt * 1e3:g}ms"
    t0 = time.perf_counter()
    run = run_scene(SCENE, folder, log=quiet, scene=scene)
    assert run.result.status == "converged", run.result.reason
    comm.barrier()
    runs[dt] = (ps.read_probes(folder / "probes.csv"), time.perf_counter() - t0)
    log(
        f"dt = {dt * 1e3:g} ms: {run.result.time_steps} steps, "
        f"{run.result.newton_iterations} Newton iterations, {runs[dt][1]:.1f} s"
    )

# ## What the run shows
# The tip in the rotating frame (the inertial position turned back by ψ(t)), its twist about
# its own tangent (the chord's angle out of the horizontal: zero for flap and lead-lag
# bending) and the envelope of the vertical tip motion: half its peak-to-peak over each
# 1/4.5 s period of the excitation.


def measures(p):
    """Time, tip (inertial, rotating), twist and the envelopes of tip z and twist."""
    t = p["time"]
    tip = np.column_stack([p["tip_x"], p["tip_y"], p["tip_z"]])
    twist = ps.tip_twist(np.column_stack([p["tip_rot_x"], p["tip_rot_y"], p["tip_rot_z"]]))
    return {
        "t": t,
        "tip": tip,
        "rotating": ps.to_rotating(t, tip),
        "twist": twist,
        "z_env": ps.envelope(t, p["tip_z"]),
        "twist_env": ps.envelope(t, twist),
    }


m = {dt: measures(p) for dt, (p, _) in runs.items()}
fine = m[min(m)]
p0 = runs[min(runs)][0]
# the clamp follows its two schedules: up and down along the axis, turned by ψ(t) about it
ramp = np.where(fine["t"] < 1, (1 - np.cos(np.pi * fine["t"])) / 2, 1.0)
assert np.allclose(p0["root_z"], 0.02 * np.sin(2 * np.pi * 4.5 * fine["t"]) * ramp, atol=1e-12)
before = fine["t"] <= ps.SPIN_START_S
angle = np.linalg.norm(np.column_stack([p0[f"root_rot_{c}"] for c in "xyz"]), axis=1)
assert np.allclose(angle, ps.spin_angle(fine["t"]), atol=1e-9)
# before the spin starts the motion stays in the strip's plane: no lead-lag, no twist
assert np.max(np.abs(fine["rotating"][before, 0])) < 1e-9
assert np.max(np.abs(fine["twist"][before])) < 1e-9
log(f"tip z amplitude at t = 2 s (4.5 Hz, no spin): {fine['z_env'][1][8]:.4f} m")


def plot(m, campbell, path):
    """Campbell diagram, vertical tip motion and its envelope, tip in the rotating frame, twist."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(2, 2, figsize=(12, 8))
    result = campbell[max(campbell)]
    spins = np.asarray(result.speeds_rad_s) / (2 * np.pi)
    for b in result.campbell:
        ax[0, 0].plot(spins, b["frequencies_hz"], label=f"f{b['branch']}")
    spin, _ = ps.crossing(*ps.lowest(result))
    ax[0, 0].axhline(ps.EXCITATION_HZ, color="k", ls="--", label="4.5 Hz excitation")
    ax[0, 0].plot([spin], [ps.EXCITATION_HZ], "ko")
    ax[0, 0].set(xlabel="spin (Hz)", ylabel="rotating-frame frequency (Hz)", ylim=(0, 40))
    ax[0, 0].set_title(f"Campbell diagram; f1 = 4.5 Hz at {spin:.3f} Hz spin")
    ax[0, 0].legend(fontsize=8)
    for dt, r in sorted(m.items()):
        ls = "-" if dt == min(m) else ":"
        if dt == min(m):
            ax[0, 1].plot(r["t"], r["tip"][:, 2], lw=0.4, color="0.6", label="tip z")
            for i, c in enumerate("xyz"):
                ax[1, 0].plot(r["t"], r["rotating"][:, i], lw=0.5, label=f"{c} (rotating)")
            ax[1, 0].plot(r["t"], r["tip"][:, 0], lw=0.3, color="0.7", label="x (inertial)")
            ax[1, 1].plot(r["t"], np.degrees(r["twist"]), lw=0.4, color="0.6", label="twist")
        ax[0, 1].plot(*r["z_env"], "k" + ls, label=f"envelope, dt = {dt * 1e3:g} ms")
        ax[1, 1].plot(
            r["twist_env"][0],
            np.degrees(r["twist_env"][1]),
            "k" + ls,
            label=f"envelope, dt = {dt * 1e3:g} ms",
        )
    ax[0, 1].set(xlabel="t (s)   [spin = t - 2 Hz after 2 s]", ylabel="tip z (m)")
    ax[1, 0].set(xlabel="t (s)", ylabel="tip position (m)")
    ax[1, 1].set(xlabel="t (s)", ylabel="tip twist (degrees)")
    for a in (ax[0, 1], ax[1, 0], ax[1, 1]):
        a.axvline(ps.SPIN_START_S + spin, color="r", lw=0.8)
        a.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


if FULL:
    a, b = (m[dt]["z_env"][1] for dt in sorted(m, reverse=True))
    ta, tb = (m[dt]["twist_env"][1] for dt in sorted(m, reverse=True))
    k = int(np.argmax(b))
    log(
        f"peak tip z amplitude {b[k]:.4f} m at t = {fine['z_env'][0][k]:.2f} s "
        f"(spin {ps.spin_hz(fine['z_env'][0][k]):.2f} Hz); peak twist amplitude "
        f"{np.degrees(tb.max()):.2f} deg; dt 2.5 -> 1.25 ms: envelope changes by at most "
        f"{np.max(np.abs(a - b)):.2e} m ({np.max(np.abs(a - b)) / b.max():.1%} of its peak), "
        f"twist envelope by {np.degrees(np.max(np.abs(ta - tb))):.2f} deg"
    )
    if comm.rank == 0:
        plot(m, campbell, OUT / "pai_spin_ramp.png")
        # the tip's history in both frames and its twist, one row per step of the finer run
        columns = [fine["t"], ps.spin_hz(fine["t"]), *fine["tip"].T, *fine["rotating"].T]
        np.savetxt(
            OUT / "tip_history.csv",
            np.column_stack([*columns, fine["twist"]]),
            delimiter=",",
            header="time,spin_hz,x,y,z,x_rotating,y_rotating,z_rotating,twist_rad",
            comments="",
        )
        log(f"wrote {OUT / 'pai_spin_ramp.png'} and {OUT / 'tip_history.csv'}")
