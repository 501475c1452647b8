"""The 3D solid of a beam: its section swept along the centre line, meshed with gmsh.

The section lies in the beam's reference section frame at the start (t0, e2, e3 of
:func:`beamfx.physics.kinematics.section_frame`, with the beam's orientation vector and twist,
:func:`beamfx.geometry.frames.frame_from_tangent`): a rectangle has ``w`` along e2 and ``h``
along e3; a circle or tube is centred on the centre line. A :class:`~beamfx.geometry.Line` is
swept by an extrusion and an :class:`~beamfx.geometry.Arc` by a revolution about the arc's
axis, both with ``layers`` structured layers of cells (OpenCASCADE, exact geometry). With
``cell="hexahedron"`` (rectangles only) the section is a transfinite quadrilateral grid and the
layers are hexahedra; otherwise the section is triangulated and each prism of a layer is split
into three tetrahedra. The geometry is quadratic (``setOrder(2)``) to match P2/Q2 fields.

Tags: volume 1, start face 11, end face 12.
"""

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..geometry.frames import frame_from_tangent

VOLUME, START, END = 1, 11, 12
CELLS = ("tetrahedron", "hexahedron")


@dataclass(frozen=True)
class SolidMesh:
    """Options of the swept mesh: ``section_cells`` cells across the section's smallest size
    (the wall of a tube), ``layers`` cells along the centre line (None: chosen so that a cell
    is at most ``aspect`` times longer than wide)."""

    section_cells: int = 2
    layers: int | None = None
    cell: str = "hexahedron"
    aspect: float = 8.0


class Frame(NamedTuple):
    """Centroid and section axes (t0, e2, e3) of an end face, reference configuration."""

    centre: np.ndarray
    t0: np.ndarray
    e2: np.ndarray
    e3: np.ndarray


class SweepError(ValueError):
    """A solid that cannot be built; ``key`` names the scene key at fault (curve, section) or
    the mesh option."""

    def __init__(self, key, message):
        super().__init__(message)
        self.key = key


def _unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


def start_frame(beam):
    """Section frame at the start of ``beam``, the beam's own (orientation, twist_deg)."""
    t0, e2, e3 = frame_from_tangent(_start_tangent(beam.curve), beam.orientation, beam.twist_deg).T
    return Frame(np.asarray(beam.curve.start, float), t0, e2, e3)


def _start_tangent(curve):
    from ..geometry import Arc, Line

    if isinstance(curve, Line):
        t0 = _unit(np.subtract(curve.end, curve.start))
    elif isinstance(curve, Arc):
        e_r = _unit(np.subtract(curve.start, curve.centre))
        t = np.asarray(curve.start_tangent, float)
        t0 = _unit(t - (t @ e_r) * e_r)
    else:
        raise ValueError(  # noqa: TRY004 (a scene input, reported as SceneError)
            f"the solid sweeps lines and arcs only, not a {type(curve).__name__.lower()}"
        )
    return t0


def carried_frame(beam, fraction=1.0):
    """The start frame carried along ``fraction`` of the curve (translated along a line, turned
    with an arc): the section of the swept solid there."""
    from ..geometry import Arc

    f, curve = start_frame(beam), beam.curve
    if not isinstance(curve, Arc):
        return Frame(f.centre + fraction * curve.length * f.t0, f.t0, f.e2, f.e3)
    R = rotation_matrix(arc_axis(curve), math.radians(fraction * curve.angle_deg))
    return Frame(curve.points([fraction * curve.length])[0], R @ f.t0, R @ f.e2, R @ f.e3)


def end_frame(beam):
    """The section frame of the solid's end face."""
    return carried_frame(beam)


def frame_turn_deg(beam, samples=9):
    """Largest angle (degrees) between the beam's section axes and the solid's (the start
    section carried along the curve), at ``samples`` points; zero on a line, and on an arc
    whose orientation vector lies along its axis or in its plane."""
    turn = 0.0
    for fraction in np.linspace(0.0, 1.0, samples):
        f = carried_frame(beam, fraction)
        e3 = frame_from_tangent(f.t0, beam.orientation, beam.twist_deg)[:, 2]
        turn = max(turn, math.degrees(math.acos(min(1.0, abs(e3 @ f.e3)))))
    return turn


def arc_axis(curve):
    """Unit axis a of an arc: turning the start about a (through the centre) follows it."""
    e_r = _unit(np.subtract(curve.start, curve.centre))
    return _unit(np.cross(e_r, _start_tangent(curve)))


def rotation_matrix(axis, angle):
    """Rodrigues: I + sin φ hat(a) + (1 − cos φ) hat(a)²."""
    a = _unit(axis)
    A = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(angle) * A + (1 - math.cos(angle)) * A @ A


def section_sizes(section):
    """(kind, extent along e2, extent along e3, smallest size to resolve) of a section."""
    shape = tuple(section.shape)
    if not shape:
        raise ValueError(
            "a 'general' section has stiffnesses only; the solid needs a rectangle, circle or tube"
        )
    if shape[0] == "rectangle":
        _, h, w = shape
        return "rectangle", w, h, min(h, w)
    _, d, di = shape
    return ("tube" if di > 0 else "circle"), d, d, ((d - di) / 2 if di > 0 else d)


