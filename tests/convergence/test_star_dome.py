"""The 24-member star dome under an apex load (demos/scenes/star_dome.toml): its symmetric
snap-through traced by arc length, checked by structural properties and against OpenSeesPy.

The dome has the symmetry of a regular hexagon (C6v) and so does the load; the symmetric path
keeps it: the six support reactions are one reaction turned by 60°, and the tangent's
asymmetric eigenvalues come in pairs (the modes of the 2-dimensional irreducible
representations), so the inertia jumps by 2 at the bifurcation from the symmetric path and by
1 at the (symmetric) limit point.
"""

import numpy as np
import pytest
from mpi4py import MPI

from beamfx.solvers.convergence import FLOOR_LIMIT

#: beamfx's converged limit load (kN): P2 with 8 elements per member (extrapolated from 2, 4,
#: 8: 75.6517) and P3 with 4 and 8 (75.6519, 75.6518) agree to 5 digits; OpenSeesPy's
#: corotational elasticBeamColumn, extrapolated from 4, 8 and 16 elements per member: 75.649
#: (docs/validation/star_dome.md)
P_LIMIT = 75.652
#: relative error of the limit load with one P3 element per member, measured 8.2e-3 against
#: P_LIMIT; the tolerance keeps a factor ~1.2 for the limit point's placement by a quadratic
#: fit between arc-length steps
P3_NE1_RTOL = 1e-2


def trace(elements, degree, until=-8.6, folder=None):
    """The arc-length result of the demo scene with ``elements`` P``degree`` per member,
    stopped when the apex has sunk ``until`` (cm; the limit is at about -8.46)."""
    from beamfx.bench import star_dome
    from beamfx.runner import run_scene

    data = star_dome.scene_data(elements, degree)
    data["analysis"]["displacement_limit"] = ["uz", until]
    scene = star_dome.scene(data=data)
    return run_scene(scene.file, folder, log=lambda *a, **k: None, scene=scene).result


def _rotated(force, angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([c * force[0] - s * force[1], s * force[0] + c * force[1], force[2]])


def test_star_dome_snap_through_coarse(tmp_path):
    folder = MPI.COMM_WORLD.bcast(str(tmp_path), root=0)
    result = trace(1, 3, folder=folder)
    P = result.limit_points[0]["load_factor"]
    assert result.limit_points[0]["kind"] == "maximum"
    assert abs(P - P_LIMIT) / P_LIMIT < P3_NE1_RTOL
    # the inertia of the tangent: 0 -> 2 (a pair of asymmetric modes) before the limit, 2 -> 3
    kinds = [(c["kind"], c["negative_eigenvalues"]) for c in result.critical_points]
    assert kinds == [("bifurcation", [0, 2]), ("limit", [2, 3])]
    assert result.critical_points[0]["interval"][1] < P
    # the reactions of every traced point: one reaction turned by 60° at every support, which
    # together carry the load, to the equilibrium the corrector guarantees: its residual is
    # below FLOOR_LIMIT of the force scale (shear-rigid penalty: a round-off floor above 1e-10)
    for point in result.path[1:]:
        reactions = point["reactions"]
        forces = {
            np.arctan2(r["position"][1], r["position"][0]): r["force"] for r in reactions.values()
        }
        angles = sorted(forces)
        first = np.asarray(forces[angles[0]])
        scale = np.abs(first).max()
        for a in angles[1:]:
            turned = _rotated(first, a - angles[0])
            assert np.abs(np.asarray(forces[a]) - turned).max() < FLOOR_LIMIT * scale
        assert abs(6 * first[2] - point["load_factor"]) < FLOOR_LIMIT * scale


@pytest.mark.slow
def test_star_dome_limit_load_converges(tmp_path):
    """P2 with 2, 4 and 8 elements per member: the limit load converges monotonically, and
    its extrapolated value is P_LIMIT within the last change."""
    folder = MPI.COMM_WORLD.bcast(str(tmp_path), root=0)
    P = [trace(n, 2, folder=folder).limit_points[0]["load_factor"] for n in (2, 4, 8)]
    d1, d2 = P[1] - P[0], P[2] - P[1]
    assert d1 < 0 and d2 < 0 and abs(d2) < abs(d1) / 4  # at least second order
    extrapolated = P[2] - d2**2 / (d2 - d1)
    assert abs(extrapolated - P_LIMIT) < abs(d2)


def test_star_dome_geometry_copy_and_members():
    """The scene's .geo is the copy of meshes/star_dome/star_dome.geo; 13 nodes, 24 members of
    the lengths the geometry gives (ribs 25.08, ring 25, legs 31.60)."""
    from pathlib import Path

    from beamfx.geometry.line_mesh import read_line_mesh

    root = Path(__file__).resolve().parents[2]
    master = root / "meshes" / "star_dome" / "star_dome.geo"
    assert (root / "demos" / "scenes" / "star_dome.geo").read_bytes() == master.read_bytes()
    mesh = read_line_mesh(master)
    assert len(mesh.points) == 13 and len(mesh.members) == 24
    lengths = np.linalg.norm(np.diff(mesh.points[mesh.members], axis=1)[:, 0], axis=1)
    expected = {
        "ribs": np.hypot(25, 2),
        "ring": 25.0,
        "legs": np.sqrt(25**2 + 50**2 - 2 * 25 * 50 * np.cos(np.pi / 6) + 6.216**2),
    }
    for group, length in expected.items():
        assert np.allclose(lengths[mesh.member_groups[group]], length, rtol=1e-12)
    assert sorted(len(v) for v in mesh.member_groups.values()) == [6, 6, 12]
