"""What the ParaView frames cost: per frame as the frames add up, and in whole runs.

    python -m beamfx.bench.output_cost REPORT.md [--frames 10000] [--before REV]

Writes a markdown report with three tables:

1. **Per frame, as frames add up**: a real transient of the flying spaghetti (16 quadratic
   elements, the free beam of :mod:`beamfx.bench.transient`, given a rectangular section so
   that the surface is drawn; generalized-α, 10⁴ time steps) writes a frame (the default
   formats: centre line and surface) at every step; the table gives the median and mean cost
   of a frame over the first 100, frames 901–1 000 and frames 9 901–10 000. XDMF (DOLFINx, not a
   default) is timed on repeated frames of the final state, up to 10³ frames only: its cost
   grows with the frames written (10⁴ would take hours).
2. **Whole runs**: ``beamfx run`` of ``demos/scenes/spin_up.toml`` (4 P2 elements, 1440 time
   steps, 207 frames) and of a roll-up (16 cubic elements, two turns in 40 load steps, a
   frame per step), each in a fresh process with timers around the frame writing, the probe
   evaluation and the Newton solves; with ``--before REV`` also the same runs of the beamfx
   package of git revision REV (its files extracted to a scratch folder).

Timings are wall-clock on whatever machine runs it; the machine's load shows in them, and so
does its file system: the runs write into a temporary folder (``--scratch`` names another
parent); on the machine of the benchmarks the roll-up's frames took 0.04 to 0.13 s from run to
run in the same folder, the creation of a file 13 to 270 µs.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
ROLLUP = """
[material]
E = 1.0e7
nu = 0.3
[[beams]]
name = "b"
curve = { shape = "line", start = [0, 0, 0], end = [10, 0, 0] }
section = { type = "rectangle", h = 0.1, w = 0.1 }
elements = 16
degree = 3
[[supports]]
at = "b:start"
fix = "all"
[[loads]]
at = "b:end"
moment = [0, -104.71975511965977, 0]
[analysis]
type = "static"
steps = 40
[[probes]]
name = "tip"
at = "b:end"
"""

# Run inside the child: timers around the frame writing (the FrameWriter, or the writers of
# older revisions), the probes and the Newton solves; the outermost call of each is counted.
SHIM = r"""
import atexit, json, os, sys, time
t0 = time.perf_counter()
T, active = {}, set()

def wrap(owner, name, key):
    f = getattr(owner, name, None)
    if f is None:
        return
    def timed(*a, **k):
        if key in active:
            return f(*a, **k)
        active.add(key)
        s = time.perf_counter()
        try:
            return f(*a, **k)
        finally:
            active.discard(key)
            T[key] = T.get(key, 0.0) + time.perf_counter() - s
    setattr(owner, name, timed)

try:  # what `beamfx run` does first (revisions before it had no beamfx.startup)
    from beamfx.startup import prepare
    prepare()
except ImportError:
    pass
import beamfx.io as io
import beamfx.solvers.snes as snes
try:
    import beamfx.io.output as output
    wrap(output.FrameWriter, "write", "output")
except ImportError:  # before the frame writer: the writers the runner called
    import beamfx.io.surface as surface
    for name in ("nodal_fields", "write_vtu"):
        wrap(io, name, "output")
    for cls in (io.PvdSeries, io.XdmfSeries, surface.SurfaceSeries):
        wrap(cls, "add", "output")
wrap(io, "evaluate_points", "probes")
try:  # a transient's probes, kept raw per step and made into rows per block
    import beamfx.io.probe_blocks as blocks
    wrap(blocks.ProbeBlocks, "record", "probes")
    wrap(blocks.ProbeBlocks, "drain", "probes")
except ImportError:  # (before the blocks: evaluate_points at every step)
    pass
wrap(snes.NewtonSolver, "solve", "newton")

@atexit.register
def report():
    T["process"] = time.perf_counter() - t0
    with open(os.environ["BEAMFX_TIMES"], "w") as f:
        json.dump(T, f)

sys.argv = ["beamfx", *sys.argv[1:]]
from beamfx.cli import main
main()
"""


def _checkout(rev, folder):
    """The ``beamfx`` package of git revision ``rev`` extracted into ``folder``."""
    archive = subprocess.run(
        ["git", "-C", str(ROOT), "archive", rev, "beamfx"], capture_output=True, check=True
    )
    subprocess.run(["tar", "-x", "-C", str(folder)], input=archive.stdout, check=True)
    return folder


def run_timed(scene, out, source=ROOT):
    """``beamfx run scene --out out`` in a child process whose beamfx comes from ``source``;
    its timers and the process's wall time."""
    env = dict(os.environ, PYTHONPATH=str(source), BEAMFX_TIMES=str(Path(out) / "times.json"))
    env.setdefault("SETUPTOOLS_USE_DISTUTILS", "stdlib")
    Path(out).mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    cmd = [sys.executable, "-c", SHIM, "run", str(scene), "--out", str(out)]
    subprocess.run(cmd, env=env, check=True, capture_output=True, cwd=source)
    times = json.loads((Path(out) / "times.json").read_text())
    times["wall"] = time.perf_counter() - t0
    return times


def _windows(n):
    """The frame windows timed: the first 100, 901–1000, 9901–10000 (those within n)."""
    return [(lo, lo + 100) for lo in (0, 900, 9900) if lo + 100 <= n]


