"""The count of free dofs with a finite eigenvalue (beamfx.analyses.mode_count) that bounds
``[analysis] modes`` on reading: exact for a cantilever, an upper bound elsewhere."""

import tomllib

import numpy as np
import pytest

from beamfx.analyses.mode_count import count_dofs, free_dofs_of, spec_nodes
from beamfx.scene import SceneError, parse_scene

BEAM = """
[material]
E = 210e9
rho = 7850

[[beams]]
name = "b"
curve = {{ shape = "line", start = [0, 0, 0], end = [1, 0, 0] }}
section = {{ type = "circle", d = 0.02 }}
elements = {elements}
degree = {degree}

[[supports]]
at = "b:start"
fix = "all"
{more}
[analysis]
type = "modal"
modes = {modes}
{analysis}
"""


def spec(elements=16, degree=3, more="", analysis="", modes=1):
    text = BEAM.format(elements=elements, degree=degree, more=more, analysis=analysis, modes=modes)
    return parse_scene(tomllib.loads(text), "my.toml").model


def free(model, rotary=None):
    return free_dofs_of(model, spec_nodes(model), rotary)


def test_a_clamped_cantilever_has_six_per_free_node():
    """16 x P3: 49 nodes, 343 unknowns (7 per node: the quaternion's fourth has no mass); the
    clamp takes one node: 48 x 6 = 288, the pairs SLEPc converged when asked for 340."""
    model = spec()
    assert spec_nodes(model) == 49
    assert free(model, "full") == 288
    assert free(model) == 288  # buckling: every nodal dof
    assert count_dofs(model, 49, "none") == (49, 3, 0, 3)
    assert free(model, "polar") == 48 * 4  # the clamp fixes the polar one too


def test_point_masses_releases_and_local_supports():
    """A point mass with rotary inertia gives its node its rotations back ("none"); a support
    in local axes is a spring (its dofs stay unknowns); a second support at the same point
    fixes nothing twice."""
    mass = '\n[[masses]]\nat = "b:end"\nmass = 1.0\ninertia = [1e-3, 1e-3, 1e-3]\n'
    assert free(spec(more=mass), "none") == 48 * 3 + 3
    local = '\n[[supports]]\nat = "b:end"\nfix = ["uy"]\naxes = "local"\n'
    assert free(spec(more=local), "full") == 288
    twice = '\n[[supports]]\nat = "b:start"\nfix = ["ux", "uy"]\n'
    assert free(spec(more=twice), "full") == 288


def test_the_planar_model_has_three_per_node():
    """[model] plane = "xy": ux, uy, rz per node; "polar" leaves rz (a bending axis) no mass."""
    model = spec(more='\n[model]\nplane = "xy"\n')
    assert free(model, "full") == 48 * 3
    assert free(model, "polar") == 48 * 2


def test_modes_beyond_the_count_are_refused_with_the_count():
    with pytest.raises(SceneError) as e:
        spec(elements=2, degree=2, analysis='rotary_inertia = "none"', modes=13)
    message = str(e.value)
    assert message.startswith("my.toml: analysis.modes = 13: more than a modal analysis")
    assert "5 nodes x 3 dofs with mass (rotary_inertia = 'none') − 3 fixed" in message
    assert "allowed: an integer in [1, 12]" in message


FRAME = BEAM.replace(
    "[[supports]]",
    """[[beams]]
name = "post"
curve = {{ shape = "line", start = [0.3, 0, 0], end = [0.3, 0, 1] }}
section = {{ type = "circle", d = 0.02 }}
elements = 2
degree = 1

[[beams]]
name = "arm"
curve = {{ shape = "line", start = [1, 0, 0], end = [1, 1, 0] }}
section = {{ type = "circle", d = 0.02 }}
elements = 1
degree = 1

[[probes]]
name = "p"
at = "arm:0.5"

[[supports]]""",
)


