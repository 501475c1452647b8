"""Continuum-based (ANCF-style) beam against the Reissner beam and the 3D solid: one table.

``python -m beamfx.bench.continuum [sm21] [rollup] [sm28] --report DIR`` writes
DIR/continuum.json and DIR/continuum.md. Each case runs the Reissner beam (beamfx) and the
continuum beam's variants (:data:`beamfx.continuum.model.VARIANTS`) at a few meshes and quotes
the solid from docs/solid.md (not rerun: minutes each). Every row has its unknowns, wall time
without JIT compilation, value and relative error against the case's reference:

* sm21 (SM 2.1, linear cantilever 1 m × 20 × 10 mm, F_z = M_y = M_x = 1e4): Timoshenko theory
  (Cowper k) for u_z and φ_y, Saint-Venant torsion for φ_x (the Reissner beam's model; the
  solid agrees to 6e-6 in bending and is 7.8e-4 stiffer in torsion, the clamp's warping).
* rollup (full circle, M = 2πEI/L about −y, L = 1 m, square 1 mm, 8 load steps): the exact
  circle, i.e. the tip back at the start; error = distance / L. The continuum model's own
  uniform-bending state (:func:`uniform_bending`) misses it by O((κh)²), a row of its own.
* sm28 (SM 2.8, free-free 1 m × 20 × 20 mm): the solid's finest level in docs/solid.md.
"""

import json
import sys
import time
from pathlib import Path

import numpy as np

from ..continuum import model as cm
from ..physics import sections
from ..physics.kinematics import Kinematics
from . import schwab_meijaard_2009 as sm
from . import schwab_meijaard_eigen as se
from ._builders import cantilever, straight

VARIANTS = cm.VARIANTS
G = sm.E / (2 * (1 + sm.NU))
LINEAR = Kinematics(finite=False, shear=True)

# --- the solid, quoted from docs/solid.md (hexahedral P2, levels = cells across the section) ---
SOLID = {
    "sm21": [
        {"level": 4, "unknowns": 46_359, "wall_s": 49.0, "u_z": -1.189766, "phi_y": 3.571416,
         "phi_x": 27.024, "note": "MUMPS"},
        {"level": 7, "unknowns": 230_985, "wall_s": 350.0, "u_z": -1.189755, "phi_y": 3.571420,
         "phi_x": 27.049, "note": "CG+GAMG, 1 rank"},
    ],
    "sm28": [
        {"level": 4, "unknowns": 12_393, "wall_s": None, "omega_L": 16248.45, "omega_T": 9260.28,
         "omega_B1": 667.271, "omega_B2": 1835.44},
        {"level": 6, "unknowns": 39_039, "wall_s": None, "omega_L": 16248.45, "omega_T": 9256.09,
         "omega_B1": 667.173, "omega_B2": 1834.427},
    ],
}  # fmt: skip

# --- roll-up: a slender square bar, so that the SVK model's own miss (∝ (h/L)²) is small ---
ROLL = {"L": 1.0, "h": 1e-3, "w": 1e-3, "steps": 8}


def _clock():
    """(wall, JIT) seconds so far: rows report wall time without form compilation."""
    from ..solvers.forms import compile_seconds

    return time.perf_counter(), compile_seconds[0]


def _since(start):
    t, c = _clock()
    return (t - start[0]) - (c - start[1])


def _row(case, quantity, model, mesh, unknowns, wall, value, ref, its=None, note=""):
    err = None if value is None or ref is None else abs(value - ref) / abs(ref)
    return {
        "case": case,
        "quantity": quantity,
        "model": model,
        "mesh": mesh,
        "unknowns": unknowns,
        "wall_s": wall,
        "newton_iterations": its,
        "value": value,
        "reference": ref,
        "error": err,
        "note": note,
    }


