"""Pinned and released joints (beamfx.analyses.releases) against exact solutions.

Linear: with joint loads only the exact Timoshenko solution is cubic in u and quadratic in θ
along each member, which P3 elements hold, and the enriched element holds a released end
exactly, so beamfx equals the direct stiffness method with released member ends
(beamfx.bench.frame_stiffness) and the hand solutions to round-off (1e-9 relative: the
Newton/linear solve's floor with EA/GJ ~ 1e5). Nonlinear: a hinge turned by 90° with its
joint still releases the bending about its (turned) axis.
"""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from test_frames import PORTAL

from beamfx.bench import frame_peers, frame_stiffness
from beamfx.geometry.curves import Line
from beamfx.physics.kinematics import Kinematics
from beamfx.physics.sections import tube
from beamfx.scene import load_scene
from beamfx.spec import Beam, Model, PointLoad, Release, Support

TILTED = ((0.6, 0.0, 0.8), (0.0, 1.0, 0.0), (-0.8, 0.0, 0.6))
RELEASES = {
    "pinned": (Release("top:start"),),
    "hinge about a tilted axis": (Release("top:start", ("rx",), TILTED),),
    "two ends, two components": (
        Release("top:start", ("ry", "rz")),
        Release("right:start", ("rx",)),
    ),
}


@pytest.fixture(scope="module")
def portal(tmp_path_factory):
    path = Path(tmp_path_factory.mktemp("portal")) / "portal.toml"
    path.write_text(PORTAL.replace("ELEMENTS", "2"))
    return load_scene(path).model


@pytest.mark.parametrize("case", RELEASES)
def test_released_portal_equals_the_exact_frame(portal, case):
    """Skew members, turned sections, member ends released about global and tilted axes:
    beamfx's linear solution equals the direct stiffness method with the released ends'
    own rotation unknowns; the releases change the solution by more than 1e-3."""
    spec = replace(portal, releases=RELEASES[case])
    u, reactions, _ = frame_peers.beamfx_frame(spec)
    exact, exact_reactions = frame_stiffness.solve(frame_stiffness.problem_from_model(spec))
    assert max(frame_peers.differences(u, reactions, exact, exact_reactions)) < 1e-9
    rigid, rigid_reactions = frame_stiffness.solve(frame_stiffness.problem_from_model(portal))
    assert min(frame_peers.differences(rigid, rigid_reactions, exact, exact_reactions)) > 1e-3


def _cantilever_flexibility(section, L):
    """Tip deflection per unit tip force of a Timoshenko cantilever: L³/3EI + L/GA."""
    _, GA_y, GA_z, _, EI_y, EI_z = section.stiffnesses()
    assert EI_y == pytest.approx(EI_z) and GA_y == pytest.approx(GA_z)  # round: any plane
    return L**3 / (3 * EI_y) + L / GA_y


def _chain(kin, rotation, released):
    """Two members along x, A clamped at the origin (its clamp turned by ``rotation``), B
    held at its far end (displacements only), B released at the joint; a force F along
    global z at the joint."""
    section = tube(210e9, 80e9, 7850.0, 0.1, 0.08)
    beams = (
        Beam("A", Line((0.0, 0.0, 0.0), (1.0, 0.0, 0.0)), section, 2, 3),
        Beam("B", Line((1.0, 0.0, 0.0), (2.0, 0.0, 0.0)), section, 2, 3),
    )
    supports = (
        Support("A:start", ("ux", "uy", "uz", "rx", "ry", "rz"), rotation=rotation),
        Support("B:end", ("ux", "uy", "uz")),
    )
    F = 1e-5 / _cantilever_flexibility(section, 1.0)  # a deflection of 1e-5 of the length
    spec = Model(
        beams,
        supports,
        (PointLoad("A:end", force=(0.0, 0.0, F)),),
        kinematics=kin,
        releases=(Release("B:start", released),) if released else (),
    )
    return spec, F, _cantilever_flexibility(section, 1.0)


