"""The beam drawn as its section swept along the deformed centre line, for ParaView.

At every sample of the centre line the section outline, given as points (y, z) in the
section plane, is placed at x + y e2 + z e3, with (e1, e2, e3) = R·Λ0 the current section
axes (global axes). Consecutive outlines of one element are joined by quads; each beam is
closed by an end cap at its two ends. The samples are the k + 1 nodes of each element of
:func:`~beamfx.io.fields.nodal_fields` refined in NumPy (no new JIT form): positions X + u, N
and M by the element's Lagrange polynomials through its nodes (exact: u and the P_k geometry
are P_k, recovered N and M are of degree k − 1), the section axes the same way followed,
between the nodes, by the nearest rotation (polar decomposition), which is accurate to the
interpolation error; a sample at a node has the node's axes (a rotation: R·Λ0).
The cells are the same at every frame of a run: :class:`SweptSurface` makes them once
(:mod:`beamfx.io.surface_cells`) and a frame only its points and point arrays (:func:`sweep`).

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
(section axes). Cell data: ``cell`` the input index of the element a face belongs to and
``beam`` its beam index. Cells: VTK_QUAD along the beam and VTK_POLYGON (or, for tubes,
VTK_QUAD rings) as end caps, at the first and last element of each beam only, so that the
pieces of several ranks (each its own elements) together make the surface of one rank.
"""

from functools import lru_cache
from typing import NamedTuple

import numpy as np

from ._sections import lagrange_matrix
from .surface_cells import join, surface_cells
from .vtkfiles import VTK_POLYGON, VTK_QUAD  # noqa: F401 (the surface's cell types)

CIRCLE_SEGMENTS = 32
SAMPLE_ARRAYS = ("u", "N", "M")
AXES = ("e1", "e2", "e3")


def circle_loop(d, segments=CIRCLE_SEGMENTS, clockwise=False):
    """(segments, 2) points (y, z) of a circle of diameter ``d`` about the centre line."""
    a = 2 * np.pi * np.arange(segments) / segments
    loop = 0.5 * d * np.stack([np.cos(a), np.sin(a)], axis=1)
    return loop[::-1] if clockwise else loop


def section_outline(type, h=None, w=None, d=None, d_inner=0.0, segments=CIRCLE_SEGMENTS):
    """Outline loops of a section (see the module docstring), None for ``general``.

    Args:
        type: "rectangle", "circle", "tube" or "general" (the scene's section types).
        h: rectangle height along e3.
        w: rectangle width along e2.
        d: outer diameter of a circle or tube.
        d_inner: inner diameter of a tube (0: a full circle).
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
        fields: the dict of :func:`~beamfx.io.fields.local_fields` or
            :func:`~beamfx.io.fields.nodal_fields` (whole elements, each in order).
        degree: the element degree k.
        subdivisions: intervals per element (its samples are equally spaced in ξ).

    Returns:
        dict of arrays of shape (elements, subdivisions + 1, ...): ``x`` the current position,
        ``axes`` the current section axes as columns (3, 3; between the nodes the nearest
        rotation to the interpolated axes, at a node its axes as given), ``u``, ``N``, ``M``,
        and ``beam`` (elements,).
    """
    k = degree
    n_el = len(fields["X"]) // (k + 1)
    A = _refinement_matrix(k, subdivisions)
    # one product for all the arrays side by side (one per array cost 7 times more; each
    # value is the same sum of the same products)
    columns = [np.asarray(fields[name]).reshape(-1, 3) for name in (*SAMPLE_ARRAYS, *AXES)]
    columns.append((np.asarray(fields["X"]) + np.asarray(fields["u"])).reshape(-1, 3))
    values = np.einsum("sn,enc->esc", A, np.concatenate(columns, axis=1).reshape(n_el, k + 1, -1))
    out = {name: values[..., 3 * i : 3 * i + 3] for i, name in enumerate(SAMPLE_ARRAYS)}
    out["x"] = values[..., -3:]
    n = 3 * len(SAMPLE_ARRAYS)  # then e1, e2, e3: as the rows of each (3, 3), so transposed
    axes = np.ascontiguousarray(
        values[..., n : n + 9].reshape(*values.shape[:2], 3, 3).swapaxes(-1, -2)
    )
    between = _between_nodes(k, subdivisions)
    if len(between):  # nearest rotation U Vᵀ (the sign is safe: axes ≈ R)
        U, _, Vt = np.linalg.svd(axes[:, between])
        axes[:, between] = U @ Vt
    out["axes"] = axes
    beam = np.asarray(fields["beam"])
    out["beam"] = (beam if len(beam) == n_el else beam.reshape(n_el, k + 1)[:, 0]).astype(np.int64)
    return out


@lru_cache(maxsize=8)
def _between_nodes(degree, subdivisions):
    """The samples of :func:`refine` that are no node of the element (their row of
    :func:`_refinement_matrix` is not a unit vector): there the interpolated axes are not
    orthonormal; at a node they are the node's own, a rotation already (cached, read only)."""
    A = _refinement_matrix(degree, subdivisions)
    at_node = (np.count_nonzero(A, axis=1) == 1) & (A.max(axis=1) == 1.0)
    out = np.flatnonzero(~at_node)
    out.flags.writeable = False
    return out


