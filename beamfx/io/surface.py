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
(section axes). Cell data: ``cell`` the input index of the element a face belongs to and
``beam`` its beam index. Cells: VTK_QUAD along the beam and VTK_POLYGON (or, for tubes,
VTK_QUAD rings) as end caps, at the first and last element of each beam only, so that the
pieces of several ranks (each its own elements) together make the surface of one rank.
"""

from functools import lru_cache
from typing import NamedTuple

import numpy as np

from ._sections import lagrange_matrix
from .vtkfiles import VTK_POLYGON, VTK_QUAD

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
        ``axes`` the current section axes as columns (3, 3), ``u``, ``N``, ``M``, and ``beam``
        (elements,).
    """
    k = degree
    n_el = len(fields["X"]) // (k + 1)
    A = _refinement_matrix(k, subdivisions)

    def per_element(a):
        return np.einsum("sn,en...->es...", A, np.asarray(a).reshape(n_el, k + 1, -1))

    out = {name: per_element(fields[name]) for name in SAMPLE_ARRAYS}
    out["x"] = per_element(np.asarray(fields["X"]) + np.asarray(fields["u"]))
    axes = np.stack([per_element(fields[e]) for e in ("e1", "e2", "e3")], axis=-1)
    U, _, Vt = np.linalg.svd(axes)  # nearest rotation: U Vᵀ (the sign is safe: axes ≈ R)
    out["axes"] = U @ Vt
    beam = np.asarray(fields["beam"])
    out["beam"] = (beam if len(beam) == n_el else beam.reshape(n_el, k + 1)[:, 0]).astype(np.int64)
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


def _cap(loops, ring, flip):
    """End cap cells of the section ring starting at point ``ring``: one polygon, or for a
    tube a ring of quads between the outer and (clockwise) inner loop; ``flip`` reverses
    them (the start of a beam faces backwards)."""
    if len(loops) == 1:
        ids = ring + np.arange(len(loops[0]))
        return [ids[::-1] if flip else ids]
    if len(loops) == 2 and len(loops[0]) == len(loops[1]):
        n = len(loops[0])
        j = np.arange(n)
        outer, inner = ring + j, ring + n + j[::-1]  # inner loop runs clockwise: re-align
        quads = np.stack([outer, np.roll(outer, -1), np.roll(inner, -1), inner], axis=1)
        return list(quads[:, ::-1] if flip else quads)
    return []


def _sides(loops, n_el, samples, ring, base):
    """Quads along the beam of ``n_el`` elements whose points start at ``base`` (each element
    ``samples`` rings of ``ring`` points), element by element: (quads (m, 4), element (m,))."""
    quads = []
    e = np.arange(n_el)[:, None, None]
    i = np.arange(samples - 1)[None, :, None]
    start = 0
    for lp in loops:
        j = np.arange(len(lp))[None, None, :]
        a = base + (e * samples + i) * ring + start
        c = a + ring
        jn = (j + 1) % len(lp)
        q = np.stack(np.broadcast_arrays(a + j, a + jn, c + jn, c + j), axis=-1)
        quads.append(q.reshape(n_el, -1, 4))
        start += len(lp)
    q = np.concatenate(quads, axis=1)
    return q.reshape(-1, 4), np.repeat(np.arange(n_el), q.shape[1])