def check_sweep(beam, options):
    """Reasons the sweep cannot be built or resolved, raised as ValueError (caller adds where).

    An arc whose radius is not larger than the section's half-extent towards its centre would
    sweep a self-intersecting solid; fewer than one cell across the smallest section size (two
    for a solid section) does not resolve it.
    """
    from ..geometry import Arc

    kind, a2, a3, smallest = section_sizes(beam.section)
    turn = frame_turn_deg(beam) if isinstance(beam.curve, Arc) and kind == "rectangle" else 0.0
    if turn > 1e-6:
        raise SweepError(
            "orientation",
            f"the beam's section axes turn by up to {turn:.3g}° against the arc "
            "(its orientation vector is neither along the arc's axis nor in its plane); the "
            "solid revolves the section rigidly: give an orientation along the axis "
            f"{np.round(arc_axis(beam.curve), 6).tolist()} or in the arc's plane",
        )
    if isinstance(beam.curve, Arc):
        f = start_frame(beam)
        e_r = _unit(np.subtract(beam.curve.centre, beam.curve.start))
        half = 0.5 * (a2 * abs(e_r @ f.e2) + a3 * abs(e_r @ f.e3))  # rectangle's support
        if kind != "rectangle":
            half = a2 / 2
        if beam.curve.radius <= half * (1 + 1e-9):
            raise SweepError(
                "curve",
                f"arc radius {beam.curve.radius:g} is not larger than the section's half-size "
                f"{half:g} towards the centre: the swept solid would intersect itself",
            )
    if options.cell not in CELLS:
        raise SweepError("cell", f"cell {options.cell!r} not allowed; allowed: {list(CELLS)}")
    if options.cell == "hexahedron" and kind != "rectangle":
        raise SweepError(
            "cell", f"hexahedra need a rectangular section, not a {kind}; use tetrahedron"
        )
    need = 1 if kind == "tube" else 2
    if options.section_cells < need:
        raise SweepError(
            "section_cells",
            f"section_cells = {options.section_cells} does not resolve the {kind} section "
            f"(smallest size {smallest:g}); use at least {need} cells across it",
        )
    if options.layers is not None and options.layers < 1:
        raise SweepError("layers", f"layers = {options.layers} must be at least 1")
    size = smallest / options.section_cells
    layers = options.layers or math.ceil(beam.curve.length / (options.aspect * size))
    if beam.curve.length / layers > 50 * size:
        raise SweepError(
            "layers",
            f"layers = {layers} gives cells {beam.curve.length / layers / size:.0f} times longer "
            "than wide (more than 50): too coarse along the centre line",
        )
    return size, layers


def _section_surface(occ, section):
    """The section in the local xy plane (x = e2, y = e3), centred at the origin."""
    kind, a2, a3, _ = section_sizes(section)
    if kind == "rectangle":
        return occ.addRectangle(-a2 / 2, -a3 / 2, 0, a2, a3)
    outer = occ.addDisk(0, 0, 0, a2 / 2, a2 / 2)
    if kind == "circle":
        return outer
    inner = occ.addDisk(0, 0, 0, section.shape[2] / 2, section.shape[2] / 2)
    return occ.cut([(2, outer)], [(2, inner)])[0][0][1]


def build_solid(comm, beam, options=None):
    """Mesh the solid of ``beam`` (collective; gmsh runs on rank 0).

    Returns:
        (mesh, cell_tags, facet_tags, info) with info = dict(size, layers, cells).

    Raises:
        ValueError: the sweep is impossible or the mesh too coarse (see :func:`check_sweep`),
            or gmsh failed.
    """
    import gmsh
    from dolfinx.io import gmshio

    from ..geometry import Arc

    options = options or SolidMesh()
    size, layers = check_sweep(beam, options)
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        if comm.rank == 0:
            _sweep(gmsh, beam, options, size, layers, isinstance(beam.curve, Arc))
        mesh, cell_tags, facet_tags = gmshio.model_to_mesh(gmsh.model, comm, 0, gdim=3)
    finally:
        gmsh.finalize()
    return mesh, cell_tags, facet_tags, {"size": size, "layers": layers, "cell": options.cell}


def _sweep(gmsh, beam, options, size, layers, is_arc):
    gmsh.model.add("solid")
    occ = gmsh.model.occ
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.option.setNumber("Mesh.MeshSizeMin", size)
    gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 0)
    f = start_frame(beam)
    s = _section_surface(occ, beam.section)
    M = np.column_stack([f.e2, f.e3, f.t0, f.centre])
    occ.affineTransform([(2, s)], M.ravel().tolist())
    hexes = options.cell == "hexahedron"
    if hexes:  # a transfinite grid of quadrilaterals, about ``size`` square
        occ.synchronize()
        for _, c in gmsh.model.getBoundary([(2, s)], oriented=False):
            n = max(1, round(occ.getMass(1, abs(c)) / size))
            gmsh.model.mesh.setTransfiniteCurve(abs(c), n + 1)
        gmsh.model.mesh.setTransfiniteSurface(s)
        gmsh.model.mesh.setRecombine(2, s)
    try:
        if is_arc:
            c, a = np.asarray(beam.curve.centre, float), arc_axis(beam.curve)
            out = occ.revolve(
                [(2, s)], *c, *a, math.radians(beam.curve.angle_deg), [layers], [], hexes
            )
        else:
            out = occ.extrude([(2, s)], *(beam.curve.length * f.t0), [layers], [], hexes)
        occ.synchronize()
        top = next(t for d, t in out if d == 2)
        vol = [t for d, t in out if d == 3]
        gmsh.model.addPhysicalGroup(3, vol, VOLUME)
        gmsh.model.addPhysicalGroup(2, [s], START)
        gmsh.model.addPhysicalGroup(2, [top], END)
        gmsh.model.mesh.generate(3)
        gmsh.model.mesh.setOrder(2)
    except Exception as e:  # noqa: BLE001 (gmsh raises bare Exceptions with its log)
        raise SweepError("section", f"gmsh could not sweep the section: {e}") from None
