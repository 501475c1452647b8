"""Check that ParaView reads the results of ``beamfx run``, and render them off-screen.

Runs in ParaView's own Python and imports nothing from beamfx (only its sibling
``open_in_paraview.py``, by path):

    xvfb-run -a pvpython pvcheck.py RESULTS_DIR --png out.png [--tip X Y Z] [--tol T]

Opens ``deformed.pvd`` (``.vtu`` or, from several ranks, ``.pvtu`` frames of Lagrange curves),
and ``surface.pvd`` and ``deformed.xdmf`` where present, at the last time; checks the point
arrays each must carry and that the deformed centre line has a point within ``tol`` of ``tip``
(if given; the XDMF holds the reference line, so X + u there) and the surface one within
``tol`` plus half the section's size; reads ``reactions.pvd`` where present (a vertex per
support, arrays ``force`` and ``moment``; its times those of the deformed series, a
transient's without t = 0) and reports its last frame's values; renders the picture of
``open_in_paraview.py`` to ``--png``. Prints one JSON line with what it found; exit status 1 if
a check failed.
"""

import argparse
import json
import os
import sys

import numpy as np
import paraview.simple as pvs
from paraview import servermanager
from vtk.util.numpy_support import vtk_to_numpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import open_in_paraview  # the sibling script, found by path

REQUIRED = {
    "deformed.pvd": ("X", "u", "e1", "e2", "e3", "N", "M"),
    "deformed.xdmf": ("X", "u", "e1", "e2", "e3", "N", "M"),
    "surface.pvd": ("u", "N", "M"),
}
REACTIONS = "reactions.pvd"
REACTION_ARRAYS = ("force", "moment")


def read(path):
    """The dataset of ``path`` at its last time: (points (n, 3), {array: values}, times).

    A composite dataset (DOLFINx's XDMF: the mesh, then one grid per function) gives the
    points of its first block and the point arrays of all blocks of as many points."""
    reader = pvs.OpenDataFile(path)
    times = list(reader.TimestepValues) if reader.TimestepValues else [0.0]
    reader.UpdatePipeline(times[-1])
    blocks = _datasets(servermanager.Fetch(reader))
    points = vtk_to_numpy(blocks[0].GetPoints().GetData())
    arrays = {}
    for block in blocks:
        pd = block.GetPointData()
        if block.GetNumberOfPoints() != len(points):
            continue
        for i in range(pd.GetNumberOfArrays()):
            arrays.setdefault(pd.GetArrayName(i), vtk_to_numpy(pd.GetArray(i)))
    return points, arrays, times


def _datasets(data):
    """The leaf datasets (with points) of a composite dataset, or ``[data]``."""
    if not data.IsA("vtkCompositeDataSet"):
        return [data]
    out, it = [], data.NewIterator()
    it.InitTraversal()
    while not it.IsDoneWithTraversal():
        leaf = it.GetCurrentDataObject()
        if leaf is not None and leaf.GetNumberOfPoints():
            out.append(leaf)
        it.GoToNextItem()
    return out


def check(folder, tip=None, tol=0.5):
    """Summary dict of the three files and a list of failed checks."""
    found, failed = {}, []
    for name, required in REQUIRED.items():
        if name != "deformed.pvd" and not os.path.exists(os.path.join(folder, name)):
            continue
        points, arrays, times = read(os.path.join(folder, name))
        if name.endswith(".xdmf") and "u" in arrays:  # reference geometry + displacement
            points = points + arrays["u"]
        entry = {
            "points": len(points),
            "times": len(times),
            "last_time": times[-1],
            "arrays": sorted(arrays),
            "bounds": np.c_[points.min(0), points.max(0)].ravel().tolist(),
        }
        missing = [a for a in required if a not in arrays]
        if missing:
            failed.append(f"{name}: missing arrays {missing}")
        if tip is not None:
            gap = float(np.min(np.linalg.norm(points - np.asarray(tip), axis=1)))
            entry["distance_to_tip"] = gap
            allowed = tol
            if name == "surface.pvd":  # the tip cap's corners: half the section's diagonal
                allowed += _section_radius(points, arrays)
            if gap > allowed:
                failed.append(f"{name}: no point within {allowed:.3g} of the tip {tip} ({gap:.3g})")
        found[name] = entry
    n = {entry["times"] for entry in found.values()}
    if len(n) != 1:
        failed.append(f"the files hold different numbers of time steps: {n}")
    if os.path.exists(os.path.join(folder, REACTIONS)):
        found[REACTIONS] = check_reactions(folder, found["deformed.pvd"], failed)
    return found, failed


def check_reactions(folder, deformed, failed):
    """The reactions series: its arrays, its last time that of ``deformed`` (the entry of
    deformed.pvd), and the values of its last frame (positions, force, moment per point)."""
    points, arrays, times = read(os.path.join(folder, REACTIONS))
    missing = [a for a in REACTION_ARRAYS if a not in arrays]
    if missing:
        failed.append(f"{REACTIONS}: missing arrays {missing}")
    if times[-1] != deformed["last_time"] or len(times) not in (
        deformed["times"],
        deformed["times"] - 1,
    ):
        failed.append(f"{REACTIONS}: times {times} do not follow the deformed series'")
    entry = {"points": len(points), "times": len(times), "last_time": times[-1]}
    entry["positions"] = points.tolist()
    entry.update({a: arrays[a].tolist() for a in REACTION_ARRAYS if a in arrays})
    return entry


def _section_radius(points, arrays):
    """Largest distance of a surface point from the centre line (u equal within a section)."""
    u = arrays["u"]
    ends = np.flatnonzero(np.any(np.abs(np.diff(u, axis=0)) > 0, axis=1)) + 1
    radius = 0.0
    for ring in np.split(points, ends):
        radius = max(radius, float(np.max(np.linalg.norm(ring - ring.mean(0), axis=1))))
    return radius


def image_stats(path):
    """Colours in the PNG at ``path``: distinct ones and the share of non-background pixels
    (the background is the most frequent colour)."""
    from vtkmodules.vtkIOImage import vtkPNGReader

    reader = vtkPNGReader()
    reader.SetFileName(path)
    reader.Update()
    image = reader.GetOutput()
    rgb = vtk_to_numpy(image.GetPointData().GetScalars())[:, :3]
    colours, counts = np.unique(rgb, axis=0, return_counts=True)
    return {
        "size": list(image.GetDimensions()[:2]),
        "colours": len(colours),
        "foreground": float(1 - counts.max() / counts.sum()),
    }


def main(argv=None):
    """Command line: check a results folder in pvpython (tip position, picture)."""
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("dir", help="results folder of beamfx run")
    p.add_argument("--png", help="render the picture to this file")
    p.add_argument("--tip", type=float, nargs=3, help="expected deformed tip position")
    p.add_argument("--tol", type=float, default=0.5, help="tolerance of the tip position")
    p.add_argument("--size", type=int, nargs=2, default=(800, 600), metavar=("W", "H"))
    args = p.parse_args(argv)
    # Render before fetching data (rendering after servermanager.Fetch fails with GLXBadContext
    # under Xvfb), and delete the view before exit (else pvpython segfaults in its teardown).
    view = None
    if args.png:
        view = open_in_paraview.show_results(args.dir)["view"]
        open_in_paraview.save_png(view, args.png, args.size)
    found, failed = check(args.dir, args.tip, args.tol)
    if view is not None:
        pvs.Delete(view)
        found["png"] = {"path": os.path.abspath(args.png), **image_stats(args.png)}
    print(json.dumps({"ok": not failed, "failed": failed, "files": found}))
    return 0 if not failed else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