def _element_ends(cell, s_beam, ends):
    """Booleans (first, last) per element: does it start or end its beam?"""
    n_el = len(s_beam)
    if ends is None:  # the first and last element of each beam among these fields
        first, last = {}, {}
        for e, b in enumerate(s_beam.tolist()):
            first.setdefault(b, e)
            last[b] = e
        return np.isin(np.arange(n_el), list(first.values())), np.isin(
            np.arange(n_el), list(last.values())
        )
    lo, hi = (np.asarray(a) for a in ends)
    return cell == lo[s_beam], cell == hi[s_beam]


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
    s = refine(fields, degree, subdivisions)
    cell = np.asarray(fields.get("cell", np.arange(len(s["beam"]))), dtype=np.int64)
    first, last = _element_ends(cell, s["beam"], ends)
    samples = subdivisions + 1
    points, cells, sizes, types, element = [], [], [], [], []
    data = {name: [] for name in SAMPLE_ARRAYS}
    n_points, of_beam = 0, _beam_elements(s["beam"])
    for b, name in enumerate(beam_names):
        loops = outlines.get(name)
        elements = of_beam.get(b, np.zeros(0, np.int64))
        if loops is None or not len(elements):
            continue
        loops = [np.asarray(lp, float).reshape(-1, 2) for lp in loops]
        yz = np.concatenate(loops)  # one ring = all loops of a section
        ring = len(yz)
        x, axes = s["x"][elements], s["axes"][elements]  # (E, S, 3), (E, S, 3, 3)
        pts = x[:, :, None, :] + yz[None, None, :, 0, None] * axes[:, :, None, :, 1]
        points.append((pts + yz[None, None, :, 1, None] * axes[:, :, None, :, 2]).reshape(-1, 3))
        for key in SAMPLE_ARRAYS:
            data[key].append(np.repeat(s[key][elements].reshape(-1, 3), ring, axis=0))
        quads, owner = _sides(loops, len(elements), samples, ring, n_points)
        cells.append(quads.ravel())
        sizes.append(np.full(len(quads), 4))
        types.append(np.full(len(quads), VTK_QUAD))
        element.append(elements[owner])
        cap_type = VTK_QUAD if len(loops) == 2 else VTK_POLYGON
        for flag, flip, shift in ((first, True, 0), (last, False, (samples - 1) * ring)):
            for local in np.flatnonzero(flag[elements]):
                caps = _cap(loops, n_points + local * samples * ring + shift, flip)
                cells.extend(caps)
                sizes.append([len(c) for c in caps])
                types.append([cap_type] * len(caps))
                element.append(np.full(len(caps), elements[local]))
        n_points += len(elements) * samples * ring
    if not points:
        none = np.zeros(0, np.int64)
        empty = {k: np.zeros((0, 3)) for k in SAMPLE_ARRAYS}
        return SurfaceMesh(
            np.zeros((0, 3)),
            none,
            np.zeros(1, np.int64),
            none.astype(np.uint8),
            empty,
            {"cell": none, "beam": none},
        )
    # each list joined and emptied in turn: its pieces and the whole are not all held at once
    element = _join(element).astype(np.int64, copy=False)
    sizes = _join(sizes)
    return SurfaceMesh(
        _join(points),
        _join(cells).astype(np.int64, copy=False),
        np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64),
        _join(types).astype(np.uint8, copy=False),
        {k: _join(v) for k, v in data.items()},
        {"cell": cell[element], "beam": s["beam"][element]},
    )


def _join(parts):
    """``np.concatenate(parts)``, emptying the list ``parts`` (its pieces are freed)."""
    out = np.concatenate(parts)
    parts.clear()
    return out


def _beam_elements(beam):
    """{beam index: its elements in ascending order}: one sort, not a comparison of all
    elements per beam (O(N²) on a frame of 10⁵ members)."""
    order = np.argsort(beam, kind="stable")
    keys, starts = np.unique(beam[order], return_index=True)
    return dict(zip(keys.tolist(), np.split(order, starts[1:])))


def surface_grid(mesh, arrays=SAMPLE_ARRAYS, build=None):
    """The VTK grid of a :class:`SurfaceMesh`: point data ``arrays`` (of u, N, M), cell data
    ``cell`` and ``beam``; made by ``build`` (default
    :func:`~beamfx.io.vtkfiles.unstructured_grid`, or a :class:`~beamfx.io.vtkfiles.GridBuffer`)."""
    from .vtkfiles import unstructured_grid

    point_data = {k: mesh.point_data[k] for k in arrays if k in mesh.point_data}
    return (build or unstructured_grid)(
        mesh.points, mesh.connectivity, mesh.offsets, mesh.types, point_data, mesh.cell_data
    )
