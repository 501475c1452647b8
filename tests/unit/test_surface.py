"""The swept section surface (beamfx.io.surface), on hand-made nodal fields: no solve.

A straight beam along x (section axes = global axes) of 2 quadratic elements, displaced by a
constant u: every ring of the surface is the outline moved to x + u, faces point away from
the material, and the ends are closed.
"""

import numpy as np
import pytest

from beamfx.io._sections import lagrange_matrix
from beamfx.io.surface import (
    VTK_POLYGON,
    VTK_QUAD,
    SweptSurface,
    refine,
    section_outline,
    surface_mesh,
)

K, ELEMENTS, SUB = 2, 2, 4
U = np.array([0.1, 0.2, 0.3])


def straight_fields():
    xi = np.linspace(0, 1, K + 1)
    X = np.concatenate([np.c_[e + xi, 0 * xi, 0 * xi] for e in range(ELEMENTS)])
    n = len(X)
    eye = np.eye(3)
    return {
        "X": X,
        "u": np.tile(U, (n, 1)),
        "e1": np.tile(eye[0], (n, 1)),
        "e2": np.tile(eye[1], (n, 1)),
        "e3": np.tile(eye[2], (n, 1)),
        "N": np.zeros((n, 3)),
        "M": np.tile([0.0, 1.0, 0.0], (n, 1)),
        "beam": np.zeros(n),
    }


def outward(points, cell):
    """Normal of a planar cell (right-hand rule) dotted with the direction away from the axis."""
    p = points[cell]
    normal = np.cross(p[1] - p[0], p[2] - p[0])
    centre = p.mean(0)
    away = centre - (U + [centre[0] - U[0], 0, 0])  # from the centre line, in the section plane
    if np.ptp(p[:, 0]) < 1e-12:  # an end cap (in one section plane): away along the axis
        away = np.array([np.sign(centre[0] - U[0] - ELEMENTS / 2), 0, 0])
    return normal @ away


