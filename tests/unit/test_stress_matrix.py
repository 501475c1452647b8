"""The stress matrix's verdicts and report (beamfx.bench.stress_matrix), without a solve."""

from types import SimpleNamespace

import numpy as np

from beamfx.bench import stress_matrix as sm


def rows(values, ok=None):
    ok = ok or [True] * len(values)
    return [
        {
            "factor": f,
            "ok": k,
            "values": {"a": v} if k else None,
            "path": "scene" if k else "",
            "kappa": None,
            "seconds": 0.1,
            "cause": None if k else "divergence",
        }
        for f, v, k in zip(sm.FACTORS, values, ok)
    ]


def case(case_id, settings=((1, 2),), scale=None):
    return SimpleNamespace(id=case_id, settings=settings, scale=scale)


def test_an_independent_case_passes_only_below_the_tolerance():
    still = rows([1.0, 1 + 1e-9, 1 + 3e-9, 1 + 2e-9, 1 + 1e-9])
    assert sm.verdict(case("rollup_1"), still)[0]
    drifting = rows([1.0, 1 + 1e-9, 1 + 3e-6, 1, 1])
    ok, what = sm.verdict(case("rollup_1"), drifting)
    assert not ok and "3.0e-06" in what


def test_a_dependent_case_needs_a_falling_trend():
    converging = rows([1.0, 1.01, 1.0101, 1.010101, 1.01010101])  # P/GA: 1e-2, 1e-4, ...
    ok, what = sm.verdict(case("sm22_F_z"), converging)
    assert ok and "(converges, each value)" in what
    growing = rows([1.0, 1 + 2e-6, 1 + 1e-4, 1.04, 2.0])  # round-off growing with the ratio
    ok, what = sm.verdict(case("sm25_euler_buckling"), growing)
    assert not ok and "does not fall" in what


def test_a_value_tending_to_zero_is_judged_against_its_own_size():
    """The coupled cantilever's axial tip displacement falls like 1/sqrt(factor): relative to
    the vanishing value each move stays near 0.9 (it never fell); against the largest
    |value| over the factors the moves fall by 10 per factor 100, a converged trend."""
    to_zero = rows([-1.06e-3, -1.31e-4, -1.34e-5, -1.34e-6, -1.34e-7])
    ok, what = sm.verdict(case("coupled_cantilever"), to_zero)
    assert ok and what.startswith("trend 9e-01 → 1e-01 → 1e-02 → 1e-03")
    assert sm.scales(case("c"), to_zero) == {"a": 1.06e-3}
    assert sm.scales(case("c", scale=10.0), to_zero) == 10.0  # the case's own scale wins
    # round-off of a quantity that is ~0 counts against the largest size it reached (against
    # the round-off itself, each move would be 1 or more)
    noise = rows([1e-3, 1e-15, -1e-15, 2e-15, 0.0])
    ok, what = sm.verdict(case("c"), noise)
    assert ok and what == "trend 1e+00 → 2e-12 → 3e-12 → 2e-12 (converges, each value)"


def test_a_trend_converges_by_its_last_moves():
    """Early moves may rise (terms of different powers of 1/factor cancel far from the
    limit); a converged trend ends with a move at most half of each of the two before, or
    below the tolerance. A plateau of noise and growing round-off do not converge."""
    assert sm.falls([2e-2, 6e-6, 2e-5, 2e-6])  # the coupled cantilever's uz
    assert sm.falls([1e-3, 7e-4, 3e-5, 3e-7])  # bd_static_twisted ux, 4xP3
    assert sm.falls([5e-3, 1e-3, 2e-3, 1e-7])  # last move below the tolerance
    assert not sm.falls([3e-4, 4e-5, 1e-6, 1.2e-6])  # a plateau above the tolerance
    assert not sm.falls([1e-8, 8e-7, 3e-3, 2e-1])  # round-off growing with the factor
    assert not sm.falls([1e-2, 1e-4, 9e-6, 2e-3])  # falls, then grows again
    assert not sm.falls([1e-2, 1e-2, 6e-3, 4e-3])  # still moving: not half of the one before


def test_a_flag_that_turns_counts_as_a_move_of_one():
    assert sm.move({"steady": 1.0}, {"steady": 0.0}) == 1.0
    assert sm.move({"steady": 0.0}, {"steady": 0.0}) == 0.0


