"""Show the results of ``beamfx run`` in ParaView: the beam's section swept along the deformed
centre line, coloured by |u|, over the undeformed centre line in grey.

``beamfx run`` copies this file into its output folder. From there:

    paraview --script=open_in_paraview.py            # interactive
    pvpython open_in_paraview.py --png beam.png      # a picture (off-screen)

Without a display (Debian's ParaView renders through X only) prefix ``xvfb-run -a``. Runs in
ParaView's own Python: it imports nothing from beamfx. Reads ``deformed.pvd`` (the centre
line, arrays X, u, e1..e3, N, M), ``surface.pvd`` (the surface, arrays u, N, M) and
``reactions.pvd`` (the supports, drawn as red dots; arrays force, moment) where present, beside
it or in the folder given with ``--dir``.
"""

import argparse
import os
import sys

import paraview.simple as pvs

# view direction from the scene towards the camera, and the up vector (global axes)
VIEW_DIRECTION = (1.0, -1.0, 0.8)
VIEW_UP = (0.0, 0.0, 1.0)


# the folder this copy was written to (set by beamfx when it copies the script)
WRITTEN_TO = None


def _default_dir():
    try:
        return os.path.dirname(os.path.abspath(__file__))
    except NameError:  # paraview --script=... runs the code without __file__ (and argv)
        if os.path.exists("deformed.pvd") or not WRITTEN_TO:
            return os.getcwd()
        return WRITTEN_TO


def _time_label(folder, time):
    """Frame label ("load factor 1", "t = 0.2 s" or "mode 3") from the analysis in results.json
    (written at the end of a run; a run still going is labelled by its step value)."""
    import json

    try:
        with open(os.path.join(folder, "results.json"), encoding="utf-8") as f:
            analysis = json.load(f).get("analysis")
    except (OSError, ValueError):
        analysis = None
    if analysis == "transient":
        return f"t = {time:g} s"
    if analysis in ("modal", "buckling"):
        return f"mode {time:g}"
    return f"load factor {time:g}" if analysis else f"step value {time:g}"


def _last_time(reader):
    times = list(reader.TimestepValues) if reader.TimestepValues else [0.0]
    return times[-1]


def show_results(folder, view=None, time=None):
    """Load and show the two series of ``folder``; returns a dict of the proxies.

    Args:
        folder: the results folder (deformed.pvd; surface.pvd if present).
        view: a render view (the active one if None).
        time: the load factor to show (the last one if None).
    """
    view = view or pvs.GetActiveViewOrCreate("RenderView")
    out = {"view": view}
    line = pvs.PVDReader(FileName=os.path.join(folder, "deformed.pvd"))
    out["deformed"] = line
    time = _last_time(line) if time is None else time
    # undeformed centre line: the points moved back to the reference positions X
    ref = pvs.Calculator(Input=line, ResultArrayName="X_ref", Function="X")
    ref.CoordinateResults = 1
    ref_show = pvs.Show(ref, view)
    ref_show.ColorArrayName = ["POINTS", ""]
    ref_show.AmbientColor = ref_show.DiffuseColor = (0.55, 0.55, 0.55)
    ref_show.LineWidth = 3.0
    ref_show.RenderLinesAsTubes = 1
    out["undeformed"] = ref

    surface_file = os.path.join(folder, "surface.pvd")
    if os.path.exists(surface_file):
        surface = pvs.PVDReader(FileName=surface_file)
        normals = pvs.GenerateSurfaceNormals(Input=pvs.ExtractSurface(Input=surface))
        normals.FeatureAngle = 40.0  # sharp rectangle edges, smooth circles
        shown, out["surface"] = normals, surface
    else:  # no section outline: draw the deformed centre line itself
        shown = line
    disp = pvs.Show(shown, view)
    pvs.ColorBy(disp, ("POINTS", "u", "Magnitude"))
    lut = pvs.GetColorTransferFunction("u")
    lut.ApplyPreset("Viridis (matplotlib)", True)
    disp.LineWidth = 4.0
    disp.Specular = 0.3
    disp.RescaleTransferFunctionToDataRange(False, True)
    disp.SetScalarBarVisibility(view, True)
    bar = pvs.GetScalarBar(lut, view)
    bar.Title, bar.ComponentTitle = "displacement", "magnitude"
    bar.TitleColor = bar.LabelColor = (0.1, 0.1, 0.1)
    bar.WindowLocation = "Upper Right Corner"
    bar.HorizontalTitle = 1
    bar.ScalarBarLength = 0.3
    bar.TitleFontSize, bar.LabelFontSize = 18, 16
    bar.RangeLabelFormat = "%-#.3g"
    out["display"] = disp

    reactions = show_reactions(folder, view)
    if reactions is not None:
        out["reactions"] = reactions

    name = os.path.basename(os.path.abspath(folder))
    label = pvs.Text(Text=f"{name}: {_time_label(folder, time)}")
    label_show = pvs.Show(label, view)
    label_show.WindowLocation = "Upper Left Corner"
    label_show.FontSize, label_show.Color = 18, (0.1, 0.1, 0.1)
    out["label"] = label
    view.ViewTime = time
    scene = pvs.GetAnimationScene()
    scene.UpdateAnimationUsingDataTimeSteps()
    scene.AnimationTime = time
    view.Background = (1.0, 1.0, 1.0)
    try:  # ParaView >= 5.10 has a background palette that overrides Background
        view.UseColorPaletteForBackground = 0
    except AttributeError:
        pass
    view.OrientationAxesVisibility = 1
    view.UseFXAA = 1  # anti-aliasing: thin beams and their edges without jaggies
    shown.UpdatePipeline(time)  # the colour range of the time shown, not of the first one
    disp.RescaleTransferFunctionToDataRange(False, True)
    fit_camera(view)
    return out


