"""``[[frames]]``: frames read from a mesh file (beamfx.scene.frames) run as scenes, their
reactions balance the loads, and bad input fails naming the file, the key and the group."""

import shutil
from pathlib import Path

import numpy as np
import pytest

from beamfx.geometry.line_mesh import read_line_mesh, write_line_mesh
from beamfx.runner import run_scene
from beamfx.scene import SceneError, load_scene

DEMOS = Path(__file__).resolve().parents[2] / "demos" / "scenes"

# a tripod: three tubes from the ground to an apex, clamped feet, a load at the apex
POINTS = [[0, 0, 0], [2, 0, 0], [0, 2, 0], [0.7, 0.7, 2.0]]
MEMBERS = [[0, 3], [1, 3], [2, 3]]

SCENE = """
[material]
E = 210e9
nu = 0.3
rho = 7850
[[frames]]
name = "tri"
mesh = "tripod.msh"
elements = 2
[[frames.members]]
group = "legs"
section = { type = "tube", d = 0.1, d_inner = 0.09 }
[[frames.supports]]
group = "feet"
fix = "all"
[[frames.loads]]
group = "apex"
force = [1e3, 2e3, -1e4]
[[frames.probes]]
group = "apex"
[[loads]]
gravity = [0, 0, -9.81]
[model]
kinematics = "KIN"
[analysis]
type = "static"
steps = 2
"""


@pytest.fixture
def tripod(tmp_path):
    """``tripod(text, **groups) -> scene path``: the tripod mesh and a scene beside it."""

    def write(text=SCENE, members=None, nodes=None):
        text = text.replace("KIN", "linear")
        groups = members if members is not None else {"legs": [0, 1, 2]}
        nodes = nodes if nodes is not None else {"feet": [0, 1, 2], "apex": [3]}
        write_line_mesh(tmp_path / "tripod.msh", POINTS, MEMBERS, groups, nodes)
        (tmp_path / "scene.toml").write_text(text)
        return tmp_path / "scene.toml"

    return write


def test_mesh_round_trip(tmp_path):
    write_line_mesh(tmp_path / "t.msh", POINTS, MEMBERS, {"legs": [0, 1, 2]}, {"apex": [3]})
    mesh = read_line_mesh(tmp_path / "t.msh")
    assert np.array_equal(mesh.points, POINTS) and mesh.members.tolist() == MEMBERS
    assert mesh.member_groups["legs"].tolist() == [0, 1, 2]
    assert mesh.node_groups == {"apex": [3]}


@pytest.mark.parametrize("kin", ["linear", "finite"])
def test_tripod_runs_and_its_reactions_balance_the_loads(tripod, tmp_path, kin):
    """The apex joins three members: its dead load acts through the joint density; the
    reactions at the three feet balance it and the weight (1e-9: the Newton tolerance)."""
    run = run_scene(tripod(SCENE.replace("KIN", kin)), tmp_path / "out", log=lambda m: None)
    assert run["model"]["beams"] == ["tri.1", "tri.2", "tri.3"]
    assert set(run["reactions"]) == {"tri.1:start", "tri.2:start", "tri.3:start"}
    bal = run["reaction_balance"]
    assert bal["force"] < 1e-9 and bal["moment"] < 1e-9
    length = sum(np.linalg.norm(np.subtract(POINTS[3], POINTS[i])) for i in range(3))
    weight = 7850 * np.pi / 4 * (0.1**2 - 0.09**2) * length * 9.81
    assert bal["applied_force"] == pytest.approx([1e3, 2e3, -1e4 - weight], rel=1e-6)
    assert "apex" in run["probes"]


@pytest.mark.parametrize("name", ["tower", "dome", "lattice"])
def test_demo_frames_run_and_balance(name, tmp_path):
    run = run_scene(DEMOS / f"{name}.toml", tmp_path / "out", log=lambda m: None)
    assert run.converged
    bal = run["reaction_balance"]
    assert bal["force"] < 1e-9 and bal["moment"] < 1e-9


