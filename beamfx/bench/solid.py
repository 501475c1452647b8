"""Beam against the 3D solid of the same geometry: a comparison table, not a bench case.

The solids take minutes, too slow for the full ``beamfx bench``; run
``python -m beamfx.bench.solid [case ...] --report DIR`` (writes solid.json and solid.md).
Each case solves the solid at 2–3 mesh levels (cells across the section) and the beam once,
converged, and reports both beside the elementary theory.
"""

import json
import sys
import time
from pathlib import Path

from ..physics import sections
from ..physics.kinematics import Kinematics
from ..solid.geometry import SolidMesh
from ..spec import Beam, Model
from . import howcroft_2016 as hc
from . import schwab_meijaard_2009 as sm
from . import schwab_meijaard_eigen as se
from ._builders import arc, cantilever, straight

LINEAR = Kinematics(finite=False, shear=True)


def make_solid(beam, E, nu, rho, loads, material, cells, cell, clamped=("start",), **kw):
    """(the Solid, its start time) of a case: ``cells`` across the section, keywords
    ``layers`` and ``solver`` as in SolidMesh and SolidSpec."""
    from ..solid.solve import Solid, SolidSpec

    t0 = time.perf_counter()
    mesh = SolidMesh(cells, kw.get("layers"), cell)
    spec = SolidSpec(
        beam, E, nu, rho, clamped, loads, material, mesh, solver=kw.get("solver", "auto")
    )
    solid = Solid(spec)
    return solid, t0


def _beam_tip(model_spec, steps=1):
    from ..analyses.model import BeamModel
    from ..analyses.static import solve_static
    from ..io.probes import evaluate_points

    t0 = time.perf_counter()
    model = BeamModel(model_spec, extra_points=["b:end"])
    r = solve_static(model, steps=steps, prefix="beamfx_solid_beam_")
    tip = evaluate_points(model, ["b:end"])["b:end"]
    cost = {
        "unknowns": model.unknowns(),
        "wall_s": time.perf_counter() - t0,
        "solve_s": r.seconds["total"] - r.seconds["compile"],
    }
    return tip, cost


def _static_levels(beam, E, nu, loads, material, levels, cell, pick, steps=1):
    rows = []
    for n in levels:
        solid, t0 = make_solid(beam, E, nu, 0.0, {"end": loads}, material, n, cell)
        report = solid.solve_static(steps=steps)
        tip = solid.face_values("end")
        rows.append(
            {
                "section_cells": n,
                "layers": solid.mesh_info["layers"],
                "unknowns": solid.unknowns(),
                **report,
                "wall_s": time.perf_counter() - t0,
                "values": pick(tip),
            }
        )
    return rows


def _pick21(t):
    return {
        "u_z": t["displacement"][2],
        "phi_y": t["rotation_vector"][1],
        "phi_x": t["rotation_vector"][0],
    }


def sm21_beam():
    """The Timoshenko beam of SM 2.1 (Saint-Venant torsion constant): tip values and cost."""
    S = sections.rectangle(sm.E, sm.G, sm.RHO, 0.02, 0.01, nu=sm.NU)
    spec = cantilever(straight(1.0), S, 2, 3, (0, 0, sm.F), (sm.MX, sm.MY, 0), kinematics=LINEAR)
    tip, cost = _beam_tip(spec)
    return _pick21(tip), cost


def sm21(levels=(2, 4, 6)):
    """SM 2.1 cantilever, F_z, M_y, M_x together (linear)."""
    beam = Beam("b", straight(1.0), sm.S21, 1, 3)
    beam_values, cost = sm21_beam()
    pick = _pick21
    rows = _static_levels(
        beam, sm.E, sm.NU, ((0, 0, sm.F), (sm.MX, sm.MY, 0)), "linear", levels, "hexahedron", pick
    )
    return {
        "theory": sm.THEORY_21,
        "beam": beam_values,
        "beam_cost": cost,
        "solid": rows,
        "note": "theory: Euler-Bernoulli with the paper's thin-strip S_t; beam: Timoshenko "
        "(Cowper k) with the Saint-Venant torsion constant.",
    }


