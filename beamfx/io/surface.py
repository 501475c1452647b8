"""The beam drawn as its section swept along the deformed centre line, for ParaView.

At every sample of the centre line the section outline, given as points (y, z) in the
section plane, is placed at x + y e2 + z e3, with (e1, e2, e3) = R·Λ0 the current section
axes (global axes). Consecutive outlines of one element are joined by quads; each beam is
closed by an end cap at its two ends. The samples are the k + 1 nodes of each element of
:func:`~beamfx.io.fields.nodal_fields` refined in NumPy (no new JIT form): positions X + u, N
and M by the element's Lagrange polynomials through its nodes (exact: u and the P_k geometry
are P_k, recovered N and M are of degree k − 1), the section axes the same way followed by
the nearest rotation (polar decomposition), which is accurate to the interpolation error.

Outlines, a list of closed loops each an (n, 2) array of (y, z), counter-clockwise about e1:

* rectangle: ``h`` along e3 (section z), ``w`` along e2 (section y), 4 corners;
* circle: diameter ``d``, ``segments`` points;
* tube: the outer circle and the inner one (``d_inner``), clockwise, so the quads face away
  from the material.

The outlines come from the ``shape`` of each beam's :class:`~beamfx.physics.sections.Section`
(:func:`model_outlines`; a non-prismatic beam is drawn with its mid-span section); a beam with
a ``general`` section (stiffnesses only) has no outline and is left out of the surface.

Point data of the surface: ``u`` the displacement of the centre line at the section's sample
(global axes; points of one section share it), ``N`` and ``M`` the section force and moment
(section axes), ``beam`` the beam index. Cells: VTK_QUAD along the beam and VTK_POLYGON (or,
for tubes, VTK_QUAD rings) as end caps.
"""

import os

import numpy as np
from mpi4py import MPI

from ._sections import lagrange_matrix
from .paraview import PvdSeries, write_unstructured_vtu

VTK_POLYGON, VTK_QUAD = 7, 9
CIRCLE_SEGMENTS = 32
SAMPLE_ARRAYS = ("u", "N", "M")


def circle_loop(d, segments=CIRCLE_SEGMENTS, clockwise=False):
    """(segments, 2) points (y, z) of a circle of diameter ``d`` about the centre line."""
    a = 2 * np.pi * np.arange(segments) / segments
    loop = 0.5 * d * np.stack([np.cos(a), np.sin(a)], axis=1)
    return loop[::-1] if clockwise else loop


def section_outline(type, h=None, w=None, d=None, d_inner=0.0, segments=CIRCLE_SEGMENTS):
    """Outline loops of a section (see the module docstring), None for ``general``.

    Args:
        type: "rectangle", "circle", "tube" or "general" (the scene's section types).
        h, w: rectangle height along e3 and width along e2.
        d, d_inner: outer and inner diameter of a circle or tube.
        segments: points per circle.
    """
    if type == "rectangle":
        y, z = w / 2, h / 2
        return [np.array([[-y, -z], [y, -z], [y, z], [-y, z]])]
    if type == "circle":
        return [circle_loop(d, segments)]
    if type == "tube":
        if not d_inner:
            return [circle_loop(d, segments)]
        return [circle_loop(d, segments), circle_loop(d_inner, segments, clockwise=True)]
    if type == "general":
        return None
    raise ValueError(f"unknown section type {type!r}")


def model_outlines(beams):
    """``{beam name: outline loops or None}`` of the beams' sections, from the section's
    ``shape`` (a non-prismatic beam is drawn with its mid-span section)."""
    out = {}
    for b in beams:
        shape = b.section.along([b.curve.length / 2])[0].shape
        if not shape:
            out[b.name] = None
        elif shape[0] == "rectangle":
            out[b.name] = section_outline("rectangle", h=shape[1], w=shape[2])
        else:
            out[b.name] = section_outline("tube", d=shape[1], d_inner=shape[2])
    return out


def refine(fields, degree, subdivisions=4):
    """Samples of the centre line: each element's k + 1 nodes refined to ``subdivisions`` + 1.

    Args:
        fields: the rank-0 dict of :func:`~beamfx.io.fields.nodal_fields`.
        degree: the element degree k.
        subdivisions: intervals per element (its samples are equally spaced in ξ).

    Returns:
        dict of arrays of shape (elements, subdivisions + 1, ...): ``x`` the current position,
        ``axes`` the current section axes as columns (3, 3), ``u``, ``N``, ``M``, and ``beam``
        (elements,).
    """
    k = degree
    n_el = len(fields["X"]) // (k + 1)
    A = lagrange_matrix(np.linspace(0, 1, k + 1), np.linspace(0, 1, subdivisions + 1))

    def per_element(a):
        return np.einsum("sn,en...->es...", A, np.asarray(a).reshape(n_el, k + 1, -1))

    out = {name: per_element(fields[name]) for name in SAMPLE_ARRAYS}
    out["x"] = per_element(np.asarray(fields["X"]) + np.asarray(fields["u"]))
    axes = np.stack([per_element(fields[e]) for e in ("e1", "e2", "e3")], axis=-1)
    U, _, Vt = np.linalg.svd(axes)  # nearest rotation: U Vᵀ (the sign is safe: axes ≈ R)
    out["axes"] = U @ Vt
    out["beam"] = np.asarray(fields["beam"]).reshape(n_el, k + 1)[:, 0].astype(np.int64)
    return out


