"""Pictures of a run (``beamfx run --png``): the beam drawn as its section surface, coloured by
|u|, over the undeformed one in grey, rendered off-screen with pyvista.

What is drawn is what ParaView shows (``surface.pvd``, ``deformed.pvd``; see
:mod:`beamfx.io.surface`): the final state of a static, arc-length or rotating run and of a
transient (``deformed.png``), one picture per mode of a modal or buckling run (``mode_01.png``
…, the shape as written for ParaView: added to the state, scaled so that its largest
displacement is a tenth of the model's size), and with ``animate`` every frame of a transient
(``animation.gif``, at most :data:`MAX_FRAMES`). Beams without a section outline (``general``
sections) are drawn as their centre line.

The undeformed section surface (``undeformed.vtu``) is written before the solve by
:func:`write_undeformed`. The pictures are rendered after the solve in a separate Python
process (:func:`write_pictures`): VTK's wheel can abort inside a process that imported dolfinx
first (see the DOLFINx notes), and a crash there must not lose the results. If pyvista is
missing or rendering fails, the run goes on and the log names the pictures skipped and why.
"""

import json
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

import numpy as np

MAX_FRAMES = 120
SIZE = (1000, 750)
GIF_SIZE = (800, 600)  # each frame is rendered in software: smaller is faster
VIEW_DIRECTION = (1.0, -1.0, 0.8)  # from the scene towards the camera (global axes)
GREY = (0.62, 0.62, 0.62)
SCALAR_BAR = {
    "color": "black",
    "fmt": "%.3g",
    "n_labels": 5,
    "vertical": True,
    "position_x": 0.86,
    "position_y": 0.2,
    "height": 0.6,
    "width": 0.06,
    "title_font_size": 16,
    "label_font_size": 14,
}
CHILD = "import pyvista; from beamfx.io.pictures import main; main()"  # pyvista before dolfinx


def write_undeformed(folder, model, beam_names, outlines):
    """``undeformed.vtu``: the section surface of the reference state. Collective; call it
    before the solve (``model.w`` still zero)."""
    from .fields import nodal_fields
    from .surface import surface_grid, surface_mesh
    from .vtkfiles import write_grid

    fields = nodal_fields(model)  # gathered: one small file, once
    if model.comm.rank != 0:
        return
    path = os.path.join(folder, "undeformed.vtu")
    if os.path.exists(path):  # of an earlier run, perhaps of another scene
        os.remove(path)
    if not any(v is not None for v in outlines.values()):
        return
    mesh = surface_mesh(fields, model.degree, beam_names, outlines)
    if len(mesh.points):
        write_grid(path, surface_grid(mesh))


def picture_plan(results, animate=False):
    """The pictures of a run from its results dict: a list of ``{"file", "frames", "label"}``,
    frames being indices into the ParaView series (-1 the last), labels with ``{time}``."""
    analysis = results.get("analysis")
    if analysis in ("modal", "buckling"):
        if analysis == "modal":
            values = [f"{f:.4g} Hz" for f in results.get("frequencies_hz", [])]
        else:
            values = [f"load factor {x:.4g}" for x in results.get("load_factors", [])]
        return [
            {
                "file": f"mode_{i:02d}.png",
                "frames": [i - 1],
                "label": f"mode {i}: {v}",
                "bar": "mode shape",
            }
            for i, v in enumerate(values, start=1)
        ]
    label = {"transient": "t = {time:g} s", "rotating": "speed {time:g}"}.get(
        analysis, "load factor {time:g}"
    )
    plan = [{"file": "deformed.png", "frames": [-1], "label": label}]
    if animate and analysis == "transient":
        plan.append({"file": "animation.gif", "frames": "all", "label": label})
    return plan


def _skip(plan, reason, log):
    names = ", ".join(p["file"] for p in plan)
    log(f"pictures skipped ({names}): {reason}")
    return {"written": [], "skipped": {p["file"]: reason for p in plan}}


def write_pictures(folder, results, log=print, animate=False, size=SIZE, timeout=900, comm=None):
    """Render the pictures of :func:`picture_plan` into ``folder`` (rank 0 only; the others
    return None). Never raises for a missing or failing renderer: the log says what was skipped.

    Returns:
        ``{"written": [file names], "skipped": {file name: reason}}``.
    """
    from mpi4py import MPI

    if (comm or MPI.COMM_WORLD).rank != 0:
        return None
    plan = picture_plan(results, animate)
    if not plan:
        return {"written": [], "skipped": {}}
    job = {"folder": os.fspath(folder), "plan": plan, "size": list(size)}
    return render_in_child(CHILD, job, [item["file"] for item in plan], log, timeout)


