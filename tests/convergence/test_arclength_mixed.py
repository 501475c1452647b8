"""Arc length in the mixed (Hellinger–Reissner) formulation (issue 16): Howcroft's shallow
arch (``beamfx/scenes/shallow_arch_snap.toml``, 4 × P3, planar) with EA and GA multiplied as
the stress matrix does (:func:`beamfx.bench.stress_matrix.stiffened`).

* Same discrete equations: with an elastic section and the planar model (no quaternion
  penalty) the mixed form's stationary points are the displacement form's (its force is
  C_N Γ at the reduced points), so both trace the same path: every critical point has the
  same kind and inertia (the mixed count less its force unknowns,
  :func:`beamfx.solvers.arclength.inertia_offset`), and the same load factor within the
  brackets the inertia puts each in, plus the displacement form's precision κ·eps.
* The stiff trend: the antisymmetric bifurcation of the arch tends to that of the
  inextensible, shear-rigid arch (the mixed form's exact constraints, compliance 0) as
  1/factor (the membrane shortening q R/EA before it). From the ×1e2 move, the ×1e6 move is
  1e-4 of it; the next term, O(1/factor²), is bounded by 5 % of the first at ×1e2 (measured
  7e-4: the ×1e2 and ×1e4 moves are 2.5659e-3 and 2.5642e-5).
"""

import math

import pytest

from beamfx.bench.shallow_arch import Q_SNAP, E, I, R, S

EPS = 2.220446049250313e-16

N, P = 4, 3
#: the next-order term's share of the 1/factor move at ×1e2 (module doc)
SECOND_ORDER = 0.05


def trace(tmp_path, name, factor, formulation="auto", **analysis):
    """results of the arch scene ``name`` (4 × P3) at 5500 N/m, EA and GA × ``factor``."""
    from beamfx.bench.shallow_arch import scene_data
    from beamfx.bench.stress_matrix import stiffened
    from beamfx.runner import run_scene
    from beamfx.scene.load import parse_scene

    data = scene_data(name, N, P)
    data.setdefault("model", {})["formulation"] = formulation
    data["loads"][0]["force_per_length"] = [0.0, -Q_SNAP, 0.0]
    data["analysis"].pop("branch", None)  # stay on the primary path
    data["analysis"].update(analysis)
    out = tmp_path / f"{name}-{factor:g}-{formulation}"
    with stiffened(factor):  # parsed there: "auto" sees the stiffened sections
        scene = parse_scene(data, f"{name}.toml")
        run = run_scene(scene.file, out, log=lambda *a, **k: None, scene=scene)
    return run


def _first(result, kind):
    return next(c for c in result.critical_points if c["kind"] == kind)


def _width(point):
    lo, hi = point["load_factor_bracket"] or (0.0, 0.0)
    return abs(hi - lo)


def test_mixed_and_displacement_forms_trace_the_same_critical_points(tmp_path):
    """×1e2: the same critical points, inertia and located loads in both forms."""
    runs = [trace(tmp_path, "shallow_arch_snap", 1e2, f) for f in ("mixed", "displacement")]
    assert [r.model["formulation"]["name"] for r in runs] == ["mixed", "displacement"]
    mixed, disp = (r.result for r in runs)
    assert mixed.status == disp.status == "converged"
    assert mixed.path[0]["negative_eigenvalues"] == 0  # the start: the mixed count less n_f

    def signature(result):
        return [(c["kind"], *c["negative_eigenvalues"]) for c in result.critical_points]

    assert signature(mixed) == signature(disp)
    assert [k for k, *_ in signature(mixed)][:2] == ["bifurcation", "limit"]
    # the displacement form's states are exact to about κ·eps, κ ~ 10 ρ (ρ = EA·L²/EI, the
    # 10 for the mesh's constants); the mixed form's to round-off
    rho = 12 * S**2 * 1e2  # unit square section: EA L²/EI = 12 L²
    pairs = list(zip(mixed.critical_points, disp.critical_points))
    assert all(a["load_factor"] and b["load_factor"] for a, b in pairs[:2])  # located
    for a, b in pairs:
        if a["load_factor"] is None or b["load_factor"] is None:
            continue  # not located (stagnation near a bifurcation): the inertia agrees
        precision = 10 * rho * EPS * abs(a["load_factor"])
        assert abs(a["load_factor"] - b["load_factor"]) <= _width(a) + _width(b) + precision


def test_stiff_arch_traced_in_mixed_form_follows_the_trend(tmp_path):
    """×1e6 ("auto": mixed, stiffness ratio 3e9): the trace passes the bifurcation and the
    limit point and snaps through to the displacement limit; its bifurcation load is the
    inextensible arch's less 1e-4 of the ×1e2 move (1/factor)."""
    rigid = trace(tmp_path, "shallow_arch_bifurcation", 1.0, max_steps=12).result
    soft = trace(tmp_path, "shallow_arch_snap", 1e2).result
    stiff_run = trace(tmp_path, "shallow_arch_snap", 1e6)
    stiff = stiff_run.result
    assert stiff_run.model["formulation"]["name"] == "mixed"
    assert stiff.status == "converged" and stiff.stopped_by == "displacement_limit"
    limit = _first(stiff, "limit")
    exact = _first(rigid, "bifurcation")["load_factor"]  # exact constraints: factor ∞
    move_2 = exact - _first(soft, "bifurcation")["load_factor"]
    move_6 = exact - _first(stiff, "bifurcation")["load_factor"]
    expected = 1e-4 * move_2
    tolerance = SECOND_ORDER * abs(expected) + _width(_first(stiff, "bifurcation"))
    assert move_6 == pytest.approx(expected, abs=tolerance)
    # the limit point: after the bifurcation, its load located (inertia 1 -> 2), below the
    # thrust of the second symmetric mode 9π²EI/S² over R (shallow-arch theory, 1 %)
    assert limit["negative_eigenvalues"] == [1, 2]
    assert limit["load_factor"] > _first(stiff, "bifurcation")["load_factor"]
    assert limit["load_factor"] <= 1.01 * 9 * math.pi**2 * E * I / S**2 / R / Q_SNAP
    top = next(p for p in stiff.limit_points if p["kind"] == "maximum")
    assert top["load_factor"] == limit["load_factor"]


if __name__ == "__main__":  # pragma: no cover
    pytest.main([__file__, "-q"])
