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
