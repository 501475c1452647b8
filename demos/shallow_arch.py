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
# planar model. Run `python demos/shallow_arch.py [--out DIR]`.

import sys
import tempfile
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
comm = MPI.COMM_WORLD
if OUT is None:
    OUT = Path(comm.bcast(tempfile.mkdtemp(prefix="shallow_arch_") if comm.rank == 0 else None))
rank0 = comm.rank == 0
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

if rank0:
    log(f"results in {OUT}")