def render_in_child(child, job, files, log=print, timeout=900):
    """Run the renderer ``child`` (Python code that imports pyvista before anything else) on
    the JSON ``job`` in a separate process; its last output line is the JSON report
    ``{"written": [...], "skipped": {file: reason}}``. Files it could not make (pyvista
    missing, a crash, a timeout) are reported as skipped with the reason, never raised."""
    from importlib.util import find_spec

    folder = job["folder"]
    plan = [{"file": f} for f in files]
    if find_spec("pyvista") is None:
        return _skip(plan, "pyvista is not installed (pip install pyvista)", log)
    # without the variables of mpirun: the child (which imports mpi4py) is a process of its
    # own, and MPI_Init under a rank's settings aborts it
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_"))}
    env.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    try:
        done = subprocess.run(
            [sys.executable, "-c", child, json.dumps(job)],
            capture_output=True,
            text=True,
            env=env,
            check=False,
            timeout=timeout,
        )
    except (OSError, subprocess.TimeoutExpired) as e:
        return _skip(plan, f"the renderer did not run: {e}", log)
    try:
        report = json.loads(done.stdout.strip().splitlines()[-1])
    except (IndexError, ValueError):
        tail = " ".join((done.stderr or "").strip().splitlines()[-2:])
        return _skip(plan, f"the renderer failed (exit status {done.returncode}): {tail}", log)
    for name in report["written"]:
        log(f"picture: {os.path.join(os.fspath(folder), name)}")
    if report["skipped"]:
        for name, reason in report["skipped"].items():
            log(f"picture skipped ({name}): {reason}")
    return report


# --- the renderer (child process: pyvista imported first, no dolfinx) ------------------------


def read_pvd(path):
    """[(time, absolute file name)] of a ParaView collection file."""
    root = ET.parse(path).getroot()
    folder = os.path.dirname(os.path.abspath(path))
    return [
        (float(d.get("timestep", 0.0)), os.path.join(folder, d.get("file")))
        for d in root.iter("DataSet")
    ]


def _frames(folder):
    """Per ParaView step: (time, surface .vtu or None, centre line .vtu)."""
    lines = read_pvd(os.path.join(folder, "deformed.pvd"))
    surface_pvd = os.path.join(folder, "surface.pvd")
    surfaces = dict(read_pvd(surface_pvd)) if os.path.exists(surface_pvd) else {}
    return [(t, surfaces.get(t), line) for t, line in lines]


def _line_beams(pv, line, surface):
    """The centre line cells of beams that the surface leaves out (no section outline), as
    polylines through the nodes of each cell (a VTK Lagrange curve lists its two ends first,
    then the interior nodes), with the point arrays."""
    drawn = set() if surface is None else set(np.unique(surface.cell_data["beam"]).tolist())
    keep = ~np.isin(np.asarray(line.cell_data["beam"]), list(drawn))
    if not keep.any():
        return None
    conn, offsets = np.asarray(line.cell_connectivity), np.asarray(line.cell_offsets)
    lines = []
    for c in np.flatnonzero(keep):
        ids = conn[offsets[c] : offsets[c + 1]]
        path = np.r_[ids[0], ids[2:], ids[1]] if len(ids) > 2 else ids
        lines.append(np.r_[len(path), path])
    poly = pv.PolyData(np.asarray(line.points), lines=np.concatenate(lines))
    for name in line.point_data:
        poly.point_data[name] = line.point_data[name]
    return poly


def _load(pv, frame):
    """(deformed surface or None, deformed centre line or None, reference centre line)."""
    _, surface_file, line_file = frame
    surface = _single(pv, pv.read(surface_file)) if surface_file else None
    line = _line_beams(pv, _single(pv, pv.read(line_file)), surface)
    reference = None
    if line is not None:
        if "X" in line.point_data:
            reference = line.copy()
            reference.points = np.asarray(line.point_data["X"])
        line.point_data["|u|"] = _magnitude(line, "u")
    if surface is not None:
        surface = surface.extract_surface().compute_normals(feature_angle=40.0, split_vertices=True)
        surface.point_data["|u|"] = _magnitude(surface, "u")
    return surface, line, reference


def _single(pv, data):
    """One grid of a frame (the pieces of a parallel run's .pvtu come as one already)."""
    return data.combine() if isinstance(data, pv.MultiBlock) else data


def _magnitude(mesh, name):
    """|a| of the point array ``name``, zero if the frames do not carry it."""
    if name not in mesh.point_data:
        return np.zeros(mesh.n_points)
    return np.linalg.norm(mesh.point_data[name], axis=1)


def _camera(plotter, bounds):
    """Look along :data:`VIEW_DIRECTION`, z up; a flat model is seen face on."""
    b = np.asarray(bounds).reshape(3, 2)
    extent = b[:, 1] - b[:, 0]
    flat = np.flatnonzero(extent < 1e-6 * max(extent.max(), 1e-300))
    direction, up = VIEW_DIRECTION, (0.0, 0.0, 1.0)
    if len(flat) == 1:
        direction = np.eye(3)[flat[0]] * (-1 if flat[0] == 1 else 1)
        up = (0.0, 1.0, 0.0) if flat[0] == 2 else (0.0, 0.0, 1.0)
    plotter.camera_position = [tuple(b.mean(1) + np.asarray(direction)), tuple(b.mean(1)), up]
    plotter.reset_camera(bounds=list(bounds), render=False)
    plotter.camera.zoom(0.95)