def _error(path):
    with pytest.raises(SceneError) as e:
        load_scene(path)
    return str(e.value)


def test_missing_and_unreadable_mesh_files(tripod, tmp_path):
    path = tripod(SCENE.replace("tripod.msh", "nothing.msh"))
    assert "frames[0].mesh: no such file" in _error(path)
    path = tripod()
    (tmp_path / "tripod.msh").write_text("$MeshFormat\nnot a mesh\n")
    message = _error(path)
    assert "frames[0].mesh" in message and "tripod.msh: not a mesh meshio can read" in message
    outside = tmp_path / "sub"
    outside.mkdir()
    shutil.copy(path, outside / "scene.toml")
    text = SCENE.replace('"tripod.msh"', '"../tripod.msh"')
    (outside / "scene.toml").write_text(text)
    assert "is outside the scene file's folder" in _error(outside / "scene.toml")


def test_groups_the_mesh_lacks_and_members_without_section(tripod):
    text = SCENE.replace('group = "legs"', 'group = "struts"')
    message = _error(tripod(text))
    assert "frames[0].members[0].group: the mesh has no member (line) group 'struts'" in message
    assert "['legs']" in message
    message = _error(tripod(SCENE.replace('group = "feet"', 'group = "base"')))
    assert "frames[0].supports[0].group: the mesh has no node (point) group 'base'" in message
    message = _error(tripod(members={"legs": [0, 1]}))
    assert "frames[0].members: 1 member(s) of the mesh have no section (first: tri.3" in message


def test_bad_values_name_their_key(tripod):
    text = SCENE.replace("force = [1e3, 2e3, -1e4]", "force = [nan, 0, 0]")
    assert "frames[0].loads[0].force: expected a list of 3 finite numbers" in _error(tripod(text))
    text = SCENE.replace("section = { type", "orientation = [0.7, 0.7, 2.0]\nsection = { type")
    assert "frames[0].members[0].orientation" in _error(tripod(text))
    text = SCENE.replace("elements = 2", "elements = 0")
    assert "frames[0].elements = 0: must be > 0" in _error(tripod(text))
    text = SCENE.replace('group = "apex"\nforce', 'group = "apex"\nforce_per_length')
    assert "frames[0].loads[0]" in _error(tripod(text))


def test_a_follower_load_at_a_joint_of_three_members_is_refused(tripod, tmp_path):
    text = SCENE.replace("KIN", "finite").replace("force = [1e3", 'kind = "follower"\nforce = [1e3')
    with pytest.raises(ValueError, match="joins 3 elements: only dead forces"):
        run_scene(tripod(text), tmp_path / "out", log=lambda m: None)


def test_limits_and_repeated_members(tripod, tmp_path):
    """[limits] max_beams bounds the members; a member given twice (reversed) is refused."""
    text = "[limits]\nmax_beams = 2\n" + SCENE
    assert "frames[0].mesh: 3 members; allowed: at most 2" in _error(tripod(text))
    write_line_mesh(tmp_path / "tripod.msh", POINTS, [*MEMBERS, [3, 0]], {"legs": [0, 1, 2, 3]}, {})
    message = _error(tmp_path / "scene.toml")
    assert "tripod.msh: nodes [4, 1] are joined by two members" in message  # from 1
    # a zero-length member: its nodes numbered from 1, as the nearly coincident ones are
    points = [*POINTS, POINTS[3]]
    write_line_mesh(tmp_path / "tripod.msh", points, [*MEMBERS, [3, 4]], {"legs": [0, 1, 2, 3]}, {})
    assert "tripod.msh: member 4 (nodes [4, 5]) has zero length" in _error(tmp_path / "scene.toml")