def _solve(spec, steps):
    from mpi4py import MPI

    from beamfx.analyses.model import BeamModel
    from beamfx.analyses.reactions import entries
    from beamfx.analyses.static import solve_static
    from beamfx.io import evaluate_points

    model = BeamModel(spec, MPI.COMM_WORLD, extra_points=["A:end"])
    solve_static(model, steps=steps)
    return evaluate_points(model, ["A:end"])["A:end"], entries(model)["reactions"]


def test_released_link_hand_solution_linear():
    """Linear: B is a link pinned at both ends in the plane of the load (released rz, free
    rotations at its far end), so A carries F alone as a cantilever (Timoshenko) and B's far
    support no transverse force; with the joint rigid B takes a share."""
    spec, F, flex = _chain(Kinematics(False), (0.0, 0.0, 0.0), ("rz",))
    spec = replace(spec, point_loads=(PointLoad("A:end", force=(0.0, F, 0.0)),))
    at, reactions = _solve(spec, 1)
    assert at["displacement"][1] == pytest.approx(F * flex, rel=1e-9)
    assert abs(reactions["B:end"]["force"][1]) < 1e-9 * F
    _, rigid = _solve(replace(spec, releases=()), 1)
    assert abs(rigid["B:end"]["force"][1]) > 0.1 * F


@pytest.mark.slow
def test_a_hinge_turned_by_90_degrees_stays_moment_free():
    """Finite rotations: the clamp turns the whole chain by 90° about x (the joint's z axis
    goes to −y), then F along z bends A about y. The release of the joint's rz turns with
    the joint, so B stays a link (no transverse reaction at its end, A deflects as a
    cantilever); a release that stayed about global z would leave B bending (as the rigid
    joint does). Tolerance 1e-6: the nonlinear terms at a deflection of 1e-5."""
    quarter = (np.pi / 2, 0.0, 0.0)
    spec, F, flex = _chain(Kinematics(True), quarter, ("rz",))
    at, reactions = _solve(spec, 4)
    assert at["displacement"][2] == pytest.approx(F * flex, rel=1e-6)
    assert abs(reactions["B:end"]["force"][2]) < 1e-6 * F
    _, rigid = _solve(replace(spec, releases=()), 4)
    assert abs(rigid["B:end"]["force"][2]) > 0.1 * F


def test_modes_of_a_beam_released_at_clamped_ends_are_those_of_a_pinned_beam():
    """A beam clamped at both ends with its bending released there (the hinge unknowns)
    against the same beam on pinned supports: the same discrete space, so without the
    rotary inertia (a hinge carries none, and torsion is about the skew axis) the frequencies
    agree to round-off."""
    from mpi4py import MPI

    from beamfx.analyses.modal import solve_modes
    from beamfx.analyses.model import BeamModel

    section = tube(210e9, 80e9, 7850.0, 0.05, 0.04)
    beam = Beam("b", Line((0.0, 0.0, 0.0), (2.0, 0.3, 0.1)), section, 6, 2)
    ends = ("b:start", "b:end")
    clamped = Model(
        (beam,),
        tuple(Support(at, ("ux", "uy", "uz", "rx", "ry", "rz")) for at in ends),
        kinematics=Kinematics(False),
        releases=tuple(Release(at, ("ry", "rz")) for at in ends),
    )
    pinned = replace(
        clamped,
        supports=tuple(Support(at, ("ux", "uy", "uz", "rx")) for at in ends),
        releases=(),
    )
    freqs = [
        np.sort(solve_modes(BeamModel(m, MPI.COMM_WORLD), 6, rotary="none").omega)
        for m in (clamped, pinned)
    ]
    assert np.allclose(freqs[0], freqs[1], rtol=1e-9, atol=0)
    rigid = np.sort(solve_modes(BeamModel(replace(clamped, releases=())), 6, rotary="none").omega)
    assert rigid[0] > 1.5 * freqs[0][0]


