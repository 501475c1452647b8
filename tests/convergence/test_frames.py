"""Linear frames against the exact Timoshenko solution (direct stiffness method with the
closed-form member stiffness, beamfx.bench.frame_stiffness): displacements, rotations and
support reactions to 1e-8 relative. With joint loads only, the exact solution is cubic in u
and quadratic in θ along each member, which P3 elements hold: the agreement is round-off,
whatever the number of elements per member. (P2 with the reduced shear integration is exact at
the nodes too, 1e-13 here; the tests use P3, exact everywhere.)"""

from pathlib import Path

import pytest

from beamfx.bench import frame_peers, frame_stiffness
from beamfx.scene import load_scene

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
    u, reactions, _ = frame_peers.beamfx_frame(spec)
    exact, exact_reactions = frame_stiffness.solve(frame_stiffness.problem_from_model(spec))
    return frame_peers.differences(u, reactions, exact, exact_reactions)


@pytest.mark.parametrize("elements", [1, 3])
def test_portal_frame_equals_the_exact_timoshenko_frame(scene_file, elements):
    """Skew members, rectangular sections turned by orientation and twist, a clamped and a
    pinned-with-rz foot, loads at two 2-element joints."""
    spec = load_scene(scene_file(PORTAL.replace("ELEMENTS", str(elements)))).model
    errors = _compare(spec)
    assert max(errors) < 1e-8, errors


@pytest.mark.parametrize("name", frame_peers.FRAMES)
def test_demo_frames_equal_the_exact_frame_with_loads_at_many_member_joints(name):
    """The tower (96 members, joints of up to 6 elements) and the dome (156 members, 12 at
    the crown) of demos/scenes, where point loads act through the joint density of
    beamfx.analyses.joints; linear, P3, no gravity (a member load is not a joint load); a
    moment added at the first loaded node."""
    from dataclasses import replace

    from beamfx.spec import PointLoad

    spec = frame_peers.linear_frame(load_scene(DEMOS / f"{name}.toml").model)
    extra = PointLoad(spec.point_loads[0].at, moment=(1e3, -2e3, 5e2))
    errors = _compare(replace(spec, point_loads=(*spec.point_loads, extra)))
    assert max(errors) < 1e-8, errors
