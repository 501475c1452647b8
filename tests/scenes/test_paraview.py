"""ParaView reads what ``beamfx run`` writes: the default scene checked and rendered in pvpython.

ParaView's own Python runs ``beamfx/io/pvscripts/pvcheck.py`` on the results folder: it
opens deformed.pvd, deformed.xdmf and surface.pvd, checks their arrays and that the deformed
tip of the 45-degree bend is where the solver put it, and renders the picture of
``open_in_paraview.py`` off-screen. Debian's ParaView renders through X only (no EGL or
OSMesa), so without a display the test starts its own Xvfb; ``-displayfd`` lets the server
pick a free display, which ``xvfb-run -a`` does racily when several run at once.

MPI: the scene runs on all ranks, pvpython on rank 0 only; its verdict is broadcast.
"""

import json
import os
import shutil
import subprocess
import time
from contextlib import contextmanager
from pathlib import Path

import pytest
from mpi4py import MPI
from scenekit import SHAKEN

import beamfx.io.pvscripts
from beamfx.runner import default_scene_path, run_scene

pytestmark = pytest.mark.paraview
comm = MPI.COMM_WORLD
PVCHECK = Path(beamfx.io.pvscripts.__file__).with_name("pvcheck.py")
PVPYTHON = shutil.which("pvpython")
XVFB = shutil.which("Xvfb")
# Bathe & Bolourchi (1979) give (15.9, 47.2, 53.4), published values spread by ~0.4; this
# checks the files against the solver's own tip (probe), so the tolerance is a file-level one
TIP_TOL = 1e-3


