"""The examples of docs/scenes.md.

Every ```toml block is a valid scene (checked next to the files of the ```geo blocks, each named
on its first line "// name.geo"), the 45-degree bend runs, and every ```toml-error block fails
with the message of the ```text block after it. Other fences (```toml-nocheck) are not checked.
"""

import json
import re
from pathlib import Path

import pytest

from beamfx.runner import check_scene, run_scene
from beamfx.scene import SceneError

DOC = Path(__file__).resolve().parents[2] / "docs" / "scenes.md"
FENCE = re.compile(r"^```([\w-]*)\n(.*?)^```$", re.MULTILINE | re.DOTALL)


def _blocks():
    """(info string, first line number, text) of every fenced block of the document."""
    text = DOC.read_text(encoding="utf-8")
    return [
        (m.group(1), text.count("\n", 0, m.start()) + 1, m.group(2)) for m in FENCE.finditer(text)
    ]


def _of(kind):
    return [pytest.param(body, id=f"line{line}") for info, line, body in _blocks() if info == kind]


def _error_pairs():
    blocks = _blocks()
    pairs = []
    for i, (info, line, body) in enumerate(blocks):
        if info == "toml-error":
            after = blocks[i + 1] if i + 1 < len(blocks) else ("", 0, "")
            assert after[0] == "text", (
                f"docs/scenes.md:{line}: toml-error block without a text block"
            )
            pairs.append(pytest.param(body, after[2].strip(), id=f"line{line}"))
    return pairs


BEND = "# 45-degree bend under a vertical tip load (Bathe & Bolourchi 1979)\n"


def test_document_has_examples():
    toml = _of("toml")
    assert len(toml) > 10
    assert toml[0].values[0].startswith(BEND), "the document must begin with the 45-degree bend"
    assert _error_pairs()


def _write_geo_files(folder):
    for info, line, body in _blocks():
        if info == "geo":
            name = re.match(r"// *([\w.-]+\.geo)\b", body)
            assert name, f"docs/scenes.md:{line}: a geo block starts with '// name.geo'"
            (folder / name.group(1)).write_text(body, encoding="utf-8")


@pytest.mark.parametrize("text", _of("toml"))
def test_toml_block_is_a_valid_scene(text, tmp_path):
    _write_geo_files(tmp_path)
    scene = tmp_path / "scene.toml"
    scene.write_text(text, encoding="utf-8")
    check_scene(scene)


@pytest.mark.parametrize("text, message", _error_pairs())
def test_error_block_gives_the_documented_message(text, message, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # messages name the file as given: "scene.toml"
    Path("scene.toml").write_text(text, encoding="utf-8")
    with pytest.raises((SceneError, ValueError)) as e:
        check_scene("scene.toml")
    assert f"beamfx: error: {e.value}" == message


def test_bend45_example_runs(tmp_path):
    text = next(p.values[0] for p in _of("toml") if p.values[0].startswith(BEND))
    scene = tmp_path / "bend45.toml"
    scene.write_text(text, encoding="utf-8")
    out = tmp_path / "out"
    run_scene(scene, out_dir=out, log=lambda message: None)

    results = json.loads((out / "results.json").read_text())
    assert results["converged"] is True
    tip = results["probes"]["tip"]
    assert len(tip["position"]) == 3 and all(isinstance(x, float) for x in tip["position"])
    assert len(tip["displacement"]) == 3
    # Bathe & Bolourchi (1979): tip at (15.9, 47.2, 53.4); published values spread by ~0.4
    assert tip["position"] == pytest.approx([15.9, 47.2, 53.4], abs=0.5)
    assert tip["displacement"] == pytest.approx(
        [p - x for p, x in zip(tip["position"], [100 - 100 * 2**-0.5, 100 * 2**-0.5, 0])], abs=1e-9
    )
    # the files the [output] section of the document lists
    for name in ("deformed.pvd", "deformed_0001.vtu"):
        assert (out / name).is_file(), name
