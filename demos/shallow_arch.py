# # A shallow arch snaps through: statically, on the symmetric path, and under a sudden load
#
# Howcroft et al. (2016, §4.2): a circular arch of radius $R = 20$ over 45° (span 15.31, rise
# 1.522), the unit square section of the 45° bend ($E = 10^7$, $\nu = 0$), pinned at both ends,
# under a uniform load toward the centre of the arc. Its shallowness
# $\lambda = S^2/(4 R r) = 10.68$ ($S$ the arc length, $r$ the radius of gyration) puts it
# where the shallow-arch theory (Pi, Bradford & Uy 2002) has two critical loads close
# together: the antisymmetric bifurcation, when the thrust reaches the antisymmetric mode's
# Euler load $4\pi^2 EI/S^2$, and the symmetric limit point (snap-through).
#
# The scene is the shipped `beamfx/scenes/shallow_arch_snap.toml`: the load is given in the
# section axes of the undeformed arch (`axes = "section"`), so it points to the centre of the
# arc everywhere; the arch has an `orientation` normal to its plane, and beamfx runs the
# planar model. Run `python demos/shallow_arch.py [--out DIR]`: the three runs' folders go into
# results/shallow_arch/ under the current folder, or DIR (or $BEAMFX_DEMO_OUT/shallow_arch: the
# tests set it to a temporary one); each run clears its folder's results of the last one.

import os
import sys
import tomllib
from importlib import resources
from pathlib import Path

import numpy as np
from mpi4py import MPI

from beamfx.bench.shallow_arch import Q_SNAP, theory_loads
from beamfx.io import log
from beamfx.runner import run_scene
from beamfx.scene.load import parse_scene

argv = sys.argv[1:] if __name__ == "__main__" else []
OUT = Path(argv[argv.index("--out") + 1]) if "--out" in argv else None
OUT = OUT or Path(os.environ.get("BEAMFX_DEMO_OUT", "results")) / "shallow_arch"
comm = MPI.COMM_WORLD
OUT = Path(comm.bcast(str(OUT), root=0))
rank0 = comm.rank == 0
log(f"shallow_arch demo: writes into {OUT}")
TEXT = resources.files("beamfx.scenes").joinpath("shallow_arch_snap.toml").read_text()


def run(name, data):
    """Run a scene (TOML data) quietly into OUT/name; return beamfx's RunResult."""
    scene = parse_scene(data, f"{name}.toml")
    return run_scene(scene.file, OUT / name, log=lambda *a, **k: None, scene=scene)


# ## The static path: arc length past the limit point
# The arc-length trace follows the symmetric path over the limit point and down to the
# inverted arch. The limit point is placed by a quadratic fit through the steps around it.

static = run("static", tomllib.loads(TEXT))
top = next(p for p in static.result.limit_points if p["kind"] == "maximum")
q_limit, crown_limit = top["load_factor"] * Q_SNAP, top["displacement"][2]
theory = theory_loads()
log(f"limit load {q_limit:.1f} N/m, crown down {abs(crown_limit):.4f} at the limit")
log(
    f"shallow-arch theory: limit {theory['q_limit']:.1f} N/m, crown {abs(theory['crown_limit']):.4f};"
    f" antisymmetric bifurcation at {theory['q_bifurcation']:.0f} N/m; paper: 5500 N/m"
)
# shallow theory neglects shear and the arc's departure from a parabola: O((rise/span)^2) ~ 1 %
assert abs(q_limit / theory["q_limit"] - 1) < 0.01
assert abs(crown_limit / theory["crown_limit"] - 1) < 0.01

# ## Under a sudden load
# The same arch with a density $\rho = 1$ and the load applied at once and held (a step in
# time). Under a step load an arch snaps at a lower load than statically: the load does work
# on the way down before the arch pushes back. Generalized-α, $\Delta t = 2$ ms, 0.6 s (about
# four periods of the first symmetric mode).


def sudden(q):
    data = tomllib.loads(TEXT)
    data["material"]["rho"] = 1.0
    data["loads"][0]["force_per_length"] = [0.0, -q, 0.0]
    data["analysis"] = {"type": "transient", "t_end": 0.6, "dt": 0.002, "rho_inf": 0.8}
    data["probes"] = [{"name": "crown", "at": "arch:0.5"}]
    return run(f"sudden_{q:.0f}", data)