def _beam_tip(model_spec, steps=1):
    """Tip values of a Reissner beam model (beamfx) and its unknowns and Newton iterations."""
    from ..analyses.model import BeamModel
    from ..analyses.static import solve_static
    from ..io.probes import evaluate_points

    model = BeamModel(model_spec, extra_points=["b:end"])
    r = solve_static(model, steps=steps, prefix="beamfx_ct_beam_")
    tip = evaluate_points(model, ["b:end"])["b:end"]
    return tip, model.unknowns(), r.newton_iterations


def _continuum(variant, n, p, **kw):
    from ..continuum.solve import ContinuumBeam, ContinuumSpec

    spec = ContinuumSpec(sm.E, sm.NU, sm.RHO, elements=n, degree=p, variant=variant, **kw)
    return ContinuumBeam(spec)


# --- SM 2.1 -------------------------------------------------------------------------------------


def sm21(settings=((1, 2), (2, 3))):
    """Linear cantilever; the continuum beam with all three loads (torsion without warping)."""
    h, w = 0.02, 0.01
    S = sections.rectangle(sm.E, G, sm.RHO, h, w, nu=sm.NU)  # Saint-Venant torsion
    ref = {
        "u_z": sm.THEORY_21["u_z"] + sm.F * sm.L / S.GA_z,
        "phi_y": sm.THEORY_21["phi_y"],
        "phi_x": sm.MX * sm.L / S.GJ,
    }
    rows = []
    start = _clock()
    spec = cantilever(straight(1.0), S, 2, 3, (0, 0, sm.F), (sm.MX, sm.MY, 0), kinematics=LINEAR)
    tip, unknowns, _ = _beam_tip(spec)
    wall = _since(start)
    picks = {"u_z": tip["displacement"][2], "phi_y": tip["rotation_vector"][1]}
    picks["phi_x"] = tip["rotation_vector"][0]
    for q, v in picks.items():
        rows.append(_row("sm21", q, "Reissner beam", "2 × P3", unknowns, wall, v, ref[q]))
    for variant in VARIANTS:
        for n, p in settings:
            start = _clock()
            b = _continuum(variant, n, p, h=h, w=w, force=(0, 0, sm.F), moment=(sm.MX, sm.MY, 0))
            b.solve_static(linear=True)
            tip = b.end_values()
            wall = _since(start)
            picks = {"u_z": tip["displacement"][2], "phi_y": tip["rotation_vector"][1]}
            picks["phi_x"] = tip["rotation_vector"][0]
            for q, v in picks.items():
                note = "no warping: G I_p" if q == "phi_x" else ""
                model = f"continuum {variant}"
                rows.append(
                    _row("sm21", q, model, f"{n} × P{p}", b.unknowns(), wall, v, ref[q], note=note)
                )
    for lvl in SOLID["sm21"]:
        for q, r in ref.items():
            rows.append(
                _row("sm21", q, f"solid level {lvl['level']} (docs/solid.md)", "hex P2",
                     lvl["unknowns"], lvl["wall_s"], lvl[q], r, note=lvl["note"])
            )  # fmt: skip
    return {"reference": ref, "rows": rows}


# --- roll-up ------------------------------------------------------------------------------------