@contextmanager
def display():
    """Environment with a usable DISPLAY (the current one, or a private Xvfb), without the
    variables of mpirun: pvpython links MPI, and its MPI_Init fails on a rank's settings."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_"))}
    if env.get("DISPLAY"):
        yield env
        return
    r, w = os.pipe()
    server = subprocess.Popen(
        [XVFB, "-displayfd", str(w), "-screen", "0", "1280x1024x24", "-nolisten", "tcp"],
        pass_fds=(w,),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    os.close(w)
    try:
        with os.fdopen(r) as f:
            number = f.readline().strip()  # written once the server accepts connections
        if not number:
            raise RuntimeError("Xvfb did not start")
        env["DISPLAY"] = f":{number}"
        yield env
    finally:
        server.terminate()
        server.wait(timeout=10)


@pytest.mark.skipif(PVPYTHON is None, reason="pvpython not found (apt: python3-paraview)")
@pytest.mark.skipif(
    not os.environ.get("DISPLAY") and XVFB is None,
    reason="no DISPLAY and no Xvfb (apt: xvfb) for ParaView's X-only rendering",
)
def test_paraview_reads_and_renders_bend45(tmp_path):
    out = Path(comm.bcast(str(tmp_path), root=0)) / "bend45"
    results = run_scene(default_scene_path(), out_dir=out, log=lambda message: None)
    tip = results["probes"]["tip"]["position"]
    assert tip == pytest.approx([15.6, 46.9, 53.6], abs=0.1)
    assert (out / results["paraview"]["script"]).is_file()

    report, error = _pvcheck(out, tip)
    assert error is None, error
    assert report["ok"], report["failed"]

    files = report["files"]
    assert {f["times"] for f in files.values() if "times" in f} == {len(results["load_steps"])}
    assert files["surface.pvd"]["points"] > files["deformed.pvd"]["points"]
    # the 1 x 1 section at the clamped start (centre line along y, at the origin) spans
    # x and z from -1/2: the surface's box reaches 1/2 below the line's there
    line, surface = files["deformed.pvd"]["bounds"], files["surface.pvd"]["bounds"]
    assert [surface[0], surface[4]] == pytest.approx([line[0] - 0.5, line[4] - 0.5], abs=1e-6)
    image = files["png"]
    assert image["size"] == [640, 480]
    assert Path(image["path"]).stat().st_size > 5000
    assert image["colours"] > 50  # shaded and colour-mapped, not one flat colour
    assert 0.005 < image["foreground"] < 0.5  # the beam is in the picture, and not all of it


def _pvcheck(out, tip=None, attempts=6):
    """pvcheck.py on ``out`` (rank 0, under a display); its report on every rank.

    One pvpython at a time on the machine (a lock file). Now and then pvpython aborts while
    creating its X window on a fresh Xvfb (SIGABRT in vtkXOpenGLRenderWindow::CreateAWindow,
    about one run in ten here, serial or parallel, more on a loaded machine): that start-up
    failure, and only it, is retried with a new server after a pause.
    """
    import fcntl
    import tempfile

    report, error = None, None
    if comm.rank == 0:
        cmd = [PVPYTHON, str(PVCHECK), str(out), "--png", str(out / "check.png")]
        cmd += ["--size", "640", "480"]
        if tip is not None:
            cmd += ["--tip", *map(str, tip), "--tol", str(TIP_TOL)]
        lock = open(Path(tempfile.gettempdir()) / "beamfx-pvpython.lock", "w")  # noqa: SIM115
        with lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            for _ in range(attempts):
                with display() as env:
                    run = subprocess.run(
                        cmd, env=env, capture_output=True, text=True, timeout=120, check=False
                    )
                if not (run.returncode == -6 and "CreateAWindow" in run.stderr):
                    break
                time.sleep(1.0)
        lines = [ln for ln in run.stdout.splitlines() if ln.startswith("{")]
        if run.returncode != 0 or not lines:
            error = f"pvcheck exit {run.returncode}\n{run.stdout[-2000:]}\n{run.stderr[-2000:]}"
        else:
            report = json.loads(lines[-1])
    return comm.bcast((report, error), root=0)


@pytest.mark.skipif(PVPYTHON is None, reason="pvpython not found (apt: python3-paraview)")
@pytest.mark.skipif(
    not os.environ.get("DISPLAY") and XVFB is None,
    reason="no DISPLAY and no Xvfb (apt: xvfb) for ParaView's X-only rendering",
)
@pytest.mark.parametrize(
    "analysis, keys",
    [
        ("transient", "t_end = 0.2\ndt = 0.01\noutput_every = 2"),
        ("modal", "modes = 4"),
        ("buckling", "modes = 2"),
    ],
)
def test_paraview_reads_transient_modal_and_buckling(tmp_path, analysis, keys):
    """A time series (the tip of the last frame where the run left it), one step per mode."""
    folder = Path(comm.bcast(str(tmp_path), root=0))
    scene = SHAKEN.replace('"ANALYSIS"', f'"{analysis}"\n{keys}')
    if analysis == "buckling":  # a column under an end load instead of the shaken base
        scene = scene.replace(
            'displacement = [0.02, 0, 0]\nhistory = "(1 - cos(pi * t / 0.2)) / 2"', ""
        )
        scene += '[[loads]]\nat = "arm:end"\nforce = [0, 0, -1]\n'
    if comm.rank == 0:
        (folder / "scene.toml").write_text(scene)
    comm.barrier()
    out = folder / "out"
    results = run_scene(folder / "scene.toml", out_dir=out, log=lambda message: None)
    tip = results["probes"]["tip"]["position"] if analysis == "transient" else None
    report, error = _pvcheck(out, tip)
    assert error is None, error
    assert report["ok"], report["failed"]
    files = report["files"]
    frames = (
        results["time_steps"] // 2 + 1 if analysis == "transient" else {"modal": 4}.get(analysis, 2)
    )
    reactions = files.pop("reactions.pvd", None)  # a transient's from its first step on
    assert (reactions is None) == (analysis != "transient")
    assert reactions is None or reactions["times"] == frames - 1
    assert {f["times"] for f in files.values() if "times" in f} == {frames}
    assert files["surface.pvd"]["points"] > files["deformed.pvd"]["points"]
    image = files["png"]
    assert image["colours"] > 50 and 0.001 < image["foreground"] < 0.5


@pytest.mark.skipif(PVPYTHON is None, reason="pvpython not found (apt: python3-paraview)")
@pytest.mark.skipif(
    not os.environ.get("DISPLAY") and XVFB is None,
    reason="no DISPLAY and no Xvfb (apt: xvfb) for ParaView's X-only rendering",
)
def test_paraview_reads_every_format(tmp_path):
    """The centre line, the surface and the XDMF (not a default) of the half-circle roll-up,
    written by the frame writer: ParaView finds the exact tip (0, 0, 2L/π) in each."""
    from dataclasses import replace

    import numpy as np
    from scenekit import SECTION, TOL_POSITION, L, rollup_model

    from beamfx.analyses.static import solve_static
    from beamfx.io import FrameWriter, OutputSettings

    folder = Path(comm.bcast(str(tmp_path), root=0))
    model, _ = rollup_model(0.5)
    steps = 4
    section = replace(SECTION, shape=("rectangle", 0.2, 0.1))
    beams = tuple(replace(b, section=section) for b in model.spec.beams)
    settings = OutputSettings(formats=("vtu", "surface", "xdmf"))
    writer = FrameWriter(folder, model, settings, beams, comm)
    solve_static(model, steps=steps, on_step=lambda s: writer.write(s.step, s.load_factor))
    writer.close()
    report, error = _pvcheck(folder, [0.0, 0.0, 2 * L / np.pi])
    assert error is None, error
    assert report["ok"], report["failed"]
    files = report["files"]
    assert set(files) == {"deformed.pvd", "surface.pvd", "deformed.xdmf", "png"}
    assert {f["times"] for f in files.values() if "times" in f} == {steps}
    assert files["deformed.pvd"]["distance_to_tip"] < TOL_POSITION * L


@pytest.mark.skipif(PVPYTHON is None, reason="pvpython not found (apt: python3-paraview)")
@pytest.mark.skipif(
    not os.environ.get("DISPLAY") and XVFB is None,
    reason="no DISPLAY and no Xvfb (apt: xvfb) for ParaView's X-only rendering",
)
def test_paraview_reads_the_reactions_of_a_cantilever(tmp_path):
    """The reactions series of a linear cantilever under a tip force F and moment M: ParaView
    finds one vertex at the clamp with force −F and moment −(M + x_tip × F) (statically
    determinate; the balance of a linear solve is at round-off, 1e-10 of the load scale), the
    values results.json holds (the frames store the doubles: equal to 1e-12)."""
    import numpy as np
    from test_reactions import CANTILEVER

    folder = Path(comm.bcast(str(tmp_path), root=0))
    if comm.rank == 0:
        text = CANTILEVER.replace("KIN", "linear").replace("CONDENSE", "none")
        (folder / "scene.toml").write_text(text)
    comm.barrier()
    out = folder / "out"
    results = run_scene(folder / "scene.toml", out_dir=out, log=lambda message: None)
    report, error = _pvcheck(out)
    assert error is None, error
    assert report["ok"], report["failed"]
    found = report["files"]["reactions.pvd"]
    assert found["points"] == 1 and found["times"] == report["files"]["deformed.pvd"]["times"]
    F, M = np.array([1e3, -2e3, 5e3]), np.array([100, 0, 300.0])
    expected = {"force": -F, "moment": -(M + np.cross([2.0, 0, 0], F))}
    for key, value in expected.items():
        assert np.allclose(found[key][0], value, rtol=0, atol=1e-10 * 1e4)
        assert np.allclose(found[key][0], results["reactions"]["b:start"][key], rtol=0, atol=1e-12)
    assert np.allclose(found["positions"][0], [0, 0, 0], atol=1e-12)
