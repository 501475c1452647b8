"""PyElastica (pypi `pyelastica`) on the static peer problems: writes DIR/pyelastica.json.

PyElastica integrates the dynamic Cosserat rod explicitly (position Verlet); a static answer
is the rest state of a damped run (AnalyticalLinearDamper), so each setting (elements) is
run in chunks of simulated time until the tip moves less than 1e-9 L per chunk or the wall
time cap is hit (both are in the record). The section stiffnesses are set directly to the
beamfx values (bend_matrix, shear_matrix); mass and damping only set the relaxation speed.
Moments are applied at the tip in the material frame of the last element, turned each step
so that they stay fixed in space. Not run here: eigenfrequencies (no linearised solver),
the 45-degree bend (PyElastica builds straight rods; a curved stress-free rod needs its
rest curvature set by hand) and the spin-up (a prescribed hub rotation is not a built-in
boundary condition). Those cells of the report say so.

    .venv-peers/bin/python peers/elastica_cases.py DIR
"""

import time

import common
import elastica as ea
import numpy as np

CODE, ELEMENT = "PyElastica", "CosseratRod, damped relaxation"
CAP_S = 10.0  # wall-time cap per run


class TipMoment(ea.NoForces):
    """A moment fixed in space at the last element, ramped in over ``ramp`` s."""

    def __init__(self, moment, ramp):
        super().__init__()
        self.M, self.ramp = np.asarray(moment, float), ramp

    def apply_torques(self, system, time=np.float64(0.0)):  # noqa: B008
        f = min(1.0, float(time) / self.ramp)
        system.external_torques[:, -1] += f * system.director_collection[:, :, -1] @ self.M


class Sim(ea.BaseSystemCollection, ea.Constraints, ea.Forcing, ea.Damping):
    pass


def relax(p, n, moment):
    """Damped run of a straight cantilever along x with section axes (y, z) = (d1, d2)."""
    L, sec = p["L"], p["section"]
    sim = Sim()
    # radius whose circle has the largest EI/EA (r² = 4 EI/EA): keeps the explicit step stable
    radius = np.sqrt(4 * max(sec["EI_y"], sec["EI_z"], sec["GJ"]) / sec["EA"])
    rod = ea.CosseratRod.straight_rod(
        n,
        np.zeros(3),
        np.array([1.0, 0, 0]),
        np.array([0, 1.0, 0]),
        L,
        radius,
        1.0,
        youngs_modulus=sec["EA"] / (np.pi * radius**2),
        shear_modulus=sec["GA_y"] / (np.pi * radius**2),
    )
    rod.bend_matrix[:] = np.diag([sec["EI_y"], sec["EI_z"], sec["GJ"]])[:, :, None]
    rod.shear_matrix[:] = np.diag([sec["GA_y"], sec["GA_z"], sec["EA"]])[:, :, None]
    sim.append(rod)
    sim.constrain(rod).using(
        ea.OneEndFixedBC, constrained_position_idx=(0,), constrained_director_idx=(0,)
    )
    # explicit step: the axial wave crosses an element in dx sqrt(ρA/EA); take a third of it
    rhoA = float(rod.mass[1] / rod.rest_lengths[0])
    dt = 0.3 * (L / n) * np.sqrt(rhoA / max(sec["EA"], sec["GA_y"], sec["GA_z"]))
    t1 = L**2 * np.sqrt(rhoA / min(sec["EI_y"], sec["EI_z"]))  # bending time scale
    sim.add_forcing_to(rod).using(TipMoment, moment=moment, ramp=t1)
    sim.dampen(rod).using(
        ea.AnalyticalLinearDamper, uniform_damping_constant=4.0 / t1, time_step=dt
    )
    sim.finalize()
    stepper = ea.PositionVerlet()
    t, tip_old, wall0, steps = np.float64(0.0), None, time.perf_counter(), 0
    chunk = max(1, int(t1 / dt))
    converged = False
    while time.perf_counter() - wall0 < CAP_S:
        for _ in range(chunk):
            t = stepper.step(sim, t, dt)
        steps += chunk
        tip = rod.position_collection[:, -1].copy()
        if tip_old is not None and t > 2 * t1 and np.linalg.norm(tip - tip_old) < 1e-9 * L:
            converged = True
            break
        tip_old = tip
    R = rod.director_collection[:, :, -1].T  # columns: d1, d2, d3 (section y, z, tangent)
    frame = np.c_[R[:, 2], R[:, 0], R[:, 1]]  # as beamfx: (tangent, y, z)
    return (
        tip,
        frame,
        {"steps": steps, "dt": float(dt), "converged": converged, "unknowns": int(6 * n + 3)},
    )


def main():
    out_dir = common.out_dir()
    P = common.load_problems(out_dir)
    recs = []
    for pid in ("rollup_half", "rollup_full", "sm23"):
        p = P[pid]
        for n in (10, 20, 40):
            (tip, frame, info), wall, cold = common.warm(lambda: relax(p, n, p["moment"]))  # noqa: B023
            if pid == "sm23":
                vals = common.rotation_values(tip - np.array([p["L"], 0, 0]), frame)
            else:
                vals = {"x": tip[0], "y": tip[1], "z": tip[2]}
            recs.append(
                common.record(
                    pid,
                    p,
                    CODE,
                    ELEMENT,
                    f"{n} elements, {info['steps']} steps",
                    info["unknowns"],
                    wall,
                    vals,
                    cold_s=cold,
                    steps=info["steps"],
                    converged=info["converged"],
                    note="" if info["converged"] else f"stopped at the {CAP_S:g} s cap",
                )
            )
    for pid, why in (
        ("sm28", "cannot: explicit dynamics only, no eigenvalue solver"),
        ("sm28_timoshenko", "cannot: explicit dynamics only, no eigenvalue solver"),
        (
            "bend45",
            "not run: straight rods only; a stress-free curved rod needs hand-set rest curvature",
        ),
        ("spin_up", "not run: no prescribed-rotation (hub) boundary condition built in"),
    ):
        recs.append(common.record(pid, P[pid], CODE, ELEMENT, "—", None, None, None, note=why))
    meta = {"version": getattr(ea, "__version__", "1.0.0")}
    common.write(out_dir, "pyelastica", recs, meta, imports=("numpy", "elastica"))


if __name__ == "__main__":
    main()
