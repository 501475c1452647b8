"""VTK's thread count is set once (beamfx.io.vtkfiles.thread_count_once): the writers then
stop asking the system for its processors at every array range (a read of
/sys/devices/system/cpu/online each, 2/3 of the cost of a small frame), and the backend in use
and its number of threads stay what VTK chose."""

import os
import shutil
import subprocess
import sys

import pytest

FRAMES = r"""
import sys
from beamfx.io.vtkfiles import import_vtk
import_vtk()
import numpy as np
from beamfx.io.vtkfiles import GridBuffer, GridWriter, lagrange_line_grid
rng = np.random.default_rng(0)
buffer, writer = GridBuffer(), GridWriter()
for step in range(20):
    point_data = {name: rng.standard_normal((12, 3)) for name in ("u", "N", "M")}
    cell_data = {"cell": np.arange(4), "beam": np.zeros(4, np.int64)}
    grid = lagrange_line_grid(rng.standard_normal((12, 3)), 2, point_data, cell_data, buffer)
    writer.write(f"{sys.argv[1]}/f_{step}.vtu", grid)
"""

BACKEND = r"""
from vtkmodules.vtkCommonCore import vtkSMPTools
before = vtkSMPTools.GetBackend(), vtkSMPTools.GetEstimatedNumberOfThreads()
from beamfx.io.vtkfiles import import_vtk
import_vtk()
print(before == (vtkSMPTools.GetBackend(), vtkSMPTools.GetEstimatedNumberOfThreads()))
"""


def _env(**extra):
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    path = os.pathsep.join(p for p in (root, os.environ.get("PYTHONPATH")) if p)
    return {**os.environ, "PYTHONPATH": path, **extra}


@pytest.mark.parametrize("backend", ["Sequential", "STDThread"])
def test_backend_and_its_threads_kept(backend):
    env = _env(VTK_SMP_BACKEND_IN_USE=backend)
    out = subprocess.run(
        [sys.executable, "-c", BACKEND], check=False, env=env, capture_output=True, text=True
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["True"]


@pytest.mark.skipif(shutil.which("strace") is None, reason="strace not installed")
def test_frames_do_not_ask_for_the_processors(tmp_path):
    """20 frames of 6 arrays each: without the count set VTK read it 248 times (the start-up: 9)."""
    trace = tmp_path / "trace"
    cmd = ["strace", "-f", "-e", "trace=openat", "-o", str(trace)]
    cmd += [sys.executable, "-c", FRAMES, str(tmp_path)]
    out = subprocess.run(cmd, check=False, env=_env(), capture_output=True, text=True)
    if out.returncode != 0 and "ptrace" in out.stderr:
        pytest.skip("strace not permitted here")
    assert out.returncode == 0, out.stderr
    reads = trace.read_text().count("/sys/devices/system/cpu/online")
    assert len(list(tmp_path.glob("f_*.vtu"))) == 20
    assert reads < 20  # the start-up's few, none per frame