def test_closest_point_of_a_line_is_the_clipped_projection():
    """The closed form for straight members (the frame checks call it for every end near a
    member) against the sampled search it replaces for lines; that search finds s only to
    about sqrt(ε) of the length (the distance is flat at its minimum), d to round-off."""
    from beamfx.analyses.checks import closest_arc_length
    from beamfx.geometry.curves import Line, Polyline

    line = Line((0.0, 1.0, 0.0), (3.0, 5.0, 0.0))
    same = Polyline(((0.0, 1.0, 0.0), (3.0, 5.0, 0.0)))  # no closed form: sampled
    for x in ([1.0, 2.0, 1.0], [-2.0, 0.0, 0.0], [4.0, 7.0, -1.0], [1.5, 3.0, 0.0]):
        s, d = closest_arc_length(line, np.array(x))
        s_ref, d_ref = closest_arc_length(same, np.array(x))
        assert s == pytest.approx(s_ref, abs=1e-7) and d == pytest.approx(d_ref, abs=1e-12)


TRIPOD_GEO = """// tripod.geo: the tripod's three legs, and an arched fourth member from the apex
Point(1) = {0, 0, 0};
Point(2) = {2, 0, 0};
Point(3) = {0, 2, 0};
Point(4) = {0.7, 0.7, 2};
Line(1) = {1, 4};
Line(2) = {2, 4};
Line(3) = {3, 4};
Physical Curve("legs") = {1, 2, 3};
Physical Point("feet") = {1, 2, 3};
Physical Point("apex") = {4};
"""


def test_a_geo_frame_equals_the_msh_frame(tripod, tmp_path):
    """The same tripod from a .geo file (gmsh geometry, scanned and read by
    geometry.curves.read_gmsh) gives the same members, groups and reactions."""
    path = tripod(SCENE.replace("KIN", "linear"))
    msh = run_scene(path, tmp_path / "msh", log=lambda m: None)
    (tmp_path / "tripod.geo").write_text(TRIPOD_GEO)
    (tmp_path / "scene.toml").write_text(path.read_text().replace("tripod.msh", "tripod.geo"))
    geo = run_scene(tmp_path / "scene.toml", tmp_path / "geo", log=lambda m: None)
    for at, r in msh["reactions"].items():
        assert np.allclose(geo["reactions"][at]["force"], r["force"], rtol=1e-12, atol=1e-9)


def test_curved_geo_members_follow_the_gmsh_curve(tmp_path):
    """A portal whose girder is a circular arc (gmsh Circle): the member is the arc (its
    length), and the reactions balance the weight."""
    (tmp_path / "arch.geo").write_text(
        "Point(1) = {0, 0, 0};\nPoint(2) = {0, 0, 2};\nPoint(3) = {2, 0, 2};\n"
        "Point(4) = {4, 0, 2};\nPoint(5) = {4, 0, 0};\n"
        "Line(1) = {1, 2};\nCircle(2) = {2, 3, 4};\nLine(3) = {4, 5};\n"
        'Physical Curve("all") = {1, 2, 3};\nPhysical Point("feet") = {1, 5};\n'
    )
    text = SCENE.replace("KIN", "linear").replace("tripod.msh", "arch.geo")
    text = text.replace('"legs"', '"all"').replace('group = "apex"\nforce = [1e3, 2e3, -1e4]\n', "")
    text = text.replace("[[frames.loads]]\n", "").replace('[[frames.probes]]\ngroup = "apex"\n', "")
    (tmp_path / "scene.toml").write_text(text)
    from beamfx.scene import load_scene

    beams = load_scene(tmp_path / "scene.toml").model.beams
    assert beams[1].curve.length == pytest.approx(np.pi * 2, rel=1e-8)
    run = run_scene(tmp_path / "scene.toml", tmp_path / "out", log=lambda m: None)
    assert run["reaction_balance"]["force"] < 1e-9