def uniform_bending(variant, E, nu, h, w, L, M):
    """The continuum model's exact pure-bending state (no discretisation).

    A uniform state r' = a t, d3 = b n, d2 = c e2 turning at κ per reference length has
    E_11 = ½((a − bκζ)² − 1), E_33 = ½(b² − 1), E_22 = ½(c² − 1), and is made stationary under
    the couple's work M κ: Newton on complex-step derivatives of the section energy of
    :mod:`beamfx.continuum.model`, evaluated with numpy. Returns (a, b, c, κ) and the tip
    position (x, z) of the clamped bar, a/κ (sin κL, 1 − cos κL).
    """

    def psi(x):
        a, b, c, k = x

        def strain_at(eta, zeta):
            return np.diag([((a - b * k * zeta) ** 2 - 1) / 2, (c**2 - 1) / 2, (b**2 - 1) / 2])

        axis, rest = cm.section_energy(variant, strain_at, E, nu, h, w)
        return axis + rest - M * k

    scale = np.array([1.0, 1.0, 1.0, 1.0 / L])

    def gradient(y):  # complex-step derivatives: exact to round-off (ψ is a polynomial)
        g = [psi((y + 1e-30j * e) * scale).imag / 1e-30 for e in np.eye(4)]
        return np.array(g) / (E * h * w)

    y = np.array([1.0, 1.0, 1.0, M * L / (E * w * h**3 / 12)])  # κL of linear bending
    for _ in range(50):  # Newton with a difference Jacobian of the exact gradient
        g = gradient(y)
        H = np.array([(gradient(y + 1e-7 * e) - gradient(y - 1e-7 * e)) / 2e-7 for e in np.eye(4)])
        step = np.linalg.solve(H.T, -g)
        y = y + step
        if np.max(np.abs(step)) < 1e-15:
            break
    a, b, c, k = y * scale
    return (a, b, c, k), np.array([a / k * np.sin(k * L), a / k * (1 - np.cos(k * L))])


def rollup(elements=(2, 4, 8)):
    """Full-circle roll-up: Reissner beam, the three variants (axis energy with the reduced
    rule) and the corrected variant with the full rule (membrane/shear locking)."""
    from ..solvers import SolveFailed

    L, h, w = ROLL["L"], ROLL["h"], ROLL["w"]
    EI = sm.E * w * h**3 / 12
    M = 2 * np.pi * EI / L
    S = sections.rectangle(sm.E, G, sm.RHO, h, w, nu=sm.NU)
    rows = []

    own = {v: uniform_bending(v, sm.E, sm.NU, h, w, L, M) for v in VARIANTS}

    def add(model, mesh, unknowns, wall, tip, its, note="", variant=None):
        miss = None if tip is None else float(np.linalg.norm(tip)) / L
        value = None if tip is None else f"x = {tip[0]:.3e}, z = {tip[1]:.3e}"
        row = _row("rollup", "tip miss / L", model, mesh, unknowns, wall, None, None, its, note)
        row.update(value=value, reference="start point", error=miss)
        row["tip_xz"] = None if tip is None else [float(t) for t in tip]
        if variant and tip is not None and mesh != "exact":
            row["error_vs_own_circle"] = float(np.linalg.norm(tip - own[variant][1])) / L
            row["note"] = f"vs the model's own circle {row['error_vs_own_circle']:.2g}"
        rows.append(row)

    for n in elements:
        start = _clock()
        try:
            spec = cantilever(straight(L), S, n, 3, moment=(0, -M, 0))
            tip, unknowns, its = _beam_tip(spec, ROLL["steps"])
            xz = np.array(tip["position"])[[0, 2]]
            add("Reissner beam", f"{n} × P3", unknowns, _since(start), xz, its)
        except SolveFailed as e:
            add("Reissner beam", f"{n} × P3", None, _since(start), None, None, _failure(e))
    runs = [(v, "reduced") for v in VARIANTS] + [("corrected", "full")]
    for variant, rule in runs:
        model = f"continuum {variant}" + (", full axis rule" if rule == "full" else "")
        for n in elements:
            start = _clock()
            b = _continuum(variant, n, 3, h=h, w=w, end=(L, 0, 0), moment=(0, -M, 0),
                           follower=True, axis_quadrature=rule)  # fmt: skip
            try:
                r = b.solve_static(steps=ROLL["steps"])
                x = np.array(b.end_values()["position"])[[0, 2]]
                its = r["newton_iterations"]
                add(model, f"{n} × P3", b.unknowns(), _since(start), x, its, variant=variant)
            except SolveFailed as e:
                add(model, f"{n} × P3", b.unknowns(), _since(start), None, None, _failure(e))
    limits = {}
    for variant, (state, tip) in own.items():
        limits[variant] = {"a_b_c_kappa": [float(x) for x in state], "tip_xz": tip.tolist()}
        if variant != "corrected":  # corrected = poisson_free in pure bending (no shear)
            add(f"continuum {variant}: uniform bending", "exact", None, None, tip, None,
                "the model's own circle, no discretisation")  # fmt: skip
    return {"L": L, "h": h, "w": w, "M": M, "model_limits": limits, "rows": rows}


