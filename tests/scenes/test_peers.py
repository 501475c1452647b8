"""The merge of peer records (beamfx.bench.peers) on fake records: no peers installed."""

import json

from beamfx.bench import peers


def _rec(code, setting, wall, err, problem="p", element="", **kw):
    """A record whose whole run is its solve unless ``whole_s`` is given."""
    return {
        "problem": problem,
        "code": code,
        "element": element,
        "setting": setting,
        "unknowns": 10,
        "whole_s": wall,
        "wall_s": wall,
        "error": err,
        "values": None,
    } | kw


def test_error_is_the_bench_metric():
    ref = {"x": 2.0, "y": -4.0}
    assert abs(peers.error({"x": 2.2, "y": -4.0}, ref, None) - 0.1) < 1e-12  # relative
    assert abs(peers.error({"x": 2.2, "y": -4.0}, ref, 10.0) - 0.02) < 1e-12  # absolute / scale
    assert peers.error({"x": 2.0}, ref, None) is None  # a missing value is no score


def test_rescore_uses_reference_and_skips_the_reference_row():
    recs = [
        _rec("beamfx", "ref", 1.0, 0.0, values={"x": 1.0}, is_reference=True),
        _rec("Exudyn", "8", 0.1, None, values={"x": 1.001}),
    ]
    peers.rescore(recs, {"p": {"x": 1.0}}, {"p": None})
    assert recs[0]["error"] is None
    assert abs(recs[1]["error"] - 1e-3) < 1e-12


def test_summary_target_and_verdict():
    recs = [
        _rec("beamfx", "a", 0.05, 1e-3),
        _rec("beamfx", "b", 0.2, 1e-7),
        _rec("Exudyn", "8", 0.1, 1e-3, element="GE"),
        _rec("Exudyn", "64", 1.0, 1e-5, element="GE"),
        _rec("PyElastica", "—", None, None, note="cannot: no eigen solver"),
    ]
    s = peers.summary(recs, "p")
    assert s["target"] == 1e-5  # the best peer error, larger than 1e-6
    assert s["beamfx_time"] == 0.2
    assert s["lines"]["Exudyn (GE)"]["time_to_target"] == 1.0
    assert s["lines"]["PyElastica"]["best_error"] is None
    assert s["beamfx_ahead"]
    recs.append(_rec("Exudyn", "fast", 0.01, 1e-6, element="GE"))
    s = peers.summary(recs, "p")
    assert s["target"] == 1e-6 and not s["beamfx_ahead"]


def test_verdict_on_whole_runs_with_the_solve_only_verdict_beside_it():
    recs = [
        _rec("beamfx", "4 x P4", 0.01, 1e-7, whole_s=0.5),
        _rec("Exudyn", "8", 0.1, 1e-6, element="GE", whole_s=0.2),
    ]
    s = peers.summary(recs, "p")
    assert s["beamfx_time"] == 0.5 and s["beamfx_solve_time"] == 0.01
    assert not s["beamfx_ahead"] and s["beamfx_ahead_solve"]
    assert s["fastest_peer"] == ("Exudyn (GE)", 0.2)
    md = peers.markdown(recs, {"p": {"title": "fake", "beamfx_case": "c"}})
    assert "| **no** | yes (0.01 vs 0.1) |" in md
    assert "beamfx 0.5 s (4 x P4) against Exudyn (GE) 0.2 s: 2.5 x the time" in md


def test_the_why_line_states_the_measured_split_and_the_stack_floor():
    """Where beamfx is behind, the bullet names each measured part of its warm run, the rest
    (whole minus the parts), and the stack's costs measured alone with the floor they make:
    mesh + 5 spaces + forms + expression + solve + a frame per load step."""
    split = {"model": 0.004, "compile": 0.002, "condition": 0.0003, "output_probes": 0.003}
    split |= {"output_reactions": 0.001, "output_frames": 0.004, "total": 0.011, "run": 0.018}
    stack = {"mesh": 0.0002, "space": 0.0001, "forms": 0.002, "expression": 0.0015}
    fx = _rec("beamfx", "4 x P1", 0.001, 1e-15, whole_s=0.02, whole_split=split)
    fx |= {"stack_s": stack | {"frame": 0.0005}, "load_steps": 4}
    recs = [fx, _rec("Exudyn", "2", 0.004, 1e-12, element="GE", whole_s=0.005)]
    md = peers.markdown(recs, {"p": {"title": "fake", "beamfx_case": "c"}})
    line = next(x for x in md.splitlines() if x.startswith("- **p**"))
    assert "model build (mesh, function spaces, UFL forms, frame writers) 0.004" in line
    assert "solve 0.001, condition estimate 0.0003" in line
    assert "frames (VTK files) 0.004, the rest (load stepping, folder, log, results.json) " in line
    rest = 0.02 - (0.004 + 0.002 + 0.001 + 0.0003 + 0.003 + 0.001 + 0.004)
    assert f"results.json) {rest:.3g}." in line
    floor = 0.0002 + 5 * 0.0001 + 0.002 + 0.0015 + 0.001 + 4 * 0.0005
    assert "one frame 0.0005 (x 4 load steps)" in line and f"floor of {floor:.3g} s" in line
    fx.pop("whole_split"), fx.pop("stack_s")  # an older record: solve and rest only
    md = peers.markdown(recs, {"p": {"title": "fake", "beamfx_case": "c"}})
    assert "0.001 s is the solve and 0.019 s the rest" in md


