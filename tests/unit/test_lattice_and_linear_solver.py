"""The lattice generator (geometry/lattice.py), the pairwise-free joint search on it, and the
``[solver] linear`` preset: validated, expanded, and the same answer as the direct solver."""

from pathlib import Path

import numpy as np
import pytest

from beamfx.geometry.lattice import bcc_counts, bcc_lattice, cells_for
from beamfx.geometry.line_mesh import read_line_mesh
from beamfx.scene.table import SceneError
from beamfx.solvers.options import LINEAR, expand_linear, is_iterative, option_problems

DEMOS = Path(__file__).resolve().parents[2] / "demos" / "scenes"


def _pairs(members):
    return {tuple(sorted(map(int, m))) for m in members}


def test_the_generator_makes_the_demo_lattice():
    """3³ cells: the nodes, members and node groups of demos/scenes/lattice.msh."""
    demo, ours = read_line_mesh(DEMOS / "lattice.msh"), bcc_lattice(3)
    assert np.allclose(demo.points, ours.points)
    assert _pairs(demo.members) == _pairs(ours.members)
    for name in ("edges", "struts"):
        assert _pairs(demo.members[demo.member_groups[name]]) == _pairs(
            ours.members[ours.member_groups[name]]
        )
    for name in ("bottom", "top"):
        assert set(demo.node_groups[name]) == set(ours.node_groups[name])


@pytest.mark.parametrize("cells", [1, 2, 4, 7])
def test_lattice_counts_and_geometry(cells):
    m, c = bcc_lattice(cells), bcc_counts(cells)
    assert (len(m.points), len(m.members)) == (c.nodes, c.members)
    assert len(_pairs(m.members)) == c.members  # no member twice
    lengths = np.linalg.norm(m.points[m.members[:, 1]] - m.points[m.members[:, 0]], axis=1)
    edge, strut = lengths[m.member_groups["edges"]], lengths[m.member_groups["struts"]]
    assert np.allclose(edge, 0.01) and np.allclose(strut, 0.01 * np.sqrt(3) / 2)
    assert np.allclose(m.points[m.node_groups["bottom"], 2], 0)
    assert np.allclose(m.points[m.node_groups["top"], 2], 0.01 * cells)
    assert np.allclose(m.points[m.node_groups["corner"]], 0.01 * cells)
    assert bcc_counts(cells_for(c.unknowns)).unknowns == c.unknowns


def test_joint_search_finds_every_shared_node_of_a_lattice():
    """end_contacts (k-d tree) on a 2³ lattice: each member end touches exactly the other
    members at its node (no T-joints), and the frame is one connected group."""
    from beamfx.analyses.checks import connected_beams, end_contacts, joint_breaks
    from beamfx.geometry.curves import Line
    from beamfx.spec import Beam, Model

    m = bcc_lattice(2)
    beams = tuple(
        Beam(f"b.{k}", Line(tuple(m.points[a]), tuple(m.points[b])), None, 1, 2)
        for k, (a, b) in enumerate(m.members)
    )
    model = Model(beams, ())
    found = {(i, j) for i, j, _ in end_contacts(model)}
    expected = {
        (i, j)
        for i, mi in enumerate(m.members)
        for j, mj in enumerate(m.members)
        if i != j and set(mi) & set(mj)
    }
    assert found == expected
    assert joint_breaks(model) == []
    assert connected_beams(model) == [list(range(len(beams)))]


def test_linear_preset_is_validated_and_expanded():
    assert list(option_problems({"linear": "iterative", "ksp_rtol": 1e-8})) == []
    assert list(option_problems({"linear": "direct"})) == []
    (key, message), *_ = option_problems({"linear": "gamg"})
    assert key == "linear" and "'direct', 'iterative'" in message
    expanded = expand_linear({"linear": "iterative", "ksp_type": "gmres"})
    assert expanded["ksp_type"] == "gmres" and expanded["pc_type"] == "hypre"  # given wins
    assert "linear" not in expanded and is_iterative(expanded)
    assert not is_iterative(expand_linear({"linear": "direct"}))
    assert expand_linear(None) == {} and set(LINEAR) == {"direct", "iterative"}
    with pytest.raises(ValueError, match="allowed"):
        expand_linear({"linear": "cg"})


def test_a_scene_with_an_unknown_linear_preset_is_refused():
    from beamfx.scene.load import parse_scene

    base = {
        "material": {"E": 2e11, "nu": 0.3},
        "beams": [{"name": "b", "curve": {"shape": "line", "start": [0, 0, 0], "end": [1, 0, 0]},
                   "section": {"type": "circle", "d": 0.01}}],
        "supports": [{"at": "b:start", "fix": "all"}],
    }  # fmt: skip
    assert parse_scene(base | {"solver": {"linear": "iterative"}}).solver_options == {
        "linear": "iterative"
    }
    with pytest.raises(SceneError, match="solver.linear: 'lu': allowed: 'direct', 'iterative'"):
        parse_scene(base | {"solver": {"linear": "lu"}}, "x.toml")


@pytest.mark.parametrize("kinematics", ["linear", "finite"])
def test_iterative_and_direct_give_the_same_lattice(tmp_path, kinematics):
    """A 2³ lattice: CG + BoomerAMG and MUMPS agree on the corner probe and the reactions to
    1e-10 (the Newton test stops at 1e-10 of the load; CG is asked for 1e-12), and the
    iterative run does no LDLᵀ inertia count."""
    from mpi4py import MPI

    from beamfx.bench.frame_scaling import lattice_scene
    from beamfx.runner import run_scene

    out = {}
    for linear in ("direct", "iterative"):
        scene = lattice_scene(tmp_path, 2, kinematics, linear, MPI.COMM_SELF)
        out[linear] = run_scene("lattice", tmp_path / linear, lambda m: None, scene=scene)
    a, b = out["direct"], out["iterative"]
    ua, ub = a["probes"]["corner"]["displacement"], b["probes"]["corner"]["displacement"]
    assert np.allclose(ua, ub, rtol=0, atol=1e-10 * np.max(np.abs(ua)))
    for at, r in a["reactions"].items():
        assert np.allclose(r["force"], b["reactions"][at]["force"], rtol=0, atol=1e-10 * 9)
    assert "inertia" not in b["wall_time_s"]
