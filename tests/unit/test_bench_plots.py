"""The validation report's plots from small fake results (no bench is run)."""

import builtins

import numpy as np
import pytest

from beamfx.bench import run as bench_run

pytest.importorskip("matplotlib")


def _row(n, p, error, dt=None):
    row = {
        "elements": n,
        "degree": p,
        "unknowns": 6 * (n * p + 1),
        "newton_iterations": 10,
        "load_steps": 10 if dt is None else round(1 / dt),
        "wall_s_cold": 1.0,
        "wall_s_warm": 0.01 * n * p,
        "jit_s": 0.0,
        "values": {"x": 1.0 + error, "phi": 0.5},
        "error": error,
    }
    if dt is not None:
        row["dt"] = dt
    return row


def _case(id, rows, **more):
    return {
        "id": id,
        "paper": "fake",
        "title": f"fake case {id}",
        "note": "",
        "reference": {"x": 1.0, "phi": 0.5},
        "reference_is_finest_setting": False,
        "tolerance": 1e-4,
        "error_scale": "relative",
        "rows": rows,
        "rates": [],
        "cheapest_within_tolerance": rows[-1] if rows[-1]["error"] <= 1e-4 else None,
        "passed": rows[-1]["error"] <= 1e-4,
        "extra": {},
        **more,
    }


def fake_results():
    static = [_row(n, p, 10.0 ** -(p * k)) for p in (2, 3) for k, n in enumerate((2, 4, 8), 1)]
    path = [{"load_factor": lam, "x": 1 - 0.1 * lam, "phi": 0.5 * lam} for lam in (0.25, 0.5, 1)]
    t = np.linspace(0, 2, 50)
    history = {"t (s)": t.tolist(), "axial (m)": np.sin(t).tolist(), "angle (rad)": t.tolist()}
    transient = [_row(4, 2, 10.0**-k, dt=0.1 / 2**k) for k in range(1, 4)]
    transient[-1]["error"] = 0.0  # the finest setting as the reference
    campbell = {
        "omega_By": 100.0,
        "omega_Bz": 1000.0,
        "alphas": [0, 0.1, 1, 10],
        "paper_flap": [1, 1.005, 1.47, 10.3],
        "paper_lead_lag": [1, 1.0, 1.001, 1.08],
    }
    rotating = [_row(n, 2, 10.0**-n) for n in (1, 2, 4)]
    for row in rotating:
        row["values"] = {
            f"{b} alpha={a:g}": v
            for a in (0, 0.1, 1, 10)
            for b, v in (("flap", a + 1), ("lead_lag", 1))
        }
    return [
        _case("static_path", static, path=path),
        _case("transient", transient, history=history, reference_is_finest_setting=True),
        _case("rotating", rotating, extra={"campbell": campbell}, reference=rotating[-1]["values"]),
        _case("plain", static[:3]),
    ]


def _not_blank(path):
    import matplotlib.image as mpimg

    pixels = mpimg.imread(path)[..., :3]
    assert pixels.shape[0] > 300 and pixels.shape[1] > 800
    assert np.mean(np.any(pixels < 0.9, axis=-1)) > 0.005  # lines and text on white
    assert pixels.std() > 0.05


def test_one_figure_per_case_and_a_summary_linked_from_the_report(tmp_path):
    results = fake_results()
    from beamfx.bench.plots import write_plots

    figures = write_plots(results, tmp_path)
    assert figures == {r["id"]: f"{r['id']}.png" for r in results} | {"summary": "summary.png"}
    for name in figures.values():
        _not_blank(tmp_path / name)
    widths = {r["id"]: _width(tmp_path / figures[r["id"]]) for r in results}
    assert widths["static_path"] > widths["plain"]  # the third panel: load-displacement
    assert widths["transient"] == widths["rotating"] == widths["static_path"]
    text = bench_run.markdown(results, figures)
    assert "![Error over tolerance against warm wall time, every case](summary.png)" in text
    section = text.split("## rotating:")[1]
    assert "![rotating: convergence and cost](rotating.png)" in section.split("## ")[0]


def _width(path):
    import matplotlib.image as mpimg

    return mpimg.imread(path).shape[1]


def test_without_matplotlib_the_report_says_so(tmp_path, monkeypatch):
    results = fake_results()
    monkeypatch.setattr(bench_run, "run_case", lambda case, log: results.pop(0))
    real_import = builtins.__import__

    def no_matplotlib(name, *args, **kwargs):
        if name.startswith("matplotlib"):
            raise ImportError(f"No module named {name!r}")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_matplotlib)
    bench_run.run_bench(["rollup_1"], tmp_path, log=None)
    text = (tmp_path / "README.md").read_text()
    assert "No plots: matplotlib is missing" in text
    assert not list(tmp_path.glob("*.png"))
    assert (tmp_path / "bench.json").is_file()