def test_the_count_on_reading_is_the_built_mesh_s():
    """Joined beams share a node (arm), a T-joint (post on b at s = 0.3) and a probe (arm's
    middle) put a vertex in: the nodes counted on reading are those of the mesh built."""
    from mpi4py import MPI

    from beamfx.analyses.mode_count import mesh_nodes
    from beamfx.analyses.planar_condensed import build_model

    text = FRAME.format(elements=2, degree=2, more="", analysis="", modes=1)
    scene = parse_scene(tomllib.loads(text), "my.toml")
    # b: its 2 cells split at the T-joint (s = 0.3), 5 nodes at P2; post: 2 cells, its foot
    # on b: +4; arm: 1 element but 2 cells (a vertex at the probe), its start on b's end: +4
    assert spec_nodes(scene.model, tuple(scene.probes.values())) == 13
    model = build_model(scene.model, MPI.COMM_WORLD, list(scene.probes.values()), False)
    assert mesh_nodes(model) == 13
    assert free_dofs_of(scene.model, 13) == 13 * 6 - 6
    parse_scene(tomllib.loads(FRAME.format(elements=2, degree=2, more="", analysis="", modes=72)))
    text = FRAME.format(elements=2, degree=2, more="", analysis="", modes=73)
    with pytest.raises(SceneError, match=r"analysis\.modes = 73: .*\(13 nodes x 6 dofs"):
        parse_scene(tomllib.loads(text))


def test_the_nearest_in_hz_are_proven_only_when_the_pairs_reach_far_enough():
    """Pairs nearest 100 Hz in ω²: 65, 129, 21, 10 Hz. The 3 nearest in Hz among them (129,
    65, 21: 79 Hz off) are not proven: a mode up to 179 Hz (79² + 2·100·79 in Hz²) would be
    nearer than 21 Hz and may be missing, and the pairs found reach only 9900 Hz² from the
    target. With 182 Hz found as well they are."""
    from beamfx.analyses.modal_target import nearest_in_hz

    def lam(f):
        return (2 * np.pi * np.asarray(f, float)) ** 2

    hz = [65.0, 129.0, 21.0, 10.0]
    keep, proven = nearest_in_hz(hz, lam(hz), 3, 100.0)
    assert [hz[i] for i in keep] == [129.0, 65.0, 21.0] and not proven
    hz = [65.0, 129.0, 21.0, 10.0, 182.0]
    keep, proven = nearest_in_hz(hz, lam(hz), 3, 100.0)
    assert [hz[i] for i in keep] == [129.0, 65.0, 21.0] and proven


def test_a_rotating_analysis_is_bounded_by_the_same_count():
    """The built-in rotating strip (16 x P3, clamped): 288 modes per speed at most."""
    from beamfx.runner import default_scene_path

    text = (default_scene_path().parent / "pai_rotating.toml").read_text()
    assert "\nmodes = 4\n" in text
    parse_scene(tomllib.loads(text.replace("\nmodes = 4\n", "\nmodes = 288\n")), "r.toml")
    with pytest.raises(SceneError, match=r"r\.toml: analysis\.modes = 289: more than a rotating"):
        parse_scene(tomllib.loads(text.replace("\nmodes = 4\n", "\nmodes = 289\n")), "r.toml")


def test_when_the_count_overestimates_the_modes_all_found_are_taken():
    """A model with 15 finite modes counted 16 (polar inertia, a single rotation fixed):
    asking for 16 to find the 8 nearest in Hz fails with 15 converged; those are all there
    are, so they are asked for and the answer is exact (not a failure: the user asked 8)."""
    from beamfx.analyses.modal import ModalResult
    from beamfx.analyses.modal_target import solve_nearest_hz
    from beamfx.solvers import SolveFailed

    spectrum = np.array([1.0, 2.0, 3.0, 5.0, 8.0, 13.0, 21.0, 34.0, 55.0, 89.0, 144.0, 233.0])
    spectrum = np.r_[spectrum, 377.0, 610.0, 987.0]  # 15 modes (Hz)
    asked = []

    def solve(m):
        asked.append(m)
        if m > len(spectrum):
            raise SolveFailed("too few", details={"requested": m, "converged": len(spectrum)})
        lam = (2 * np.pi * spectrum) ** 2
        order = np.argsort(np.abs(lam - (2 * np.pi * 30.0) ** 2), kind="stable")[:m]
        hz = spectrum[order]
        return ModalResult(lam[order], 2 * np.pi * hz, hz, tuple(hz), 0 * hz, {"solve": 1.0})

    res = solve_nearest_hz(solve, 8, 30.0, 16)
    assert asked == [16, 15]
    expected = spectrum[np.argsort(np.abs(spectrum - 30.0), kind="stable")[:8]]
    assert list(res.hz) == list(expected) and res.seconds == {"solve": 1.0}