dips = {}
for q in (4000.0, 4600.0):
    sudden(q)
    crown = np.loadtxt(OUT / f"sudden_{q:.0f}" / "probes.csv", delimiter=",", skiprows=1)
    header = (OUT / f"sudden_{q:.0f}" / "probes.csv").read_text().splitlines()[0].split(",")
    uz = crown[:, header.index("crown_uz")]
    dips[q] = float(uz.min())
    log(f"sudden load {q:.0f} N/m: crown down at most {abs(dips[q]):.3f} (rise 1.522)")

# below the dynamic snap-through load the crown swings back; above it the arch inverts
assert dips[4000.0] > -1.522 and dips[4600.0] < -1.522 * 2
log(
    f"dynamic snap-through between 4000 and 4600 N/m, {4000 / q_limit:.2f}-{4600 / q_limit:.2f} of the static limit"
)

# ## Without shear and extension flexibility: an antisymmetric bifurcation
# The shipped `beamfx/scenes/shallow_arch_bifurcation.toml`: the same arch, shear-rigid and
# inextensible (`[model] shear = false, stretch = false`), at 7500 N/m. The perfect arch only
# shortens until its tangent has a zero eigenvalue with an antisymmetric mode: the arc-length
# trace counts the tangent's negative eigenvalues at every point, locates the change (regula
# falsi on the arc length, inside the bracket the inertia keeps) and, with
# `branch = "secondary"`, steps along the mode onto the antisymmetric branch, followed until
# the crown is down twice the rise. Theories: shallow arch (inextensible) 4π²EI/(S²R) =
# 6667 N/m; deep arch under a pressure that follows the arch (Timoshenko & Gere)
# (EI/R³)(π²/α² − 1) = 6562.5 N/m. The independent check on the same mesh is a linear
# buckling analysis about the state at 6500 N/m (`about = "current"`, in the plane).

from beamfx.bench.shallow_arch import scene_data
from beamfx.bench.shallow_arch_bifurcation import Q_BELOW, Q_BIF, buckling_data, theories

bif = run("bifurcation", scene_data("shallow_arch_bifurcation")).result
point = next(c for c in bif.critical_points if c["kind"] == "bifurcation")
q_bif = point["load_factor"] * Q_BIF
q_bracket = (point["load_factor_bracket"][1] - point["load_factor_bracket"][0]) * Q_BIF
q_buckling = run("buckling", buckling_data()).result.load_factors[0] * Q_BELOW
bounds = theories()
log(f"bifurcation located at {q_bif:.4f} N/m (the inertia brackets it within {q_bracket:.1e})")
log(f"linear buckling about the state at {Q_BELOW:.0f} N/m: {q_buckling:.4f} N/m")
log(
    f"theories: shallow arch {bounds['q_shallow']:.1f} N/m, deep arch under a follower "
    f"pressure {bounds['q_deep_follower']:.1f} N/m"
)
end = bif.path[-1]
log(
    f"secondary branch: {len(bif.path)} points, ends at load factor {end['load_factor']:.3f}"
    f" with the crown down {abs(end['displacement'][2]):.3f}"
)
# the located point is the linear buckling load of the same mesh, within the location's bracket
# and the linear buckling's own digits: the primary path is a membrane state (no rotation
# before buckling), so the linearisation is exact but for round-off, and about states at 6000,
# 6500 and 6600 N/m it gives the same load to 6e-8 (the penalty's round-off in the state)
assert abs(q_bif - q_buckling) <= q_bracket + 1e-7 * q_bif
# shallow theory neglects the depth: O((rise/span)^2) = (1.522/15.31)^2 ~ 1 %; the dead load
# has no load stiffness, so it buckles above the follower pressure (which has)
assert abs(q_bif / bounds["q_shallow"] - 1) < (1.522 / 15.307) ** 2
assert bounds["q_deep_follower"] < q_bif
# the trace switched branch there and reached the displacement limit on the secondary branch
assert (
    point["switched"] and bif.stopped_by == "displacement_limit" and end["displacement"][2] <= -3.0
)
assert any(p.get("note") == "branch switch" for p in bif.path)

if rank0:
    log(f"results in {OUT}")