def sm22(levels=(2, 4, 6)):
    """SM 2.2 quarter circle, circular section, tip F_z and M_x (two solves each)."""
    beam = Beam("b", arc(sm.P22["geometry"]), sm.S22, 8, 3)
    pick = lambda t: {
        "u_z": t["displacement"][2],
        "phi_x": t["rotation_vector"][0],
        "phi_y": t["rotation_vector"][1],
    }
    out = {}
    for name, force, moment in (("F_z", (0, 0, 1e4), (0, 0, 0)), ("M_x", (0, 0, 0), (1e4, 0, 0))):
        spec = cantilever(arc(sm.P22["geometry"]), sm.S22, 8, 3, force, moment, kinematics=LINEAR)
        tip, cost = _beam_tip(spec)
        rows = _static_levels(
            beam, sm.E, sm.NU, (force, moment), "linear", levels, "tetrahedron", pick
        )
        out[name] = {
            "theory": sm._theory_22(**({"F": 1e4} if name == "F_z" else {"M": 1e4})),
            "beam": pick(tip),
            "beam_cost": cost,
            "solid": rows,
        }
    return out


def bend45(levels=(2, 3, 4)):
    """The 45° bend, vertical tip load 600, neo-Hookean solid (nu = 0) vs the finite beam."""
    beam = Beam("b", arc(hc.V["geometry"]), hc.SECTION, 16, 4)
    tip, cost = _beam_tip(cantilever(arc(hc.V["geometry"]), hc.SECTION, 16, 4, (0, 0, hc.F)), 10)
    pick = lambda t: dict(zip("xyz", t["position"]))
    rows = _static_levels(
        beam,
        hc.E,
        0.0,
        ((0, 0, hc.F), (0, 0, 0)),
        "neo-hookean",
        levels,
        "hexahedron",
        pick,
        steps=10,
    )
    return {
        "beam": pick(tip),
        "beam_cost": cost,
        "solid": rows,
        "published_spread": hc.V["reference_tip_position"],
    }


def sm28(levels=(2, 4, 6)):
    """SM 2.8 free-free frequencies: solid vs Timoshenko beam vs Euler-Bernoulli theory."""
    from ..analyses.model import BeamModel
    from ..solid.solve import Solid, SolidSpec

    T = se.THEORY_28
    kinds = {"omega_L": "axial", "omega_T": "torsion", "omega_B1": "bending", "omega_B2": "bending"}
    beam_model = BeamModel(Model(beams=(Beam("b", straight(1.0), se.S28, 16, 3),)))
    from ..analyses.modal import solve_modes

    beam = {
        k: float(solve_modes(beam_model, 1, target=T[k] ** 2, prefix="beamfx_solid_bm_").omega[0])
        for k in T
    }
    rows = []
    for n in levels:
        t0 = time.perf_counter()
        spec = SolidSpec(
            Beam("b", straight(1.0), se.S28, 1),
            se.E,
            se.NU,
            se.RHO,
            (),
            {},
            mesh=SolidMesh(n, None, "hexahedron"),
        )
        solid = Solid(spec)
        w = solid.modes({k: (kinds[k], T[k]) for k in T})
        rows.append(
            {
                "section_cells": n,
                "layers": solid.mesh_info["layers"],
                "unknowns": solid.unknowns(),
                "wall_s": time.perf_counter() - t0,
                "values": {k: float(v) for k, v in w.items()},
            }
        )
    return {"theory": T, "beam": beam, "solid": rows}


CASES = {"sm21": sm21, "sm22": sm22, "bend45": bend45, "sm28": sm28}


def main(argv=None):
    """Command line: run the chosen cases (default all) and write the report (``--report DIR``)."""
    from mpi4py import MPI

    argv = list(sys.argv[1:] if argv is None else argv)
    report = (
        Path(argv.pop(argv.index("--report") + 1)) if "--report" in argv else Path("results/solid")
    )
    argv = [a for a in argv if a != "--report"]
    names = argv or list(CASES)
    out = {}
    for name in names:
        out[name] = CASES[name]()
        if MPI.COMM_WORLD.rank == 0:
            print(json.dumps({name: out[name]}, indent=1, default=float), flush=True)
    if MPI.COMM_WORLD.rank == 0:
        report.mkdir(parents=True, exist_ok=True)
        tag = "_".join(names)
        (report / f"solid_{tag}.json").write_text(json.dumps(out, indent=1, default=float))


if __name__ == "__main__":
    main()
