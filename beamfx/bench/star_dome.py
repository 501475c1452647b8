"""The 24-member star dome (Meek & Tan 1984; a classic of corotational frame analysis) under a
vertical load at the apex: the snap-through (limit) load of its symmetric path.

The scene is ``demos/scenes/star_dome.toml`` (the one a user runs; geometry
``star_dome.geo``, a copy of ``meshes/star_dome/star_dome.geo``), units cm and kN: rigid
joints, the six outer nodes pinned, shear-rigid members with E = 3030 kN/cm²,
G = 1096 kN/cm², A = 3.17 cm², I_y = I_z = 2.377 cm⁴, J = 2.1 cm⁴, P = 1 kN times the load
factor. The arc-length trace passes a bifurcation (a pair of negative eigenvalues: the
asymmetric modes, double by the dome's symmetry) just before the symmetric limit point, and
stays on the symmetric path, as displacement control does.

Reference: no published limit load could be checked offline for these section values, so the
case's reference is withheld (the finest setting is the reference); the independent check is
OpenSeesPy (corotational ``elasticBeamColumn`` elements, displacement control,
:mod:`peers/opensees_star_dome.py`, run by ``make bench-peers`` through
:mod:`~beamfx.bench.star_dome_peers`), whose limit load converges in mesh to the same value.
"""

import tomllib
from pathlib import Path

from .registry import register
from .scenes import SceneCase

DEMOS = Path(__file__).resolve().parents[2] / "demos" / "scenes"
SCENE = DEMOS / "star_dome.toml"
#: the apex: the start of the first member (the ribs run from the apex to the inner ring)
APEX = "dome.1:start"


def scene_data(elements=None, degree=None):
    """The TOML data of demos/scenes/star_dome.toml, with ``elements`` per member of degree
    ``degree`` if given."""
    data = tomllib.loads(SCENE.read_text())
    if elements is not None:
        data["frames"][0].update(elements=elements, degree=degree)
    return data


def scene(elements=None, degree=None, data=None):
    """The parsed scene (its geometry file read from demos/scenes/)."""
    from ..scene.load import parse_scene

    return parse_scene(data or scene_data(elements, degree), str(SCENE), DEMOS)


def read_limit(result):
    """The first load maximum of an arc-length result: ``limit_load`` (kN) and the apex's
    ``limit_uz`` (cm) there."""
    top = next((p for p in result.limit_points if p["kind"] == "maximum"), None)
    if top is None:
        raise RuntimeError("star dome: the trace passed no load maximum")
    return {"limit_load": top["load_factor"], "limit_uz": top["displacement"][2]}


def _snap(elements, degree):
    return [(scene(elements, degree), read_limit)]


register(
    SceneCase(
        "star_dome",
        "Meek & Tan 1984 (star dome)",
        "24-member star dome, apex load: symmetric snap-through (limit) load",
        _snap,
        lambda values: values,
        None,
        1e-4,
        tuple((n, p) for p in (2, 3) for n in (1, 2, 4, 8)),
        note="Arc-length trace of the symmetric path (the demo scene with 1 to 8 elements per "
        "member), limit point placed by a quadratic fit in the arc length. Reference withheld "
        "(no published value checked offline for these section values): the finest setting "
        "is the reference. The independent check, OpenSeesPy with corotational "
        "elasticBeamColumn elements under displacement control, is in "
        "docs/validation/star_dome.md (make bench-peers).",
    )
)
