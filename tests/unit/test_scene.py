"""Scene files: bad input gets a clear error naming the file, the key path and what is allowed."""

import json
import tomllib

import pytest

from beamfx.runner import check_scene, default_scene_path, run_scene
from beamfx.scene import SceneError, parse_scene

BASE = tomllib.loads(default_scene_path().read_text())


def scene_with(edit):
    data = json.loads(json.dumps(BASE))
    edit(data)
    return data


@pytest.mark.parametrize(
    "edit, words",
    [
        (
            lambda d: d["beams"][0].update(elemnts=3),
            ["beams[0].elemnts", "unknown key", "elements"],
        ),
        (
            lambda d: d["beams"][0].update(elements="8"),
            ["beams[0].elements", "expected an integer"],
        ),
        (  # a misspelt key whose table then lacks the key: the misspelling is named
            lambda d: d.update(springs=[{"at": "bend:end", "stiffnes": [1.0, 2.0, 3.0]}]),
            ["springs[0].stiffnes: unknown key; did you mean 'stiffness'?"],
        ),
        (
            lambda d: d.update(masses=[{"at": "bend:end", "mas": 1.0}]),
            ["masses[0].mas: unknown key; did you mean 'mass'?"],
        ),
        (  # the words allowed, not Python's type names
            lambda d: d["supports"][0].update(fix=6),
            ["supports[0].fix", "6 is not allowed; allowed: ['all', 'clamped', 'pinned']"],
        ),
        (lambda d: d["material"].update(E=True), ["material.E", "got true"]),
        (  # a key of another analysis type: which ones take it
            lambda d: d["analysis"].update(modes=4),
            ["analysis.modes: unknown key", "'modes' is a key of type = [", "'modal'"],
        ),
        (
            lambda d: d["beams"][0]["curve"].update(shape="circle"),
            ["beams[0].curve.shape", "allowed", "arc"],
        ),
        (lambda d: d["beams"][0]["curve"].update(angle_deg=0), ["angle_deg = 0", "> 0"]),
        (lambda d: d["material"].update(E=-1.0), ["material.E = -1.0", "finite number > 0"]),
        (
            lambda d: d["beams"][0]["section"].update(
                type="general", EA=1.0, GA_y=1.0, GA_z=1.0, GJ=0.0, EI_y=1.0, EI_z=1.0
            ),
            ["section.GJ = 0.0", "finite number > 0"],
        ),
        (lambda d: d["loads"][0].update(at="bnd:end"), ["'bnd:end'", "names no beam", "bend"]),
        (lambda d: d["loads"][0].update(at="bend:1.5"), ["bend:1.5", "[0, 1]"]),
        (
            lambda d: d["supports"][0].update(fix=["ux", "rotz"]),
            ["supports[0].fix", "allowed", "rz"],
        ),
        (lambda d: d["analysis"].update(type="dynamic"), ["analysis.type", "static"]),
        (
            lambda d: d["beams"][0].update(
                curve={"shape": "line", "start": [0, 0, 0], "end": [0, 0, 0]}
            ),
            ["beams[0].curve.end", "zero length"],
        ),
    ],
)
def test_bad_input_names_file_key_and_allowed_values(edit, words):
    with pytest.raises(SceneError) as err:
        parse_scene(scene_with(edit), "my.toml")
    message = str(err.value)
    assert message.startswith("my.toml: ")
    for w in words:
        assert w in message, message


def test_free_rigid_body_motion_is_refused_before_solving(tmp_path):
    data = scene_with(lambda d: d["supports"][0].update(fix="pinned"))
    path = tmp_path / "s.toml"
    path.write_text(_toml(data))
    with pytest.raises(ValueError, match="3 rigid-body motion"):
        check_scene(path)


def test_failed_run_leaves_no_results_json(tmp_path):
    """A stale results.json is removed before solving; a refused scene writes none."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "results.json").write_text('{"converged": true}')
    data = scene_with(lambda d: d["supports"][0].update(fix="pinned"))
    path = tmp_path / "s.toml"
    path.write_text(_toml(data))
    with pytest.raises(ValueError):
        run_scene(path, out)
    assert not (out / "results.json").exists()


def test_unwritable_output_folder_fails_before_the_solve(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("")
    with pytest.raises(OSError, match="cannot write results"):
        run_scene(default_scene_path(), blocker / "out")


def _toml(data):
    """Minimal TOML writer for these scenes (tables, arrays of tables, inline values)."""

    def value(v):
        if isinstance(v, dict):
            return "{ " + ", ".join(f"{k} = {value(x)}" for k, x in v.items()) + " }"
        if isinstance(v, list):
            return "[" + ", ".join(value(x) for x in v) + "]"
        if isinstance(v, str):
            return json.dumps(v)
        return repr(v).lower() if isinstance(v, bool) else repr(v)

    lines = []
    for key, v in data.items():
        if isinstance(v, list) and v and isinstance(v[0], dict):
            for item in v:
                lines += [f"[[{key}]]"] + [f"{k} = {value(x)}" for k, x in item.items()]
        else:
            lines += [f"[{key}]"] + [f"{k} = {value(x)}" for k, x in v.items()]
    return "\n".join(lines) + "\n"