ECCENTRIC = """
[material]
E = 210e9
nu = 0.3
[[frames]]
name = "p"
mesh = "portal.msh"
elements = 2
degree = 3
[[frames.members]]
group = "columns"
section = { type = "rectangle", h = 0.3, w = 0.2 }
[[frames.members]]
group = "beam"
section = { type = "tube", d = 0.3, d_inner = 0.25 }
[[frames.offsets]]
group = "beam"
offset = [0, 0.1, 0.2]
[[frames.supports]]
group = "feet"
fix = "all"
[[frames.loads]]
group = "left"
force = [1e4, 2e3, -5e3]
moment = [1e3, 0, 2e3]
[model]
plane = "none"
[analysis]
type = "linear_static"
"""
PORTAL_NODES = np.array([[0, 0, 0], [0, 0, 3], [4, 0, 3], [4, 0, 0]], float)


def _eccentric_exact(spec, offset, released):
    """The exact portal: columns 0-1 and 3-2, the beam 1-2 on rigid arms ``offset`` at both
    ends (released about y at both knees if ``released``), clamped feet, the load at node 1."""
    from beamfx.geometry.frames import frame_from_tangent

    members = np.array([[0, 1], [3, 2], [1, 2]])
    beams = {b.name: b for b in spec.beams}
    C = [beams[f"p.{k}"].section.stiffnesses() for k in (1, 2, 3)]
    axes = []
    for k, (a, b) in enumerate(members):
        d = PORTAL_NODES[b] - PORTAL_NODES[a]
        axes.append(frame_from_tangent(d / np.linalg.norm(d), beams[f"p.{k + 1}"].orientation))
    load = np.r_[spec.point_loads[0].force, spec.point_loads[0].moment]
    ey = np.array([[0.0], [1.0], [0.0]])
    return frame_stiffness.FrameProblem(
        PORTAL_NODES,
        members,
        np.array(C),
        np.array(axes),
        {0: list(range(6)), 3: list(range(6))},
        {1: load},
        {(2, 0): ey, (2, 1): ey} if released else {},
        {(2, 0): np.asarray(offset), (2, 1): np.asarray(offset)},
    )


@pytest.mark.parametrize("released", [False, True])
def test_eccentric_portal_equals_the_exact_frame_with_rigid_arms(tmp_path, released):
    """The beam's ends sit off the knees, on rigid arms (stiff beams, 1e6 times their
    member's stiffness): beamfx's linear solution equals the exact frame with rigid offsets
    (and with the beam hinged about y at the knees, at the node end of the arms) to 1e-6,
    the arms' relative compliance; without the offsets it differs by more than 1e-3."""
    from beamfx.geometry.line_mesh import write_line_mesh

    groups, nodes = {"columns": [0, 2], "beam": [1]}, {"feet": [0, 3], "knees": [1, 2], "left": [1]}
    members = [[0, 1], [1, 2], [3, 2]]
    write_line_mesh(tmp_path / "portal.msh", PORTAL_NODES, members, groups, nodes)
    text = ECCENTRIC
    if released:
        text += '[[frames.joints]]\ngroup = "knees"\nreleases = ["ry"]\nmembers = "beam"\n'
    (tmp_path / "scene.toml").write_text(text)
    spec = load_scene(tmp_path / "scene.toml").model
    assert [b.name for b in spec.beams][3:] == ["p.3.arm_start", "p.3.arm_end"]
    if released:
        assert [r.at for r in spec.releases] == ["p.3.arm_start:start", "p.3.arm_end:start"]
    u, reactions, _ = frame_peers.beamfx_frame(spec)
    problem = _eccentric_exact(spec, (0, 0.1, 0.2), released)
    exact, exact_reactions = frame_stiffness.solve(problem)
    index = frame_stiffness.problem_from_model(spec).nodes  # beamfx_frame's node order
    order = [int(np.argmin(np.linalg.norm(index - x, axis=1))) for x in PORTAL_NODES]
    mine = {i: reactions[order[i]] for i in (0, 3)}
    assert max(frame_peers.differences(u[order], mine, exact, exact_reactions)) < 1e-6
    concentric = frame_stiffness.solve(problem._replace(offsets={}))
    assert min(frame_peers.differences(exact, exact_reactions, *concentric)) > 1e-3