def _failure(e):
    lam = e.history[-1].load_factor if e.history else 0.0
    return f"no convergence beyond load factor {lam:.3g}"


# --- SM 2.8 -------------------------------------------------------------------------------------

KINDS = {"omega_L": "axial", "omega_T": "torsion", "omega_B1": "bending", "omega_B2": "bending"}


def sm28(elements=(4, 8, 16)):
    """Free-free frequencies (ω, rad/s); each mode found by shift-and-invert at the theory value
    and classified by its kinetic energy (axial, torsion, bending, section)."""
    from ..analyses.modal import solve_modes
    from ..analyses.model import BeamModel
    from ..spec import Beam, Model

    T = se.THEORY_28
    ref = {k: SOLID["sm28"][-1][k] for k in T}
    rows = []
    for n in elements:
        start = _clock()
        model = BeamModel(Model(beams=(Beam("b", straight(1.0), se.S28, n, 3),)))
        omega = {
            k: float(solve_modes(model, 1, target=T[k] ** 2, prefix="beamfx_ct_bm_").omega[0])
            for k in T
        }
        wall = _since(start)
        for k in T:
            rows.append(
                _row("sm28", k, "Reissner beam", f"{n} × P3", model.unknowns(), wall, omega[k],
                     ref[k])
            )  # fmt: skip
    extras = {}
    for variant in VARIANTS:
        for n in elements:
            start = _clock()
            b = _continuum(variant, n, 3, h=0.02, w=0.02, clamped=False)
            omega, _ = b.modes({k: (KINDS[k], T[k]) for k in T})
            wall = _since(start)
            for k in T:
                note = "G I_p (no warping)" if k == "omega_T" else ""
                rows.append(
                    _row("sm28", k, f"continuum {variant}", f"{n} × P3", b.unknowns(), wall,
                         omega[k], ref[k], note=note)
                )  # fmt: skip
        extras[variant] = _lowest_section_mode(b)
    for lvl in SOLID["sm28"]:
        note = "the reference" if lvl is SOLID["sm28"][-1] else ""
        for k in T:
            rows.append(
                _row("sm28", k, f"solid level {lvl['level']} (docs/solid.md)", "hex P2",
                     lvl["unknowns"], lvl["wall_s"], lvl[k], ref[k], note=note)
            )  # fmt: skip
    return {"reference": ref, "rows": rows, "section_modes": extras}


def _lowest_section_mode(beam):
    """The section mode of the continuum beam nearest the uniform in-plane section shear
    ω_s² = 4 G A / (ρ I_p) (a mode the Reissner beam and the solid do not have as such)."""
    s = beam.spec
    A, I_y, I_z = cm.section_moments(s.h, s.w)
    estimate = np.sqrt(4 * (s.E / (2 * (1 + s.nu))) * A / (s.rho * (I_y + I_z)))
    omega, _ = beam.modes({"section": ("section", estimate)}, per_target=8)
    return {"estimate": float(estimate), "omega": float(omega["section"])}


# --- report -------------------------------------------------------------------------------------

CASES = {"sm21": sm21, "rollup": rollup, "sm28": sm28}
TITLES = {
    "sm21": "SM 2.1 cantilever (linear)",
    "rollup": "roll-up, full circle",
    "sm28": "SM 2.8 free-free",
}
QUANTITIES = {
    "u_z": "u_z [m]",
    "phi_y": "φ_y",
    "phi_x": "φ_x",
    "tip miss / L": "tip miss / L",
    "omega_L": "ω axial",
    "omega_T": "ω torsion",
    "omega_B1": "ω bending 1",
    "omega_B2": "ω bending 2",
}