def _union(bounds):
    b = np.asarray(bounds).reshape(len(bounds), 3, 2)
    return np.c_[b[:, :, 0].min(0), b[:, :, 1].max(0)].ravel().tolist()


class _Scene:
    """One plotter: the undeformed beam in grey, the current one coloured by |u|; camera and
    colour range fixed (frames of an animation share them). Nothing renders until a
    screenshot or GIF frame (software rendering: each render costs)."""

    def __init__(self, pv, folder, size, clim, bounds, title):
        self.clim, self.title = clim, title
        self.plotter = p = pv.Plotter(off_screen=True, window_size=list(size))
        p.set_background("white")
        p.enable_anti_aliasing("msaa")  # FXAA is not supported with EGL
        undeformed = os.path.join(folder, "undeformed.vtu")
        if os.path.exists(undeformed):
            grey = pv.read(undeformed).extract_surface()
            p.add_mesh(grey, color=GREY, opacity=0.45, smooth_shading=True, render=False)
        p.add_axes(color="black")
        _camera(p, bounds)
        self.name = os.path.basename(os.path.abspath(folder))

    def show(self, surface, line, reference, label):
        p, bar = self.plotter, dict(SCALAR_BAR, title=self.title)
        common = {"scalars": "|u|", "cmap": "viridis", "clim": self.clim, "render": False}
        common["scalar_bar_args"] = bar
        if reference is not None:
            p.add_mesh(
                reference,
                color=GREY,
                line_width=4,
                render_lines_as_tubes=True,
                name="reference_line",
                render=False,
            )
        if surface is not None:
            p.add_mesh(surface, smooth_shading=True, specular=0.3, name="surface", **common)
        if line is not None:
            p.add_mesh(line, render_lines_as_tubes=True, line_width=6, name="line", **common)
        p.add_text(
            f"{self.name}: {label}",
            position="upper_left",
            font_size=12,
            color="black",
            name="label",
            render=False,
        )


def _clim(meshes):
    top = max((float(np.max(m.point_data["|u|"], initial=0.0)) for m in meshes if m), default=0)
    return [0.0, top or 1.0]


def render(pv, folder, item, frames, size):
    """Render one plan item (see :func:`picture_plan`) from the ``frames`` of ``folder``."""
    chosen = range(len(frames)) if item["frames"] == "all" else item["frames"]
    chosen = [range(len(frames))[i] for i in chosen]
    if len(chosen) > MAX_FRAMES:  # keep the first and the last
        chosen = [
            chosen[i] for i in np.linspace(0, len(chosen) - 1, MAX_FRAMES).round().astype(int)
        ]
    loaded = [(frames[i][0], *_load(pv, frames[i])) for i in chosen]
    meshes = [m for _, s, ln, r in loaded for m in (s, ln, r) if m is not None]
    undeformed = os.path.join(folder, "undeformed.vtu")
    if os.path.exists(undeformed):
        meshes.append(pv.read(undeformed))
    clim = _clim([m for _, s, ln, _ in loaded for m in (s, ln)])
    bounds = _union([m.bounds for m in meshes])
    path = os.path.join(folder, item["file"])
    if path.endswith(".gif"):
        size = [min(a, b) for a, b in zip(size, GIF_SIZE)]
    scene = _Scene(pv, folder, size, clim, bounds, item.get("bar", "displacement"))
    if item["file"].endswith(".gif"):
        scene.plotter.open_gif(path, fps=min(20, max(5, len(loaded) // 6)))
    for t, surface, line, reference in loaded:
        scene.show(surface, line, reference, item["label"].format(time=t))
        if path.endswith(".gif"):
            scene.plotter.write_frame()
    if not path.endswith(".gif"):
        scene.plotter.screenshot(path)
    scene.plotter.close()
    return item["file"]


def main(argv=None):
    """The renderer's entry: one JSON argument ``{"folder", "plan", "size"}``; prints one JSON
    line ``{"written": [...], "skipped": {file: reason}}``."""
    import pyvista as pv

    pv.OFF_SCREEN = True
    job = json.loads((argv or sys.argv[1:])[0])
    folder, report = job["folder"], {"written": [], "skipped": {}}
    try:
        frames = _frames(folder)
        if not frames:
            raise ValueError("no ParaView steps were written")
    except (OSError, ValueError, ET.ParseError) as e:
        report["skipped"] = {item["file"]: f"cannot read the results: {e}" for item in job["plan"]}
        frames = None
    for item in job["plan"] if frames else ():
        try:
            report["written"].append(render(pv, folder, item, frames, job["size"]))
        except Exception as e:  # noqa: BLE001 - one picture failing leaves the others
            report["skipped"][item["file"]] = f"{type(e).__name__}: {e}"
    print(json.dumps(report))
