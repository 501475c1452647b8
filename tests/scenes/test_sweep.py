"""Parameter sweeps (``[[sweep]]``): members, key paths, errors, and the ensemble run (serial
here; the split-communicator run against serial is in test_mpi.py)."""

import json
import tomllib

import numpy as np
import pytest

from beamfx.runner import check_scene, default_scene_path, run_scene
from beamfx.scene import SceneError, load_scene, parse_scene, parse_sweep
from beamfx.sweep import groups_of

TEXT = default_scene_path().read_text()
BASE = tomllib.loads(TEXT)


def sweep_text(*entries, base=TEXT):
    """A scene file: ``base`` and ``[[sweep]]`` tables (JSON values are TOML inline values)."""
    tables = [f"[[sweep]]\nkey = {json.dumps(k)}\nvalues = {json.dumps(v)}\n" for k, v in entries]
    return base + "\n" + "\n".join(tables)


def sweep_data(*entries, edit=None):
    data = json.loads(json.dumps(BASE))
    if edit:
        edit(data)
    data["sweep"] = list(entries)
    return data


def test_members_are_all_combinations():
    data = sweep_data(
        {"key": "loads[0].force", "values": [[0, 0, 150], [0, 0, 300], [0, 0, 600]]},
        {"key": ["beams.bend.elements", "beams.bend.degree"], "values": [[4, 2], [2, 4]]},
    )
    sweep = parse_sweep(data, "s.toml")
    assert len(sweep.members) == 6
    assert sweep.keys == ("loads[0].force", "beams.bend.elements", "beams.bend.degree")
    last = sweep.members[-1]
    assert last.values == {
        "loads[0].force": [0, 0, 600],
        "beams.bend.elements": 2,
        "beams.bend.degree": 4,
    }
    assert last.scene.model.point_loads[0].force == (0.0, 0.0, 600.0)
    beam = last.scene.model.beams[0]
    assert (beam.elements, beam.degree) == (2, 4)
    # the base data is not changed by its members
    assert data["beams"][0]["elements"] == BASE["beams"][0]["elements"]


@pytest.mark.parametrize("key", ["loads.0.force", "loads[0].force"])
def test_array_entries_by_index_or_name(key):
    data = sweep_data({"key": key, "values": [[0, 0, 1]]})
    assert parse_sweep(data).members[0].scene.model.point_loads[0].force == (0.0, 0.0, 1.0)
    data = sweep_data({"key": "beams[bend].section.h", "values": [2.0]})
    assert parse_sweep(data).members[0].scene.model.beams[0].section.EI_y == pytest.approx(
        parse_scene(BASE).model.beams[0].section.EI_y * 8  # h³
    )


def test_a_single_sweep_table_is_one_entry():
    data = sweep_data()
    data["sweep"] = {"key": "analysis.steps", "values": [2, 3]}
    assert [m.scene.steps for m in parse_sweep(data).members] == [2, 3]


@pytest.mark.parametrize(
    "entry, words",
    [
        ({"key": "beams.spring.elements", "values": [2]}, ["no entry 'spring'", "['bend']"]),
        ({"key": "loads[3].force", "values": [2]}, ["no entry '3'", "index 0..0"]),
        ({"key": "analysys.steps", "values": [2]}, ["no key 'analysys'", "analysis"]),
        ({"key": "beams.bend.elements", "values": []}, ["sweep[0].values", "empty"]),
        ({"key": 3, "values": [2]}, ["sweep[0].key", "key path"]),
        ({"key": ["analysis.steps", "beams.bend.elements"], "values": [2]}, ["list of 2"]),
        ({"key": "analysis.steps", "values": [2], "vales": 1}, ["sweep[0].vales", "unknown"]),
        (
            {"key": "beams.bend.elements", "values": [4, 0]},
            ["sweep member 1", "beams.bend.elements = 0", "beams[0].elements", "> 0"],
        ),
        ({"key": "analysis.type", "values": ["statics"]}, ["analysis.type", "allowed"]),
    ],
)
def test_bad_sweeps_are_named(entry, words):
    with pytest.raises(SceneError) as e:
        parse_sweep(sweep_data(entry), "s.toml")
    assert "s.toml" in str(e.value)
    for w in words:
        assert w in str(e.value), (w, str(e.value))


def test_same_key_twice_is_an_error():
    entries = [{"key": "analysis.steps", "values": [1]}, {"key": "analysis.steps", "values": [2]}]
    with pytest.raises(SceneError, match="swept twice"):
        parse_sweep(sweep_data(*entries), "s.toml")


def test_load_scene_points_a_sweep_file_to_the_sweep(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(sweep_text(("analysis.steps", [2, 3])))
    with pytest.raises(SceneError, match="family of scenes"):
        load_scene(path)
    assert len(check_scene(path).members) == 2


def test_groups_split_ranks_evenly():
    assert groups_of(1, 5) == (1, [0])
    assert groups_of(2, 5) == (2, [0, 1])
    assert groups_of(4, 2) == (2, [0, 0, 1, 1])
    assert groups_of(3, 2) == (2, [0, 0, 1])
    assert groups_of(2, 1) == (1, [0, 0])


def test_sweep_rows_are_the_members_own_runs(tmp_path):
    """Each row of the table is what running that member's scene alone gives; a member whose
    Newton solve fails is reported as failed and the others go on."""
    base = TEXT + "\n[solver]\nsnes_max_it = 50\n"
    path = tmp_path / "sweep.toml"
    path.write_text(
        sweep_text(
            ("loads[0].force", [[0, 0, 300], [0, 0, 600]]),
            ("solver.snes_max_it", [50, 1]),
            base=base,
        )
    )
    lines = []
    table = run_scene(path, tmp_path / "out", log=lines.append)
    rows = table["members"]
    assert [r["status"] for r in rows] == ["converged", "failed"] * 2
    # the caller's log gets every member's lines, tagged (none printed past it)
    for i in range(4):
        assert any(line.startswith(f"[member {i}/4] ") for line in lines), i
    assert "DIVERGED_MAX_IT" in rows[1]["reason"]
    for row, force in zip(rows[::2], (300, 600)):
        single = tmp_path / f"alone_{force}.toml"
        single.write_text(base.replace("force = [0, 0, 600]", f"force = [0, 0, {force}]"))
        expected = run_scene(single, tmp_path / f"alone_{force}")["probes"]["tip"]
        got = row["probes"]["tip"]
        for what in ("displacement", "rotation_vector"):
            assert np.allclose(got[what], expected[what], rtol=1e-12, atol=1e-12)
        folder = tmp_path / "out" / row["folder"]
        assert json.loads((folder / "results.json").read_text())["probes"]["tip"] == expected
    out = tmp_path / "out"
    assert json.loads((out / "sweep.json").read_text())["members"] == rows
    assert len((out / "sweep.jsonl").read_text().splitlines()) == 4
    csv = (out / "sweep.csv").read_text().splitlines()
    assert csv[0].startswith("member,loads[0].force,solver.snes_max_it,status")
    assert len(csv) == 5
    assert "member 1 failed" in (out / "sweep.md").read_text()