@pytest.mark.parametrize(
    "outline, rings_points, caps",
    [
        (section_outline("rectangle", h=1.0, w=0.5), 4, 2),
        (section_outline("circle", d=1.0, segments=12), 12, 2),
        (section_outline("tube", d=1.0, d_inner=0.6, segments=12), 24, 24),
    ],
)
def test_swept_surface(outline, rings_points, caps):
    mesh = surface_mesh(straight_fields(), K, ["b"], {"b": outline}, SUB)
    points, cells, types, data = mesh.points, mesh.cells(), mesh.types, mesh.point_data
    samples = ELEMENTS * (SUB + 1)
    assert len(points) == samples * rings_points
    along = ELEMENTS * SUB * rings_points
    assert len(cells) == along + caps
    assert np.all(types[:along] == VTK_QUAD)
    assert set(types[along:]) == {VTK_QUAD if len(outline) == 2 else VTK_POLYGON}
    yz = np.concatenate(outline)
    rings = points.reshape(samples, rings_points, 3) - U
    assert np.allclose(rings[..., 1:], yz[None])  # the outline, unrotated (axes = identity)
    s = np.repeat(np.arange(ELEMENTS), SUB + 1) + np.tile(np.linspace(0, 1, SUB + 1), ELEMENTS)
    assert np.allclose(rings[..., 0], s[:, None])
    inner = min(np.linalg.norm(lp, axis=1).max() for lp in outline)  # a tube's hole
    for c in cells:
        r = np.linalg.norm(points[c][:, 1:] - U[1:], axis=1)
        hole = len(outline) == 2 and np.allclose(r, inner)  # the hole's wall: towards the axis
        assert outward(points, c) * (-1 if hole else 1) > 0
    assert np.allclose(data["u"], U) and np.allclose(data["M"], [0, 1, 0])
    # cell data: the element of every face (the caps: the first and the last element)
    element = mesh.cell_data["cell"]
    assert np.array_equal(element[:along], np.repeat(np.arange(ELEMENTS), along // ELEMENTS))
    assert sorted(set(element[along:].tolist())) == [0, ELEMENTS - 1]
    assert np.all(mesh.cell_data["beam"] == 0)


def test_pieces_of_elements_make_the_whole_surface():
    """The surface of each element alone, with the beam's ends given, has the caps only at
    the beam's ends: the pieces of several ranks together are the surface of one."""
    fields = straight_fields()
    outline = {"b": section_outline("rectangle", h=1.0, w=0.5)}
    whole = surface_mesh(fields, K, ["b"], outline, SUB)
    n = K + 1
    pieces = []
    for e in range(ELEMENTS):
        one = {k: v[e * n : (e + 1) * n] for k, v in fields.items()}
        one["cell"], one["beam"] = np.array([e]), np.array([0])
        pieces.append(surface_mesh(one, K, ["b"], outline, SUB, ends=([0], [ELEMENTS - 1])))
    assert sum(len(p.types) for p in pieces) == len(whole.types)
    assert np.allclose(np.concatenate([p.points for p in pieces]), whole.points)
    caps = [int(np.sum(p.types == VTK_POLYGON)) for p in pieces]
    assert caps == [1, 1]  # the start cap on element 0, the end cap on element 1


def test_general_section_has_no_outline():
    assert section_outline("general") is None
    mesh = surface_mesh(straight_fields(), K, ["b"], {"b": None})
    assert len(mesh.points) == 0 and mesh.cells() == [] and len(mesh.types) == 0


def bent_fields(seed, elements=3, k=3):
    """Nodal fields of ``elements`` elements of degree k with random positions, loads and
    section axes near random rotations (interpolated axes are not orthonormal)."""
    rng = np.random.default_rng(seed)
    n = elements * (k + 1)
    q, _ = np.linalg.qr(rng.standard_normal((n, 3, 3)))
    axes = q + 1e-3 * rng.standard_normal((n, 3, 3))
    fields = {name: rng.standard_normal((n, 3)) for name in ("X", "u", "N", "M")}
    fields.update({f"e{i + 1}": np.ascontiguousarray(axes[..., i]) for i in range(3)})
    fields["cell"], fields["beam"] = np.arange(elements), np.zeros(elements, np.int64)
    return fields


def test_refine_is_the_interpolation_of_each_array():
    """refine's one product of all arrays side by side gives, bit for bit, each array's own
    interpolation (the sums of the same products), and between the nodes the nearest
    rotations of the axes; at the samples that are nodes (ξ = 0 and 1 of a cubic element
    sampled at quarters) the nodes' axes as given, bit for bit (the fields' axes are R·Λ0,
    rotations already: no polar decomposition there)."""
    k, sub = 3, 4
    fields = bent_fields(0, k=k)
    s = refine(fields, k, sub)
    A = lagrange_matrix(np.linspace(0, 1, k + 1), np.linspace(0, 1, sub + 1))

    def alone(a):
        return np.einsum("sn,en...->es...", A, np.asarray(a).reshape(-1, k + 1, 3))

    for name in ("u", "N", "M"):
        assert np.array_equal(s[name], alone(fields[name]))
    assert np.array_equal(s["x"], alone(fields["X"] + fields["u"]))
    interpolated = np.stack([alone(fields[e]) for e in ("e1", "e2", "e3")], axis=-1)
    U, _, Vt = np.linalg.svd(interpolated)
    between = [1, 2, 3]  # ξ = 1/4, 1/2, 3/4: no node of the cubic element
    assert np.array_equal(s["axes"][:, between], (U @ Vt)[:, between])
    at_nodes = [0, sub]
    nodal = np.stack([fields[e] for e in ("e1", "e2", "e3")], axis=-1).reshape(-1, k + 1, 3, 3)
    assert np.array_equal(s["axes"][:, at_nodes], nodal[:, [0, k]])
    assert np.array_equal(s["axes"][:, at_nodes], interpolated[:, at_nodes])
    R = s["axes"][:, between]
    assert np.allclose(R @ R.swapaxes(-1, -2), np.eye(3), atol=1e-14)


def test_swept_surface_reuses_its_cells_across_frames():
    """A series' SweptSurface makes its cells once: each frame equals surface_mesh of that
    frame's fields, with the same cell arrays (read only); other elements make new cells."""
    outline = {"b": section_outline("tube", d=1.0, d_inner=0.6, segments=8)}
    swept = SweptSurface(3, ["b"], outline, SUB, ends=([0], [2]))
    frames = [swept(bent_fields(seed)) for seed in (1, 2)]
    for seed, mesh in zip((1, 2), frames):
        fresh = surface_mesh(bent_fields(seed), 3, ["b"], outline, SUB, ends=([0], [2]))
        for a, b in zip(mesh[:4], fresh[:4]):
            assert np.array_equal(a, b)
        for name in ("point_data", "cell_data"):
            d, e = getattr(mesh, name), getattr(fresh, name)
            assert d.keys() == e.keys() and all(np.array_equal(d[x], e[x]) for x in d)
    assert frames[0].connectivity is frames[1].connectivity
    assert not frames[0].connectivity.flags.writeable
    part = bent_fields(3)
    part = {key: v[4:] if key not in ("cell", "beam") else v[1:] for key, v in part.items()}
    fewer = swept(part)  # elements 1 and 2 only: fewer cells, the end cap only
    assert len(fewer.types) < len(frames[0].types)
    assert set(fewer.cell_data["cell"].tolist()) == {1, 2}