# a portal in the x-z plane: columns 1-2 and 4-3 (3 m), a beam 2-3 (4 m), square columns
PORTAL_POINTS = [[0, 0, 0], [0, 0, 3], [4, 0, 3], [4, 0, 0]]
PORTAL_MEMBERS = [[0, 1], [1, 2], [3, 2]]
PORTAL = """
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
section = { type = "rectangle", h = 0.25, w = 0.25 }
[[frames.members]]
group = "beam"
section = { type = "rectangle", h = 0.4, w = 0.2 }
[[frames.supports]]
group = "feet"
fix = FIX
[[frames.loads]]
group = "left"
force = [1e4, 0, 0]
[[frames.joints]]
JOINT
[model]
plane = "PLANE"
[analysis]
type = "linear_static"
"""
PINNED = 'group = "knees"\ntype = "pinned"'


@pytest.fixture
def portal(tmp_path):
    """``portal(joint, fix, plane) -> scene path`` of the portal with the joint table."""

    def write(joint=PINNED, fix='"all"', plane="auto"):
        groups = {"columns": [0, 2], "beam": [1]}
        nodes = {"feet": [0, 3], "knees": [1, 2], "left": [1]}
        write_line_mesh(tmp_path / "portal.msh", PORTAL_POINTS, PORTAL_MEMBERS, groups, nodes)
        text = PORTAL.replace("JOINT", joint).replace("FIX", fix).replace("PLANE", plane)
        (tmp_path / "scene.toml").write_text(text)
        return tmp_path / "scene.toml"

    return write


@pytest.mark.parametrize("plane", ["auto", "none"])
def test_portal_with_pinned_knees_equals_the_hand_solution(portal, tmp_path, plane):
    """Both knees hinged: the clamped columns are Timoshenko cantilevers (tip stiffness k_c)
    joined by an axial link (k_b = EA/L): the far column takes H2 = F/(2 + k_c/k_b), the
    loaded one H1 = F − H2, the base moments are H·h and nothing is vertical. Exact (P3
    holds the cantilevers and the release is exact): 1e-9."""
    path = portal('group = "knees"\nreleases = ["ry"]', plane=plane)  # y: normal to the plane
    spec = load_scene(path).model
    # members in file order (groups first): p.1 and p.2 the columns, p.3 the beam
    assert [r.at for r in spec.releases] == ["p.3:start", "p.3:end"]
    _, GA, _, _, EI, _ = spec.beams[0].section.stiffnesses()
    k_c = 1 / (3**3 / (3 * EI) + 3 / GA)
    k_b = spec.beams[2].section.stiffnesses()[0] / 4
    H2 = 1e4 / (2 + k_c / k_b)
    run = run_scene(path, tmp_path / "out", log=lambda m: None)
    left, right = run["reactions"]["p.1:start"], run["reactions"]["p.2:start"]
    assert left["force"] == pytest.approx([-(1e4 - H2), 0, 0], rel=1e-9, abs=1e-9 * 1e4)
    assert right["force"] == pytest.approx([-H2, 0, 0], rel=1e-9, abs=1e-9 * 1e4)
    assert left["moment"][1] == pytest.approx(-3 * (1e4 - H2), rel=1e-9)
    assert right["moment"][1] == pytest.approx(-3 * H2, rel=1e-9)


@pytest.mark.parametrize(
    "joint, fix, named",
    [  # 3D: the beam pinned at both ends spins about its own axis, so it does with only
        # its torsion released at both ends
        (PINNED, '"all"', ["p node 2 (group 'knees')", "p node 3 (group 'knees')"]),
        (
            'group = "knees"\nreleases = ["rx"]\naxes = "member"\nmembers = "beam"',
            '"all"',
            ["p node 2 (group 'knees')", "p node 3 (group 'knees')"],
        ),
    ],
)
def test_mechanisms_are_found_before_the_solve_naming_the_joints(
    portal, tmp_path, joint, fix, named
):
    with pytest.raises(ValueError, match="leave 1 mechanism") as e:
        run_scene(portal(joint, fix, "none"), tmp_path / "out", log=lambda m: None)
    assert all(n in str(e.value) for n in named), str(e.value)