def _fmt(x, digits=7):
    if x is None:
        return "—"
    if isinstance(x, str):
        return x
    if not np.isfinite(x):
        return "—"
    return f"{x:.{digits}g}"


def markdown(out):
    """One table over all cases (rows grouped by case and quantity)."""
    header = "| case | quantity | model | mesh | unknowns | wall [s] | Newton its | value | "
    lines = [header + "reference | error | note |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for case, result in out.items():
        if case not in CASES:
            continue
        rows = sorted(result["rows"], key=lambda r: list(QUANTITIES).index(r["quantity"]))
        for r in rows:
            value, err = r["value"], r["error"]
            lines.append(
                f"| {TITLES[case]} | {QUANTITIES[r['quantity']]} | {r['model']} | {r['mesh']} | "
                f"{_fmt(r['unknowns'])} | {_fmt(r['wall_s'], 2)} | "
                f"{_fmt(r['newton_iterations'])} | {_fmt(value)} | {_fmt(r['reference'])} | "
                f"{_fmt(err, 2)} | {r['note']} |"
            )
    return "\n".join(lines) + "\n"


def locking_summary(out):
    """The Poisson-locking factor predicted, (λ + 2μ)/E = (1 − ν)/((1 + ν)(1 − 2ν)), and as
    measured by the cases that ran: the stiffness ratio full/corrected from SM 2.1's φ_y, the
    squared ratio of SM 2.8's first bending frequencies (shear and rotary inertia blur it) and
    the roll-up's curvature ratio of the exact uniform states (finite strain blurs it)."""
    nu = sm.NU
    summary = {"predicted": (1 - nu) / ((1 + nu) * (1 - 2 * nu))}

    def value(case, quantity, model, mesh):
        for r in out[case]["rows"]:
            if (r["quantity"], r["model"], r["mesh"]) == (quantity, model, mesh):
                return r["value"]
        return None

    if "sm21" in out:
        full = value("sm21", "phi_y", "continuum full", "2 × P3")
        corrected = value("sm21", "phi_y", "continuum corrected", "2 × P3")
        summary["sm21_phi_y"] = corrected / full
    if "sm28" in out:
        full = value("sm28", "omega_B1", "continuum full", "16 × P3")
        corrected = value("sm28", "omega_B1", "continuum corrected", "16 × P3")
        summary["sm28_omega_B1_squared"] = (full / corrected) ** 2
    if "rollup" in out:
        limits = out["rollup"]["model_limits"]
        summary["rollup_kappa"] = (
            limits["corrected"]["a_b_c_kappa"][3] / (limits["full"]["a_b_c_kappa"][3])
        )
    return summary


def main(argv=None):
    """Command line: run the chosen cases (default all) and write the report (``--report DIR``)."""
    from mpi4py import MPI

    argv = list(sys.argv[1:] if argv is None else argv)
    report = Path("results/continuum")
    if "--report" in argv:
        i = argv.index("--report")
        report = Path(argv[i + 1])
        del argv[i : i + 2]
    names = argv or list(CASES)
    bad = [n for n in names if n not in CASES]
    if bad:
        raise SystemExit(f"unknown cases {bad}; allowed: {list(CASES)}")
    out = {name: CASES[name]() for name in names}
    out["locking_factor"] = locking_summary(out)
    if MPI.COMM_WORLD.rank == 0:
        report.mkdir(parents=True, exist_ok=True)
        (report / "continuum.json").write_text(json.dumps(out, indent=1, default=float))
        (report / "continuum.md").write_text(markdown(out))
        print(markdown(out), json.dumps(out["locking_factor"], indent=1), flush=True)


if __name__ == "__main__":
    main()
