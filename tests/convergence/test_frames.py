"""Linear frames against the exact Timoshenko solution (direct stiffness method with the
closed-form member stiffness, beamfx.bench.frame_stiffness): displacements, rotations and
support reactions to 1e-8 relative. With joint loads only, the exact solution is cubic in u
and quadratic in θ along each member, which P3 elements hold: the agreement is round-off,
whatever the number of elements per member. (P2 with the reduced shear integration is exact at
the nodes too, 1e-13 here; the tests use P3, exact everywhere.)"""

from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

from beamfx.analyses.model import BeamModel
from beamfx.analyses.reactions import entries
from beamfx.analyses.static import solve_static
from beamfx.bench import frame_stiffness
from beamfx.io import evaluate_points
from beamfx.scene import load_scene
from beamfx.spec import resolve_point

DEMOS = Path(__file__).resolve().parents[2] / "demos" / "scenes"

PORTAL = """
[material]
E = 210e9
nu = 0.3
[[beams]]
name = "left"
curve = { shape = "line", start = [0, 0, 0], end = [0, 0.5, 3] }
section = { type = "rectangle", h = 0.3, w = 0.15 }
orientation = [1, 0, 0]
elements = ELEMENTS
degree = 3
[[beams]]
name = "top"
curve = { shape = "line", start = [0, 0.5, 3], end = [4, 0.5, 3.5] }
section = { type = "rectangle", h = 0.4, w = 0.2 }
orientation = [0, 0.3, 1]
twist_deg = 10
elements = ELEMENTS
degree = 3
[[beams]]
name = "right"
curve = { shape = "line", start = [4, 0.5, 3.5], end = [4.5, 0, 0] }
section = { type = "tube", d = 0.3, d_inner = 0.25 }
elements = ELEMENTS
degree = 3
[[supports]]
at = "left:start"
fix = "all"
[[supports]]
at = "right:end"
fix = ["ux", "uy", "uz", "rz"]
[[loads]]
at = "top:start"
force = [3e4, -1e4, -5e4]
moment = [2e3, 0, 1e3]
[[loads]]
at = "top:end"
force = [0, 2e4, -3e4]
[model]
plane = "none"
[analysis]
type = "linear_static"
"""


def _compare(spec):
    """Max relative differences (translations, rotations, reactions) of beamfx's linear
    solution at every member end against the exact frame."""
    ends = [f"{b.name}:{w}" for b in spec.beams for w in ("start", "end")]
    model = BeamModel(spec, MPI.COMM_WORLD, extra_points=ends)
    solve_static(model)
    values = evaluate_points(model, ends)
    problem = frame_stiffness.problem_from_model(spec)
    exact, reactions = frame_stiffness.solve(problem)
    index = {tuple(np.round(x / 1e-9).astype(np.int64)): i for i, x in enumerate(problem.nodes)}

    def node(at):
        return index[tuple(np.round(resolve_point(spec, at)[2] / 1e-9).astype(np.int64))]

    got = np.array([np.r_[values[a]["displacement"], values[a]["rotation_vector"]] for a in ends])
    want = exact[[node(a) for a in ends]]
    err = [
        np.abs(got[:, s] - want[:, s]).max() / np.abs(want[:, s]).max()
        for s in (slice(0, 3), slice(3, 6))
    ]
    found = entries(model)["reactions"]
    r_got = np.array([np.r_[found[a]["force"], found[a]["moment"]] for a in found])
    r_want = np.array([reactions[node(a)] for a in found])
    err.append(np.abs(r_got - r_want).max() / np.abs(r_want).max())
    return err


@pytest.mark.parametrize("elements", [1, 3])
def test_portal_frame_equals_the_exact_timoshenko_frame(scene_file, elements):
    """Skew members, rectangular sections turned by orientation and twist, a clamped and a
    pinned-with-rz foot, loads at two 2-element joints."""
    spec = load_scene(scene_file(PORTAL.replace("ELEMENTS", str(elements)))).model
    errors = _compare(spec)
    assert max(errors) < 1e-8, errors


def test_tower_equals_the_exact_frame_with_loads_at_many_member_joints():
    """The 96-member tower of demos/scenes (joints of up to 6 elements, where point loads act
    through the joint density of beamfx.analyses.joints), linear, P3, no gravity (a member
    load is not a joint load), a moment added at one top node."""
    from dataclasses import replace

    from beamfx.physics.kinematics import Kinematics
    from beamfx.spec import PointLoad

    spec = load_scene(DEMOS / "tower.toml").model
    beams = tuple(replace(b, degree=3) for b in spec.beams)
    loads = (*spec.point_loads, PointLoad(spec.point_loads[0].at, moment=(1e3, -2e3, 5e2)))
    spec = replace(
        spec, beams=beams, point_loads=loads, gravity=(0.0, 0.0, 0.0), kinematics=Kinematics(False)
    )
    errors = _compare(spec)
    assert max(errors) < 1e-8, errors