def test_member_axes_and_torsion_release_at_one_end(portal, tmp_path):
    """The beam's torsion released at one knee only is no mechanism (the other end holds
    it); with axes = "member" the release is about the beam's axis (x)."""
    joint = 'group = "left"\nreleases = ["rx"]\naxes = "member"\nmembers = "beam"'
    spec = load_scene(portal(joint)).model
    (rel,) = spec.releases
    assert rel.at == "p.3:start" and rel.released == ("rx",)
    assert np.allclose(rel.axes[0], [1, 0, 0])
    run = run_scene(portal(joint), tmp_path / "out", log=lambda m: None)
    assert run["reaction_balance"]["force"] < 1e-9


@pytest.mark.parametrize(
    "joint, message",
    [
        ('group = "knees"\nreleases = ["rw"]', "joints[0].releases: ['rw']: give distinct"),
        ('group = "knees"\ntype = "pinned"\nreleases = ["rz"]', "joints[0].type: give either"),
        ('group = "knees"\ntype = "hinge"', "joints[0].type"),
        ('group = "knees"', "joints[0].type: missing; allowed: ['rigid', 'pinned']"),
        (
            'group = "elbows"\ntype = "pinned"',
            "joints[0].group: the mesh has no node (point) group 'elbows'",
        ),
        (
            'group = "knees"\ntype = "pinned"\nmembers = "girders"',
            "joints[0].members: the mesh has no member",
        ),
        (
            'group = "knees"\ntype = "pinned"\naxes = { x = [1, 0, 0], y = [2, 0, 0] }',
            "joints[0].axes.y: is zero or parallel to frames[0].joints[0].axes.x",
        ),
        ('group = "knees"\ntype = "pinned"\naxes = "local"', "joints[0].axes"),
    ],
)
def test_bad_joints_name_their_key(portal, joint, message):
    assert message in _error(portal(joint))


def test_joints_in_an_analysis_that_cannot_take_them_are_refused(portal, tmp_path):
    path = portal()
    path.write_text(path.read_text().replace('type = "linear_static"', 'type = "buckling"'))
    assert "frames: pinned or released joints" in _error(path)


def test_nearly_coincident_nodes_are_refused_and_coincident_ones_merged(tripod, tmp_path):
    """A mesh exported without merging its nodes: an exact duplicate at the apex is one node
    (as the mesh builder joins it anyway); one 1e-8 off is refused naming both nodes, their
    groups and members, since the members there would not be joined."""
    points = [*POINTS, [0.7, 0.7, 2.0]]
    write_line_mesh(
        tmp_path / "tripod.msh",
        points,
        [[0, 3], [1, 4], [2, 3]],
        {"legs": [0, 1, 2]},
        {"feet": [0, 1, 2], "apex": [4]},
    )
    (tmp_path / "scene.toml").write_text(SCENE.replace("KIN", "linear"))
    mesh = load_scene(tmp_path / "scene.toml")
    assert mesh.model.beams[1].curve.length == pytest.approx(
        np.linalg.norm(np.subtract(POINTS[3], POINTS[1]))
    )
    points[4] = [0.7, 0.7, 2.0 + 1e-8]
    write_line_mesh(
        tmp_path / "tripod.msh",
        points,
        [[0, 3], [1, 4], [2, 3]],
        {"legs": [0, 1, 2]},
        {"feet": [0, 1, 2], "apex": [4]},
    )
    message = _error(tmp_path / "scene.toml")
    assert (
        "frames[0].mesh" in message and "tripod.msh: node 4 (groups [], members [1, 3])" in message
    )
    assert "node 5 (groups ['apex'], members [2]) are 1e-08 apart" in message


def test_a_planar_sway_mechanism_is_found(portal, tmp_path):
    """Feet and knees hinged about y (normal to the plane): the portal sways freely."""
    joint, fix = 'group = "knees"\nreleases = ["ry"]', '["ux", "uy", "uz", "rx", "rz"]'
    with pytest.raises(ValueError, match="leave 1 mechanism") as e:
        run_scene(portal(joint, fix), tmp_path / "out", log=lambda m: None)
    assert "p node 2 (group 'knees')" in str(e.value)
