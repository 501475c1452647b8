"""A scene through ``beamfx run`` with the mixed formulation: chosen automatically for a
shear-rigid, inextensible model, logged and in results.json, and the displacement (penalty)
model's answer to the penalty's error."""

import json
import tomllib

import numpy as np

from beamfx.runner import default_scene_path, run_scene
from beamfx.scene import parse_scene

BASE = tomllib.loads(default_scene_path().read_text())


def _run(tmp_path, name, **model):
    data = json.loads(json.dumps(BASE))
    data["model"] = {"shear": False, "stretch": False, "condense": "none", **model}
    data["beams"][0]["degree"] = 3  # the two quaternion penalties move a P2 tip by 1e-3
    lines = []
    run = run_scene(
        f"{name}.toml",
        tmp_path / name,
        log=lines.append,
        scene=parse_scene(data, f"{name}.toml"),
    )
    return run, lines, json.loads((tmp_path / name / "results.json").read_text())


def test_auto_mixed_for_a_kirchhoff_rod(tmp_path):
    """The 45° bend as a Kirchhoff rod: the builder picks the mixed form (exact constraints);
    the penalty model (1e8 EI/L², stated displacement) is within its ~3e-8 relative error,
    the quaternion penalties' difference (1e-7 at 8 × P3) and Newton's tolerance: 1e-6 of the
    tip displacement."""
    mixed, lines, results = _run(tmp_path, "auto")
    assert mixed.converged
    entry = results["model"]["formulation"]
    assert entry["name"] == "mixed" and "shear-rigid and inextensible" in entry["reason"]
    assert any(line.startswith("model: mixed formulation") for line in lines), lines
    penalty, _, other = _run(tmp_path, "penalty", formulation="displacement")
    assert other["model"]["formulation"]["name"] == "displacement"
    a = np.asarray(mixed.probes["tip"]["displacement"])
    b = np.asarray(penalty.probes["tip"]["displacement"])
    assert np.linalg.norm(a - b) <= 1e-6 * np.linalg.norm(b), (a, b)