def test_a_failed_factor_fails_the_setting_and_its_cause_is_shown():
    failed = rows([1.0, 1.0, 1.0, 1.0, None], ok=[True, True, True, True, False])
    ok, what = sm.verdict(case("sm21_shear_rigid"), failed)
    assert not ok and what == "fails at x1e+08"
    lines = sm.table_rows(case("sm21_shear_rigid"), (1, 2), failed)
    assert lines[-1].startswith("| sm21_shear_rigid | 1×P2 | 1e+08 | NO |")
    assert lines[-1].endswith("| divergence |")


def test_one_setting_per_degree_the_middle_one():
    settings = ((1, 2), (2, 2), (4, 2), (1, 3), (2, 3), (4, 4))
    assert sm.settings_by_degree(case("c", settings)) == [(2, 2), (2, 3), (4, 4)]
    assert sm.settings_by_degree(case("c", ((4, 1), (8, 1), (16, 1)))) == [(8, 1)]


def test_the_cause_is_read_from_beamfx_messages():
    message = "x: failed: Newton failed at step 1; cause: floor above the force scale (|F| ..."
    assert sm._cause(message) == "floor above the force scale"
    assert sm._cause("cause: eigen solve; remedy: ...") == "eigen solve"


def test_the_hand_written_findings_are_kept(tmp_path):
    report = tmp_path / "report.md"
    report.write_text("# old tables\n\n| a |\n\n## Findings\n\nEuler: round-off.\n")
    kept = sm.findings_of(report)
    assert kept == "## Findings\n\nEuler: round-off.\n"
    text = sm.markdown([(case("rollup_1"), (4, 4), rows([1.0] * 5))], kept)
    assert text.endswith(kept) and "| rollup_1 | 4×P4 | yes |" in text
    assert sm.findings_of(tmp_path / "none.md") == ""


def test_the_saved_runs_render_the_same_report(tmp_path, monkeypatch):
    from beamfx.bench import all_cases

    monkeypatch.setattr(sm, "OUT", tmp_path / "stress_matrix.md")
    results = [(all_cases()["rollup_1"], (8, 4), rows([1.0, 1.0, 1.0 + 2e-5, 1.0, 1.0]))]
    sm.save(results, sm.OUT.with_suffix(".json"))
    sm.OUT.write_text("old\n\n## Findings\n\nkept\n")
    sm.render()
    text = sm.OUT.read_text()
    assert text == sm.markdown(results, "## Findings\n\nkept\n")
    # its scale is 10: the move 2e-5 counts as 2e-6
    assert "| rollup_1 | 8×P4 | NO | moves 2.0e-06 (independent of EA, GA) |" in text


def test_a_rerun_replaces_its_cases_rows_in_place():
    a, b, c = case("a"), case("b"), case("c")
    saved = [(a, (1, 2), "old a2"), (a, (1, 3), "old a3"), (b, (1, 2), "old b")]
    new = [(a, (2, 3), "new a"), (c, (1, 2), "new c")]
    assert sm.merge(saved, new) == [
        (a, (2, 3), "new a"),
        (b, (1, 2), "old b"),
        (c, (1, 2), "new c"),
    ]


def test_the_factor_reaches_matrix_sections_as_a_congruence():
    """A 6x6 section under the matrix's factor: force block times f, coupling times sqrt f,
    moment block unchanged (so a coupled section stays positive definite)."""
    from beamfx.bench.stress_matrix import stiffened
    from beamfx.physics.matrix_sections import MatrixSection

    rng = np.random.default_rng(1)
    A = rng.normal(size=(6, 6))
    C = A @ A.T + 6 * np.eye(6)
    section = MatrixSection(np.array([C]), np.array([np.eye(6)]), (0.0,), 1.0, False)
    base, _ = section.matrices_at([0.5])
    with stiffened(100.0):
        scaled, _ = section.matrices_at([0.5])
    assert np.allclose(scaled[0][:3, :3], 100 * base[0][:3, :3])
    assert np.allclose(scaled[0][:3, 3:], 10 * base[0][:3, 3:])
    assert np.allclose(scaled[0][3:, 3:], base[0][3:, 3:])
    assert np.all(np.linalg.eigvalsh(scaled[0]) > 0)