def transient_frames(n, folder):
    """Per-frame cost (s) of the default formats in a real transient writing every step,
    by window of frames; and the model (its final state) for the XDMF timing."""
    from dataclasses import replace

    from mpi4py import MPI

    from ..analyses.model import BeamModel
    from ..analyses.transient import TransientSettings, solve_transient
    from ..io import FrameWriter, OutputSettings
    from .transient import flying_spaghetti_model

    spec = flying_spaghetti_model(16, 2)
    section = replace(spec.beams[0].section, shape=("rectangle", 0.2, 0.1))
    spec = replace(spec, beams=(replace(spec.beams[0], section=section),))
    model = BeamModel(spec)
    Path(folder).mkdir(parents=True, exist_ok=True)
    writer = FrameWriter(folder, model, OutputSettings(), spec.beams, MPI.COMM_WORLD)
    cost = []

    def on_step(r):
        t = time.perf_counter()
        writer.write(r.step, r.time)
        cost.append(time.perf_counter() - t)

    settings = TransientSettings(t_end=n * 0.004, dt=0.004, checkpoint_every=0)
    solve_transient(model, settings, on_step=on_step)
    cost = np.array(cost[1:])  # step 0 (t = 0) aside: the windows count frames 1, 2, ...
    return {w: _stats(cost[w[0] : w[1]]) for w in _windows(len(cost))}, model, spec


def xdmf_frames(model, spec, n, folder):
    """Per-frame cost (s) of the XDMF format on repeated frames of ``model``'s state."""
    from mpi4py import MPI

    from ..io import FrameWriter, OutputSettings

    Path(folder).mkdir(parents=True, exist_ok=True)
    settings = OutputSettings(formats=("xdmf",))
    writer = FrameWriter(folder, model, settings, spec.beams, MPI.COMM_WORLD)
    cost = []
    for step in range(1, n + 1):
        t = time.perf_counter()
        writer.write(step, float(step))
        cost.append(time.perf_counter() - t)
    writer.close()
    return {w: _stats(cost[w[0] : w[1]]) for w in _windows(n)}


def _stats(seconds):
    """(median, mean) in ms: the median is the cost, the mean shows the machine's hiccups."""
    return 1e3 * float(np.median(seconds)), 1e3 * float(np.mean(seconds))


def _row(label, t):
    rest = t["process"] - t.get("newton", 0) - t.get("output", 0) - t.get("probes", 0)
    cells = [t["wall"], t.get("newton", 0.0), t.get("output", 0.0), t.get("probes", 0.0), rest]
    ratio = t["wall"] / t["newton"] if t.get("newton") else float("nan")
    return f"| {label} | " + " | ".join(f"{c:.2f}" for c in cells) + f" | {ratio:.2f} |"


def report(frames, xdmf, runs):
    """The markdown report: cost per frame as the frames add up, and the whole runs."""
    lines = ["# Output cost (`python -m beamfx.bench.output_cost`)", ""]
    lines += ["## Per frame, as the frames add up (ms, median / mean of the window)", ""]
    lines += ["| frames | vtu + surface, real transient | xdmf, repeated frames |", "|---|---|---|"]
    for w in frames:
        x = "{:.2f} / {:.2f}".format(*xdmf[w]) if w in xdmf else "not run (grows with the frames)"
        lines.append(f"| {w[0] + 1}–{w[1]} | {'{:.2f} / {:.2f}'.format(*frames[w])} | {x} |")
    lines += ["", "## Whole runs of `beamfx run` (s)", ""]
    lines += [
        "| run | process wall | Newton solves | frames | probes | rest | wall / Newton |",
        "|---|---|---|---|---|---|---|",
    ]
    lines += [_row(label, t) for label, t in runs]
    lines += ["", f"Machine: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}."]
    return "\n".join(lines) + "\n"


def main(argv=None):
    """Command line: measure the output cost and write the markdown report."""
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("report", help="markdown file to write")
    p.add_argument("--frames", type=int, default=10000, help="time steps of the transient")
    p.add_argument("--xdmf-frames", type=int, default=1000)
    p.add_argument("--before", help="git revision to compare the whole runs with")
    p.add_argument("--scratch", help="parent folder of the runs' (default: the system's)")
    args = p.parse_args(argv)
    if args.scratch:
        Path(args.scratch).mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=args.scratch) as scratch:
        scratch = Path(scratch)
        (scratch / "rollup.toml").write_text(ROLLUP)
        sources = [("now", ROOT)]
        if args.before:
            sources.insert(0, (args.before, _checkout(args.before, scratch)))
        runs = []
        for scene, name in (
            (ROOT / "demos/scenes/spin_up.toml", "spin-up"),
            (scratch / "rollup.toml", "roll-up"),
        ):
            for label, source in sources:
                out = scratch / f"{name}-{label}"
                runs.append((f"{name}, {label}", run_timed(scene, out, source)))
        from ..io.vtkfiles import import_vtk

        import_vtk()  # before DOLFINx
        frames, model, spec = transient_frames(args.frames, scratch / "frames")
        xdmf = xdmf_frames(model, spec, args.xdmf_frames, scratch / "xdmf")
    text = report(frames, xdmf, runs)
    Path(args.report).write_text(text)
    print(text)


if __name__ == "__main__":
    main()
