"""The cells of the swept section surface (:mod:`beamfx.io.surface`): made once per run.

A series of frames draws the same elements at every frame, so its cells (VTK_QUAD along each
beam, end caps at its first and last element) and cell arrays are made once by
:func:`surface_cells`; a frame computes only the points (:func:`beamfx.io.surface.sweep`).
The point order: beam by beam (beam index order), element by element, sample by sample along
the element, one ring of the section's outline points at each sample.
"""

from typing import NamedTuple

import numpy as np

from .vtkfiles import VTK_POLYGON, VTK_QUAD


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
        first, last = np.zeros(n_el, bool), np.zeros(n_el, bool)
        first[np.unique(s_beam, return_index=True)[1]] = True  # first occurrences
        last[n_el - 1 - np.unique(s_beam[::-1], return_index=True)[1]] = True
        return first, last
    lo, hi = (np.asarray(a) for a in ends)
    return cell == lo[s_beam], cell == hi[s_beam]


class SurfaceCells(NamedTuple):
    """The cells of a swept surface (read only): the same at every frame of a run."""

    connectivity: np.ndarray  # as in SurfaceMesh
    offsets: np.ndarray
    types: np.ndarray
    cell_data: dict
    parts: tuple  # (elements, ring) of each beam drawn: its elements, its outline points (m, 2)


def surface_cells(cell, beam, beam_names, outlines, subdivisions=4, ends=None):
    """The cells of the surface of elements ``cell`` (input indices) of beams ``beam`` (beam
    indices, per element); the other arguments as in :func:`surface_mesh`."""
    first, last = _element_ends(cell, beam, ends)
    samples = subdivisions + 1
    cells, sizes, types, element, parts = [], [], [], [], []
    n_points, of_beam = 0, _beam_elements(beam)
    for b, name in enumerate(beam_names):
        loops = outlines.get(name)
        elements = of_beam.get(b, np.zeros(0, np.int64))
        if loops is None or not len(elements):
            continue
        loops = [np.asarray(lp, float).reshape(-1, 2) for lp in loops]
        parts.append((elements, np.concatenate(loops)))  # one ring = all loops of a section
        ring = len(parts[-1][1])
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
    if not parts:
        none = np.zeros(0, np.int64)
        cell_data = {"cell": none, "beam": none}
        out = SurfaceCells(none, np.zeros(1, np.int64), none.astype(np.uint8), cell_data, ())
    else:  # each list joined and emptied in turn: its pieces and the whole are not all held at once
        element = join(element).astype(np.int64, copy=False)
        sizes = join(sizes)
        out = SurfaceCells(
            join(cells).astype(np.int64, copy=False),
            np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64),
            join(types).astype(np.uint8, copy=False),
            {"cell": cell[element], "beam": beam[element]},
            tuple(parts),
        )
    for a in (out.connectivity, out.offsets, out.types, *out.cell_data.values()):
        a.flags.writeable = False  # shared by the frames (a GridBuffer then compares nothing)
    return out


def join(parts):
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


__all__ = ["SurfaceCells", "join", "surface_cells"]
