"""The roll-up solved by the planar model and by the full 3D model: the same answer with
3 instead of 7 unknowns per node (the trimming of :mod:`beamfx.analyses.trimming`).

The tip moment 2π EI/L closes the beam into a circle (exact: the tip returns to the clamp).
Quaternion and angle fields interpolate a plane rotation differently, so the two models agree
to the discretisation error, not to round-off.
"""

import time
from dataclasses import dataclass, replace

import numpy as np

from ..physics.kinematics import Kinematics
from .classic import L, _position, _rollup
from .registry import Case, register


def _solve(spec, steps):
    """(tip position, unknowns, Newton its, cold s, warm s) of one model."""
    from ..analyses.model import BeamModel
    from ..analyses.static import solve_static
    from ..io.probes import evaluate_points
    from ..solvers import NewtonSolver

    t0 = time.perf_counter()
    model = BeamModel(spec, extra_points=["b:end"])
    solver = NewtonSolver(model.F, model.J, model.w, model.bcs, "beamfx_bench_planar_")
    result = solve_static(model, steps=steps, solver=solver)
    cold = time.perf_counter() - t0
    x = np.array(evaluate_points(model, ["b:end"])["b:end"]["position"])
    model.reset()
    t1 = time.perf_counter()
    solve_static(model, steps=steps, solver=solver)
    warm = time.perf_counter() - t1
    solver.destroy()
    return x, model.unknowns(), result.newton_iterations, cold, warm


@dataclass(frozen=True)
class PlanarCase(Case):
    """The roll-up solved with the planar and the full 3D model at each setting."""

    def run_setting(self, elements, degree):
        """One row of the table: the planar model's values and costs beside the full model's."""
        spec, steps = self.build(elements, degree)
        planar = replace(spec, kinematics=Kinematics(plane="xz"))
        xp, n_p, its, cold, warm = _solve(planar, steps)
        xf, n_f, its_f, cold_f, warm_f = _solve(spec, steps)
        return {
            "elements": elements,
            "degree": degree,
            "unknowns": n_p,
            "newton_iterations": its,
            "load_steps": steps,
            "wall_s_cold": cold,
            "wall_s_warm": warm,
            "values": _position({"tip": {"position": xp.tolist()}}),
            "full_model": {
                "unknowns": n_f,
                "newton_iterations": its_f,
                "wall_s_cold": cold_f,
                "wall_s_warm": warm_f,
                "difference": float(np.linalg.norm(xp - xf)),
            },
        }


def planar_lines(r):
    """Report lines: planar beside full model (nothing for other cases)."""
    rows = [row for row in r["rows"] if "full_model" in row]
    if not rows:
        return []
    out = [
        "",
        (
            "| setting | unknowns planar / full | Newton its planar / full | cold s planar / full | "
            "warm s planar / full | tip difference / L |"
        ),
        "|---|---|---|---|---|---|",
    ]
    for row in rows:
        f = row["full_model"]
        out.append(
            f"| {row['elements']} x P{row['degree']} | {row['unknowns']} / {f['unknowns']} | "
            f"{row['newton_iterations']} / {f['newton_iterations']} | {row['wall_s_cold']:.2f} / "
            f"{f['wall_s_cold']:.2f} | {row['wall_s_warm']:.3f} / {f['wall_s_warm']:.3f} | "
            f"{f['difference'] / L:.1e} |"
        )
    return out


_build, _exact = _rollup(1.0)
register(
    PlanarCase(
        "rollup_planar_vs_full",
        "Simo & Vu-Quoc 1986 (classic)",
        "Roll-up to a full circle, planar model beside the full 3D model",
        _build,
        _position,
        _exact,
        1e-6,
        ((4, 4), (8, 4), (16, 4)),
        scale=L,
        note="A planar case solved with 3/7 of the unknowns of the full model and the same "
        "answer (to the discretisation error); error relative to L, of the planar model.",
        own_model="it compares the planar model with the full one on purpose; the scene "
        "builder would pick the planar condensed model (as for the rollup_* cases)",
    )
)