def _caps(loops, first, last, n_per_ring):
    """End cap cells of one beam: ``first``/``last`` are the ring offsets of its ends."""
    cells = []
    for ring, flip in ((first, True), (last, False)):
        if len(loops) == 1:
            ids = ring + np.arange(n_per_ring)
            cells.append(ids[::-1] if flip else ids)
        elif len(loops) == 2 and len(loops[0]) == len(loops[1]):
            n = len(loops[0])
            outer = ring + np.arange(n)
            inner = ring + n + np.arange(n)[::-1]  # inner loop runs clockwise: re-align
            for j in range(n):
                q = np.array([outer[j], outer[(j + 1) % n], inner[(j + 1) % n], inner[j]])
                cells.append(q[::-1] if flip else q)
    return cells


def surface_mesh(fields, degree, beam_names, outlines, subdivisions=4):
    """Points, cells and point data of the swept section surface (rank-0 NumPy).

    Args:
        fields: the rank-0 dict of :func:`~beamfx.io.fields.nodal_fields`.
        degree: the element degree k.
        beam_names: names of the beams in beam-index order (``fields["beam"]``).
        outlines: ``{beam name: list of (n, 2) loops (y, z)}``; beams missing or None are
            left out.
        subdivisions: intervals per element along the centre line.

    Returns:
        (points (n, 3), cells (list of index arrays), cell types (m,), point data dict).
    """
    s = refine(fields, degree, subdivisions)
    points, cells, types, data = [], [], [], {name: [] for name in (*SAMPLE_ARRAYS, "beam")}
    n_points = 0
    for b, name in enumerate(beam_names):
        loops = outlines.get(name)
        if loops is None:
            continue
        loops = [np.asarray(lp, float).reshape(-1, 2) for lp in loops]
        yz = np.concatenate(loops)  # one ring = all loops of a section
        ring = len(yz)
        elements = np.flatnonzero(s["beam"] == b)
        first_ring = n_points
        for e in elements:
            x, axes = s["x"][e], s["axes"][e]  # (S, 3), (S, 3, 3)
            pts = x[:, None, :] + yz[None, :, 0, None] * axes[:, None, :, 1]
            pts = pts + yz[None, :, 1, None] * axes[:, None, :, 2]
            points.append(pts.reshape(-1, 3))
            for key in SAMPLE_ARRAYS:
                data[key].append(np.repeat(s[key][e], ring, axis=0))
            data["beam"].append(np.full(len(x) * ring, b, np.int64))
            start = 0
            for lp in loops:
                n = len(lp)
                j = np.arange(n)
                for i in range(len(x) - 1):
                    a = n_points + i * ring + start
                    c = a + ring
                    quads = np.stack([a + j, a + (j + 1) % n, c + (j + 1) % n, c + j], axis=1)
                    cells.extend(quads)
                    types.extend([VTK_QUAD] * n)
                start += n
            last_ring = n_points + (len(x) - 1) * ring
            n_points += len(x) * ring
        if len(elements):
            caps = _caps(loops, first_ring, last_ring, ring)
            cells.extend(caps)
            types.extend(VTK_QUAD if len(c) == 4 and len(loops) == 2 else VTK_POLYGON for c in caps)
    if not points:
        return np.zeros((0, 3)), [], np.zeros(0, np.uint8), {}
    data = {k: np.concatenate(v) for k, v in data.items()}
    return np.concatenate(points), cells, np.asarray(types, np.uint8), data


class SurfaceSeries:
    """``surface.pvd`` and one ``surface_NNNN.vtu`` per step; rank 0 writes.

    Args:
        path: the ".pvd" file; the .vtu files go beside it.
        degree: the element degree k of the model.
        beam_names: beam names in beam-index order.
        outlines: ``{beam name: loops}``, e.g. from :func:`model_outlines`.
        subdivisions: intervals per element along the centre line.
        comm: the communicator whose rank 0 writes.
    """

    def __init__(self, path, degree, beam_names, outlines, subdivisions=4, comm=MPI.COMM_WORLD):
        self.pvd = PvdSeries(path, comm)
        self.degree, self.beam_names, self.outlines = degree, list(beam_names), outlines
        self.subdivisions, self.comm = subdivisions, comm

    def add(self, step, time, fields):
        """Write the surface of ``fields`` (from ``nodal_fields``) as step number ``step``."""
        if self.comm.rank != 0:
            return
        stem = os.path.splitext(self.pvd.path)[0]
        vtu = f"{stem}_{step:04d}.vtu"
        mesh = surface_mesh(fields, self.degree, self.beam_names, self.outlines, self.subdivisions)
        if len(mesh[0]) == 0:  # no beam has a drawable section (all "general")
            return
        write_unstructured_vtu(vtu, *mesh)
        self.pvd.add(time, vtu)


def write_paraview_script(folder, comm=MPI.COMM_WORLD):
    """Copy ``open_in_paraview.py`` (a pvpython script showing the results) into ``folder``,
    with that folder's absolute path as the fallback for ``paraview --script`` (no __file__)."""
    if comm.rank != 0:
        return
    here = os.path.dirname(os.path.abspath(__file__))
    source = os.path.join(here, "pvscripts", "open_in_paraview.py")
    target = os.path.join(os.fspath(folder), "open_in_paraview.py")
    with open(source, encoding="utf-8") as f:
        text = f.read()
    folder = os.path.abspath(os.fspath(folder))
    text = text.replace("\nWRITTEN_TO = None\n", f"\nWRITTEN_TO = {folder!r}\n", 1)
    tmp = f"{target}.tmp{os.getpid()}"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(tmp, target)