def show_reactions(folder, view):
    """Show ``reactions.pvd`` of ``folder`` (the supports; arrays force, moment) as red dots;
    its reader, or None if there is none."""
    path = os.path.join(folder, "reactions.pvd")
    if not os.path.exists(path):
        return None
    reactions = pvs.PVDReader(FileName=path)
    dots = pvs.Show(reactions, view)
    dots.SetRepresentationType("Points")
    dots.ColorArrayName = ["POINTS", ""]
    dots.AmbientColor = dots.DiffuseColor = (0.8, 0.1, 0.1)
    dots.PointSize = 12.0
    dots.RenderPointsAsSpheres = 1
    return reactions


def fit_camera(view, direction=VIEW_DIRECTION, up=VIEW_UP, zoom=0.95):
    """Look at everything shown from ``direction`` (towards the camera), ``up`` upwards,
    ``zoom`` times closer than ParaView's reset (which fits the bounding sphere; closer cuts
    off the near end of a beam that stands upright on the screen, magnified by perspective)."""
    pvs.Render(view)  # the first render resets the camera: do it before setting ours
    view.CameraFocalPoint = (0.0, 0.0, 0.0)
    view.CameraPosition = direction
    view.CameraViewUp = up
    view.CameraParallelProjection = 0
    view.ResetCamera(False)
    pvs.GetActiveCamera().Dolly(zoom)
    pvs.Render(view)


def save_png(view, path, size=(1200, 900)):
    """Render ``view`` at ``size`` pixels to ``path``, fonts at their size on screen."""
    view.ViewSize = list(size)
    fit_camera(view)  # the aspect ratio changed
    pvs.SaveScreenshot(path, view, ImageResolution=list(size), FontScaling="Do not scale fonts")


def main(argv=None):
    """Command line: open a results folder in ParaView, or save its picture (``--png``)."""
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--dir", default=_default_dir(), help="results folder (default: this one)")
    p.add_argument("--png", help="save a picture here instead of staying open")
    p.add_argument("--size", type=int, nargs=2, default=(1200, 900), metavar=("W", "H"))
    p.add_argument("--time", type=float, help="load factor to show (default: the last)")
    args, _ = p.parse_known_args(argv)
    shown = show_results(args.dir, time=args.time)
    if args.png:
        save_png(shown["view"], args.png, args.size)
    return shown


if __name__ == "__main__":
    main(sys.argv[1:])