def test_peer_files_give_whole_and_process_times(tmp_path):
    """A peer file's import time + a record's first run = its process time; an older file's
    whole run is its model build + warm solve."""
    recs = [
        _rec("Exudyn", "8", 0.1, 1e-3, first_s=0.4),
        {"problem": "p", "code": "Exudyn", "setting": "4", "wall_s": 0.1, "setup_s": 0.05},
    ]
    meta = {"import_s": 1.5}
    (tmp_path / "exudyn.json").write_text(json.dumps({"meta": meta, "records": recs}))
    (tmp_path / "frame_compare.json").write_text("[]")  # not a peer file of this report
    got = peers.load_peer_records(tmp_path)
    assert len(got) == 2 and abs(got[0]["process_s"] - 1.9) < 1e-12
    assert abs(got[1]["whole_s"] - 0.15) < 1e-12 and "process_s" not in got[1]


def test_markdown_and_plot(tmp_path):
    recs = [
        _rec("beamfx", "4 x P4", 0.05, 1e-7),
        _rec("Exudyn", "8", 0.1, 1e-3, element="GE"),
        _rec("PyElastica", "—", None, None, note="cannot: no eigen solver"),
    ]
    md = peers.markdown(recs, {"p": {"title": "fake", "beamfx_case": "c"}}, {"p": "a note"})
    assert "| p | 1.0e-03 |" in md and "cannot: no eigen solver" in md and "a note" in md
    peers.plot(recs, "p", "fake", tmp_path / "p.png", 1e-3)
    assert (tmp_path / "p.png").stat().st_size > 1000


def test_merge_reads_peer_files_without_running_beamfx(tmp_path):
    problems = {"p": {"title": "fake", "beamfx_case": "c", "error_scale": None}}
    (tmp_path / "problems.json").write_text(json.dumps(problems))
    fx = [_rec("beamfx", "4 x P4", 0.05, None, values={"x": 1.0 + 1e-8})]
    (tmp_path / "beamfx.json").write_text(
        json.dumps({"references": {"p": {"x": 1.0}}, "records": fx})
    )
    peer = [_rec("Exudyn", "8", 0.1, None, element="GE", values={"x": 1.01})]
    (tmp_path / "exudyn.json").write_text(json.dumps({"records": peer}))
    recs = peers.merge(tmp_path, tmp_path / "out", run=False, log=None)
    assert abs(recs[1]["error"] - 1e-2) < 1e-12
    assert (tmp_path / "out" / "peers.md").exists() and (tmp_path / "out" / "peers_p.png").exists()


def test_every_bench_formulation_has_an_element_name():
    """The peers' element column names each model a bench row can report (the mixed form
    included), so a model choice never breaks `make bench-peers`."""
    from beamfx.bench.peers import ELEMENTS, element_name

    for kind in ELEMENTS:
        assert element_name(kind) == ELEMENTS[kind]
    assert element_name("full mixed").endswith("mixed (section force unknowns)")
    assert element_name("planar mixed").startswith(ELEMENTS["planar"])


def test_stack_costs_of_a_rollup_setting():
    """The stack's parts of a P1 roll-up, each timed alone: all measured, each below the
    whole run it is part of (a generous bound: seconds on a loaded machine)."""
    from beamfx.bench import all_cases
    from beamfx.bench.peers_stack import stack_costs

    costs = stack_costs(all_cases()["rollup_0.5"], (1, 1), repeats=1)
    assert set(costs) == {"mesh", "space", "forms", "expression", "frame"}
    assert all(0 < v < 5.0 for v in costs.values())


def test_curves_compare_every_step_of_either_over_the_errors_both_reach():
    """beamfx's error-against-whole-time curve against a peer's (peers_score.curves): behind
    where the peer reaches an error sooner, from the larger best error up, and the report says
    at which errors and by how much."""
    from beamfx.bench.peers_score import curves

    recs = [
        _rec("beamfx", "coarse", 0.5, 1e-2),
        _rec("beamfx", "fine", 1.0, 1e-6),
        _rec("Exudyn", "8", 0.2, 5e-3, element="GE"),  # sooner than beamfx's 0.5 at 5e-3
        _rec("Exudyn", "64", 2.0, 1e-4, element="GE"),  # later than beamfx's 1.0 at 1e-4
        _rec("Exudyn", "512", 9.0, 1e-7, element="GE"),  # beyond beamfx's best error: not compared
    ]
    c = curves(recs, "p")["Exudyn (GE)"]
    assert c["from"] == 1e-6
    # 5e-3: beamfx needs its fine run (1.0 s); 1e-2: its coarse run (0.5 s), still later
    assert c["behind"] == [(5e-3, 1.0, 0.2), (1e-2, 0.5, 0.2)]
    assert c["floor"]["setting"] == "coarse"
    recs[2]["whole_s"] = 1.5  # now beamfx's fine run is sooner at 5e-3 as well
    assert curves(recs, "p")["Exudyn (GE)"]["behind"] == []
    recs[2]["whole_s"] = 0.2
    md = peers.markdown(recs, {"p": {"title": "fake", "beamfx_case": "c"}})
    assert "beamfx behind at 2 of the steps, errors 5.0e-03 to 1.0e-02; at most 5 x" in md
