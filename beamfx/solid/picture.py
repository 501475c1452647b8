"""``solid_vs_beam.png`` (``beamfx solid --png``): the deformed solid, coloured by |u| and half
transparent, with the beam's deformed centre line through it (red) and the undeformed solid's
edges in grey; rendered off-screen with pyvista in a separate process like
:mod:`beamfx.io.pictures`, from the files the run wrote (``solid.pvd``, ``beam.vtu``)."""

import json
import os
import sys

import numpy as np

from ..io.pictures import SCALAR_BAR, SIZE, _camera, _union, read_pvd, render_in_child

FILE = "solid_vs_beam.png"
CHILD = "import pyvista; from beamfx.solid.picture import main; main()"  # pyvista before dolfinx
RED = (0.85, 0.1, 0.1)


def write_solid_picture(folder, title, log=print, size=SIZE):
    """Render :data:`FILE` into ``folder`` (rank 0 only); the report as in write_pictures."""
    from mpi4py import MPI

    if MPI.COMM_WORLD.rank != 0:
        return None
    job = {"folder": os.fspath(folder), "title": title, "size": list(size)}
    return render_in_child(CHILD, job, [FILE], log)


def render(pv, folder, title, size):
    """The picture, from ``solid.pvd`` (its last step) and ``beam.vtu``."""
    solid_file = read_pvd(os.path.join(folder, "solid.pvd"))[-1][1]
    grid = pv.read(solid_file)
    grid = grid.combine() if isinstance(grid, pv.MultiBlock) else grid
    reference = grid.extract_surface(nonlinear_subdivision=2)
    surface = grid.warp_by_vector("displacement", factor=1.0).extract_surface(
        nonlinear_subdivision=2
    )
    surface.point_data["|u|"] = np.linalg.norm(surface.point_data["displacement"], axis=1)
    beam = pv.read(os.path.join(folder, "beam.vtu"))
    p = pv.Plotter(off_screen=True, window_size=list(size))
    p.set_background("white")
    p.enable_anti_aliasing("msaa")
    edges = reference.extract_feature_edges(feature_angle=30.0)
    p.add_mesh(edges, color=(0.55, 0.55, 0.55), line_width=1, render=False)
    bar = dict(SCALAR_BAR, title="solid |u|")
    p.add_mesh(
        surface,
        scalars="|u|",
        cmap="viridis",
        opacity=0.35,
        smooth_shading=True,
        scalar_bar_args=bar,
        render=False,
    )
    p.add_mesh(beam, color=RED, line_width=5, lighting=False, render=False)
    p.add_text(
        f"{title}\nsolid (colour, half transparent) and beam centre line (red)",
        position="upper_left",
        font_size=11,
        color="black",
        render=False,
    )
    p.add_axes(color="black")
    _camera(p, _union([reference.bounds, surface.bounds, beam.bounds]))
    p.screenshot(os.path.join(folder, FILE))
    p.close()
    return FILE


def main(argv=None):
    """The renderer's entry: one JSON argument ``{"folder", "title", "size"}``."""
    import pyvista as pv

    pv.OFF_SCREEN = True
    job = json.loads((argv or sys.argv[1:])[0])
    report = {"written": [], "skipped": {}}
    try:
        report["written"].append(render(pv, job["folder"], job["title"], job["size"]))
    except Exception as e:  # noqa: BLE001 - reported, the run's results stand
        report["skipped"][FILE] = f"{type(e).__name__}: {e}"
    print(json.dumps(report))