@lru_cache(maxsize=8)
def _refinement_matrix(degree, subdivisions):
    """Values of an element's k + 1 Lagrange polynomials at its ``subdivisions`` + 1 samples
    (cached, read only: every frame asks for the same)."""
    A = lagrange_matrix(np.linspace(0, 1, degree + 1), np.linspace(0, 1, subdivisions + 1))
    A.flags.writeable = False
    return A


class SurfaceMesh(NamedTuple):
    """The swept surface as arrays (see the module docstring)."""

    points: np.ndarray  # (n, 3)
    connectivity: np.ndarray  # point indices of all cells, one after another
    offsets: np.ndarray  # (cells + 1,): cell i is connectivity[offsets[i]:offsets[i + 1]]
    types: np.ndarray  # (cells,) VTK cell types
    point_data: dict  # u, N, M: (n, 3)
    cell_data: dict  # cell: input index of the face's element, beam: its beam index (cells,)

    def cells(self):
        """The cells as a list of point index arrays."""
        return np.split(self.connectivity, self.offsets[1:-1]) if len(self.types) else []


def sweep(samples, cells):
    """The :class:`SurfaceMesh` of the :func:`refine` ``samples`` on :func:`surface_cells`
    ``cells``: each section's ring placed at x + y e2 + z e3, and u, N, M per ring point."""
    points, data = [], {name: [] for name in SAMPLE_ARRAYS}
    for elements, yz in cells.parts:
        x, axes = samples["x"][elements], samples["axes"][elements]  # (E, S, 3), (E, S, 3, 3)
        pts = x[:, :, None, :] + yz[None, None, :, 0, None] * axes[:, :, None, :, 1]
        points.append((pts + yz[None, None, :, 1, None] * axes[:, :, None, :, 2]).reshape(-1, 3))
        for key in SAMPLE_ARRAYS:
            data[key].append(np.repeat(samples[key][elements].reshape(-1, 3), len(yz), axis=0))
    if not points:
        points = [np.zeros((0, 3))]
        data = {k: [np.zeros((0, 3))] for k in SAMPLE_ARRAYS}
    return SurfaceMesh(
        join(points),
        cells.connectivity,
        cells.offsets,
        cells.types,
        {k: join(v) for k, v in data.items()},
        cells.cell_data,
    )


class SweptSurface:
    """The surfaces of the frames of a run (:func:`surface_mesh` of each frame's fields): the
    cells are made once, at the first frame (again only if the elements change); a frame
    computes its points and point arrays alone.

    Args:
        degree, beam_names, outlines, subdivisions, ends: as in :func:`surface_mesh`.
    """

    def __init__(self, degree, beam_names, outlines, subdivisions=4, ends=None):
        self.degree, self.subdivisions = degree, subdivisions
        self.beam_names, self.outlines, self.ends = beam_names, outlines, ends
        self.cells, self.key = None, None

    def __call__(self, fields):
        """The :class:`SurfaceMesh` of ``fields`` (see :func:`surface_mesh`)."""
        s = refine(fields, self.degree, self.subdivisions)
        cell = np.asarray(fields.get("cell", np.arange(len(s["beam"]))), dtype=np.int64)
        key = self.key
        if key is None or not (np.array_equal(cell, key[0]) and np.array_equal(s["beam"], key[1])):
            self.cells = surface_cells(
                cell, s["beam"], self.beam_names, self.outlines, self.subdivisions, self.ends
            )
            self.key = (cell, s["beam"])
        return sweep(s, self.cells)


def surface_mesh(fields, degree, beam_names, outlines, subdivisions=4, ends=None):
    """The swept section surface of the elements in ``fields`` (NumPy, no MPI).

    Args:
        fields: the dict of :func:`~beamfx.io.fields.local_fields` (one rank's elements) or
            :func:`~beamfx.io.fields.nodal_fields` (all of them).
        degree: the element degree k.
        beam_names: names of the beams in beam-index order (``fields["beam"]``).
        outlines: ``{beam name: list of (n, 2) loops (y, z)}``; beams missing or None are
            left out.
        subdivisions: intervals per element along the centre line.
        ends: (first, last) input cell index of every beam (by beam index), where the end
            caps go; None: the first and last element of each beam in ``fields``.

    Returns:
        :class:`SurfaceMesh`.
    """
    return SweptSurface(degree, beam_names, outlines, subdivisions, ends)(fields)


def surface_grid(mesh, arrays=SAMPLE_ARRAYS, build=None):
    """The VTK grid of a :class:`SurfaceMesh`: point data ``arrays`` (of u, N, M), cell data
    ``cell`` and ``beam``; made by ``build`` (default
    :func:`~beamfx.io.vtkfiles.unstructured_grid`, or a :class:`~beamfx.io.vtkfiles.GridBuffer`)."""
    from .vtkfiles import unstructured_grid

    point_data = {k: mesh.point_data[k] for k in arrays if k in mesh.point_data}
    return (build or unstructured_grid)(
        mesh.points, mesh.connectivity, mesh.offsets, mesh.types, point_data, mesh.cell_data
    )
