# # The Pai beam upright and shaken at its root: frequency sweeps and the backbone of mode 2
#
# A thin titanium strip, 479 × 50.8 × 0.45 mm, stands clamped upright under its own weight.
# The clamp moves sideways in the flap plane, y(t) = A sin φ(t) with φ = 2π∫f dt, while the
# frequency f is swept slowly from 7 to 11 Hz and back (Howcroft et al. 2016, after Pai's
# experiments). The second bending mode, near 10.4 Hz, resonates. Its frequency falls as its
# amplitude grows (a softening mode), so the resonance leans to lower frequencies and the
# up and down sweeps leave it at different frequencies. The backbone, the frequency of free
# oscillation against its amplitude, comes from a free decay.
#
# The model is planar (two displacements and one angle per node, 5 cubic elements, 48
# unknowns): the motion stays in the flap plane. The damping, "0.005 % stiffness-proportional",
# is read as a Kelvin–Voigt relaxation time a1 = 5e-5 s: ζ2 = a1 ω2/2 ≈ 0.16 %.
#
# Run `python demos/pai_beam.py --full [--out DIR]` for the sweeps of docs/pai_beam.md (six
# sweeps of 40–160 s of motion, about 6–8 minutes on a quiet core); without `--full` (as
# the tests run it) the sweeps are short and narrow and only the qualitative checks are made.
# It writes pai_beam_sweep.csv and .png into results/pai_beam/ (results/pai_beam_short/
# without `--full`) under the current folder, or DIR (or $BEAMFX_DEMO_OUT/<that name>: the
# tests set it to a temporary one).

import os
import sys
from pathlib import Path

import numpy as np
from mpi4py import MPI

from beamfx.analyses.model import BeamModel
from beamfx.bench import pai_beam as pb
from beamfx.io import log

argv = sys.argv[1:] if __name__ == "__main__" else []
FULL = "--full" in argv or os.environ.get("BEAMFX_DEMO_FULL") == "1"
OUT = Path(argv[argv.index("--out") + 1]) if "--out" in argv else None
NAME = "pai_beam" if FULL else "pai_beam_short"
OUT = OUT or Path(os.environ.get("BEAMFX_DEMO_OUT", "results")) / NAME
OUT = Path(MPI.COMM_WORLD.bcast(str(OUT), root=0))
rank0 = MPI.COMM_WORLD.rank == 0
log(f"pai_beam demo: writes into {OUT}")

# ## Linear frequencies about the gravity-loaded state
# The beam's weight (0.48 N) compresses it at 28 % of its self-weight buckling load, which
# lowers the flap frequencies; mode 2 drops from 10.63 to about 10.42 Hz.

for gravity in (False, True):
    model = BeamModel(pb.pai_model(gravity=gravity), extra_points=["b:end"])
    modes = pb.linear_modes(model)
    log(f"gravity {gravity}: flap frequencies {np.round(modes.hz, 4)} Hz")
f2 = float(modes.hz[1])
assert 10.3 < f2 < 10.5

# ## Backbone from free decay
# Start at the equilibrium with the velocity field of linear mode 2 (tip speed v0), which puts
# the motion on the nonlinear mode to second order, and let it decay. The frequency per period
# comes from the upward zero crossings of the mode-2 coordinate q2 = φ2ᵀM(w − w_s)/φ2ᵀMφ2;
# the projection hides the free mode-1 oscillation that the start also leaves. A heavier
# damping (a1 = 3e-4 s, ζ2 ≈ 1 %) walks down the amplitudes in a few seconds; it shifts a
# frequency by ζ²/2 ≈ 5e-5 only.

v0, t_decay = (7.0, 5.0) if FULL else (3.0, 1.5)  # tip about 8 cm (full)
decay, _ = pb.run_free_decay(v0, t_decay, damping=3e-4)
bb = pb.backbone(decay)
f0, c = pb.backbone_slope(bb, upto=0.05)
log(
    f"backbone: {len(bb.frequency)} periods, amplitude {bb.amplitude.max():.4f} → "
    f"{bb.amplitude.min():.4f} m, frequency {bb.frequency.min():.3f} → {bb.frequency.max():.3f} "
    f"Hz; f ≈ {f0:.3f} {c:+.1f}·a² Hz (a in m, a ≤ 5 cm); {decay.steps} steps in "
    f"{decay.seconds:.1f} s"
)
assert c < 0, "mode 2 should soften"

# ## Sweeps
# Up and down at each sweep rate, ±1 mm at the clamp, starting from rest with a 1 s amplitude
# ramp. The envelope is half the peak-to-peak tip displacement (relative to the clamp) in each
# forcing cycle, against the forcing frequency at the middle of the cycle.

if FULL:
    bands, durations = [(7.0, 11.0), (11.0, 7.0)], (40.0, 80.0, 160.0)
else:
    bands, durations = [(9.6, 10.8), (10.8, 9.6)], (3.0,)
sweeps = {}
for duration in durations:
    for f_a, f_b in bands:
        sw = pb.Sweep(f_a, f_b, duration)
        trace = pb.run_sweep(sw)
        env = pb.envelope(trace, sw)
        sweeps[(duration, f_a < f_b)] = (sw, env)
        fp, ap = pb.peak(env)
        log(
            f"sweep {f_a:g} → {f_b:g} Hz in {duration:g} s ({abs(sw.rate):.3g} Hz/s): peak "
            f"{1e3 * ap:.1f} mm at {fp:.3f} Hz; {trace.steps} steps, {trace.newton_iterations} "
            f"Newton its, {trace.seconds:.1f} s ({1e3 * trace.seconds / trace.steps:.2f} ms/step)"
        )

# ## Results: CSV and plot

if rank0:
    OUT.mkdir(parents=True, exist_ok=True)
    pb.write_csv(OUT / "pai_beam_sweep.csv", sweeps.values(), bb)
    pb.plot(OUT / "pai_beam_sweep.png", list(sweeps.values()), bb, f2)
    log(f"wrote {OUT / 'pai_beam_sweep.csv'} and {OUT / 'pai_beam_sweep.png'}")

# ## Checks
# The resonance shows (peak well above the response at the sweep's start); the free decay
# softens. With the full sweeps, the down sweep, riding the upper branch of the bent
# resonance, peaks at a lower frequency than the up sweep.

for (duration, up), (sw, env) in sweeps.items():
    assert pb.peak(env)[1] > 3 * env.amplitude[0], "no resonance in a sweep"
if FULL:
    slowest = max(durations)
    assert pb.peak(sweeps[(slowest, False)][1])[0] < pb.peak(sweeps[(slowest, True)][1])[0]
if rank0:
    print("pai_beam demo: OK")
