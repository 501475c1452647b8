"""Write the frame meshes of demos/scenes/ (beside their scenes: a scene names files inside its
folder): a space-truss tower, a lattice dome and a BCC lattice block (gmsh 2.2 .msh
with physical groups naming member and node groups). Run from the repository root:
``python scripts/make_frame_meshes.py``; the files are committed, so this only documents and
reproduces them."""

from pathlib import Path

import numpy as np

from beamfx.geometry.line_mesh import write_line_mesh

SCENES = Path(__file__).resolve().parents[1] / "demos" / "scenes"  # beside their scenes


def tower(panels=6, height=12.0, base=4.0, top=1.5):
    """A square lattice tower tapering from ``base`` to ``top`` wide: legs, a horizontal ring
    at every level above the ground, and X-braces on the four faces of every panel."""
    z = np.linspace(0.0, height, panels + 1)
    half = (base + (top - base) * z / height) / 2
    corners = np.array([[1, 1], [-1, 1], [-1, -1], [1, -1]], float)
    points = np.array([[*(h * c), zz] for zz, h in zip(z, half) for c in corners])

    def node(level, corner):
        return 4 * level + corner % 4

    legs, rings, braces = [], [], []
    for k in range(panels):
        for c in range(4):
            legs.append((node(k, c), node(k + 1, c)))
            rings.append((node(k + 1, c), node(k + 1, c + 1)))
            braces.append((node(k, c), node(k + 1, c + 1)))
            braces.append((node(k, c + 1), node(k + 1, c)))
    members = legs + rings + braces
    groups = {
        "legs": range(len(legs)),
        "rings": range(len(legs), len(legs) + len(rings)),
        "braces": range(len(legs) + len(rings), len(members)),
    }
    nodes = {"base": [node(0, c) for c in range(4)], "top": [node(panels, c) for c in range(4)]}
    return points, members, groups, nodes


def dome(meridians=12, rings=4, radius=10.0, rise=4.0):
    """A spherical lattice dome (Schwedler type with diagonals): ``rings`` rings of
    ``meridians`` nodes above the supported base ring, a crown node, meridional ribs, ring
    members and one diagonal per quadrilateral."""
    R = (radius**2 + rise**2) / (2 * rise)  # sphere through the base circle and the crown
    phi0 = np.arcsin(radius / R)  # polar angle of the base ring
    phis = np.linspace(phi0, 0.0, rings + 2)[:-1]  # base ring .. top ring (crown apart)
    theta = 2 * np.pi * np.arange(meridians) / meridians
    points = [
        [R * np.sin(p) * np.cos(t), R * np.sin(p) * np.sin(t), R * np.cos(p) - (R - rise)]
        for p in phis
        for t in theta
    ]
    points.append([0.0, 0.0, rise])
    crown = len(points) - 1

    def node(ring, k):
        return ring * meridians + k % meridians

    ribs, hoops, diagonals = [], [], []
    for i in range(rings + 1):
        for k in range(meridians):
            upper = crown if i == rings else node(i + 1, k)
            ribs.append((node(i, k), upper))
            if i > 0:
                hoops.append((node(i, k), node(i, k + 1)))
            if i < rings:
                diagonals.append((node(i, k), node(i + 1, k + 1)))
    members = ribs + hoops + diagonals
    groups = {
        "ribs": range(len(ribs)),
        "rings": range(len(ribs), len(ribs) + len(hoops)),
        "diagonals": range(len(ribs) + len(hoops), len(members)),
    }
    nodes = {"base": [node(0, k) for k in range(meridians)], "crown": [crown]}
    return np.array(points), members, groups, nodes


def lattice(cells=3, size=0.01):
    """A body-centred cubic lattice block of ``cells``³ cells of edge ``size``: the cube
    edges, and in every cell the eight half-diagonals from the corners to a centre node."""
    n = cells + 1
    grid = np.array([[i, j, k] for k in range(n) for j in range(n) for i in range(n)], float)
    centres = np.array(
        [[i, j, k] for k in range(cells) for j in range(cells) for i in range(cells)], float
    )
    points = np.vstack([grid, centres + 0.5]) * size

    def node(i, j, k):
        return i + n * (j + n * k)

    edges, struts = [], []
    for i, j, k in grid.astype(int):
        for d in np.eye(3, dtype=int):
            a, b, c = i + d[0], j + d[1], k + d[2]
            if max(a, b, c) < n:
                edges.append((node(i, j, k), node(a, b, c)))
    for m, (i, j, k) in enumerate(centres.astype(int)):
        for corner in np.ndindex(2, 2, 2):
            struts.append((node(i + corner[0], j + corner[1], k + corner[2]), len(grid) + m))
    members = edges + struts
    groups = {"edges": range(len(edges)), "struts": range(len(edges), len(members))}
    nodes = {
        "bottom": [node(i, j, 0) for j in range(n) for i in range(n)],
        "top": [node(i, j, cells) for j in range(n) for i in range(n)],
    }
    return points, members, groups, nodes


def main():
    for name, build in (("tower", tower), ("dome", dome), ("lattice", lattice)):
        points, members, groups, nodes = build()
        write_line_mesh(SCENES / f"{name}.msh", points, members, groups, nodes)
        print(f"demos/scenes/{name}.msh: {len(points)} nodes, {len(members)} members")


if __name__ == "__main__":
    main()
