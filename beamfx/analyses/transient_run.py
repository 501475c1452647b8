"""A transient analysis of a scene, written as it goes (behind ``beamfx run`` for
``[analysis] type = "transient"``).

Every step appends a row to ``probes.csv`` and a line to ``probes.jsonl`` (time, step size,
Newton iterations, the probes' position, displacement and unwrapped rotation, and the
energy balance); every ``output_every`` steps adds a ParaView frame; every
``checkpoint_every`` steps a checkpoint lets ``beamfx run --restart`` go on from there.
"""

import json

import numpy as np

ENERGY_KEYS = (
    "kinetic",
    "strain",
    "work_loads",
    "work_supports",
    "dissipated_damping",
    "numerical",
)


def motion_warnings(model, t_end, samples=4000):
    """Warnings for prescribed support motions that would need infinite acceleration: a value
    or slope that jumps (including at t = 0, where the run starts at rest).

    A smooth history's largest change of slope between samples halves when the sampling is
    refined; a jump in value or slope does not.
    """
    out = []
    for i, sup in enumerate(model.supports):
        f = sup.history
        if f is None or not (any(sup.displacement) or any(sup.rotation)):
            continue
        kinks = []
        for n in (samples, 2 * samples):
            t = np.linspace(0.0, t_end, n + 1)
            slope = np.diff(f(t)) / (t[1] - t[0])
            kinks.append(np.max(np.abs(np.diff(slope)), initial=0.0))
        scale = np.max(np.abs(f(np.linspace(0.0, t_end, 101)))) / t_end + 1e-300
        dt0 = t_end / samples
        slopes = [abs(float(f(d) - f(0.0))) / d for d in (dt0, dt0 / 2)]  # halves if smooth
        start = abs(float(f(0.0))) > 1e-9 * scale * t_end or (
            slopes[1] > 0.75 * slopes[0] and slopes[1] > 1e-6 * scale
        )
        if kinks[1] > 0.75 * kinks[0] and kinks[1] > 1e-6 * scale or start:
            where = "at t = 0 (the run starts at rest)" if start else "inside the run"
            out.append(
                f"supports[{i}] at {sup.at!r}: the history {getattr(f, 'text', '')!r} jumps in "
                f"value or slope {where}: that needs an infinite acceleration, and the "
                "response will ring; smooth it (e.g. a (1 - cos) ramp)"
            )
    return out


def _columns(probes):
    cols = ["step", "time", "dt", "iterations", "cutbacks"]
    for name in probes:
        cols += [f"{name}_{c}" for c in ("x", "y", "z", "ux", "uy", "uz")]
        cols += [f"{name}_rot_{c}" for c in ("x", "y", "z")]
    return cols + list(ENERGY_KEYS)


def run_transient(model, scene, out, write, log, restart=False):
    """Solve the scene's transient. Returns (result with ``steps``, results.json entries)."""
    from ..io import Progress, evaluate_points, track_rotations
    from .static import solve_static
    from .transient import load_checkpoint, solve_transient

    comm = model.comm
    settings = scene.settings["transient"]
    for w in motion_warnings(scene.model, settings.t_end):
        log(f"warning: {w}")
    saved = load_checkpoint(out, comm) if restart else None
    if restart and saved is None:
        log("note: no checkpoint for this number of ranks; starting from t = 0")
    if saved is None and scene.settings["start"] == "static":
        model.set_time(0.0)
        static = solve_static(model, steps=scene.steps, options=scene.solver_options, log=log)
        log(f"static start: {static.newton_iterations} Newton iterations")

    csv, jsonl = out / "probes.csv", out / "probes.jsonl"
    probes = scene.probes
    cols = _columns(probes)
    t_restart = saved["t"] if saved else None
    if saved is not None:
        write.resume(t_restart)
    if comm.rank == 0:
        if saved is None:
            csv.write_text(",".join(cols) + "\n")
            jsonl.write_text("")
        else:  # keep what was written up to the checkpoint
            rows = csv.read_text().splitlines() if csv.exists() else [",".join(cols)]
            keep = [r for r in rows[1:] if float(r.split(",")[1]) <= t_restart * (1 + 1e-12)]
            csv.write_text("\n".join([rows[0], *keep]) + "\n")
            lines = jsonl.read_text().splitlines() if jsonl.exists() else []
            keep = [x for x in lines if json.loads(x)["time"] <= t_restart * (1 + 1e-12)]
            jsonl.write_text("".join(x + "\n" for x in keep))
    latest = {}

    def on_step(r):
        values = evaluate_points(model, list(probes.values()))
        latest["probes"] = track_rotations(latest.get("probes"), values)
        latest["energy"] = r.energy
        if r.step % settings.output_every == 0:
            write(r.step, r.time)
        if comm.rank != 0:
            return
        row = [r.step, r.time, r.dt, r.iterations, r.cutbacks]
        entry = {"step": r.step, "time": r.time, "dt": r.dt, "iterations": r.iterations}
        entry["probes"] = {}
        for name, at in probes.items():
            v = latest["probes"][at]
            row += [*v["position"], *v["displacement"], *v["rotation_vector_unwrapped"]]
            entry["probes"][name] = {
                k: v[k] for k in ("position", "displacement", "rotation_vector_unwrapped")
            }
        row += [r.energy[k] for k in ENERGY_KEYS]
        entry["energy"] = r.energy
        with csv.open("a") as f:
            f.write(",".join(f"{x:.12g}" for x in row) + "\n")
        with jsonl.open("a") as f:
            f.write(json.dumps(entry) + "\n")

    bar = Progress(label="transient", every=5.0, comm=model.comm)

    def progress(r):
        residual = r.residuals[-1] if r.residuals else 0.0
        bar.update(
            r.step,
            f"t = {r.time:.5g}/{settings.t_end:g} s, dt = {r.dt:.3g}, {r.iterations} its, "
            f"|F| = {residual:.2e}",
        )

    try:
        result = solve_transient(
            model,
            settings,
            on_step=on_step,
            log=log,
            progress=progress,
            options=scene.solver_options,
            checkpoint_dir=out,
            saved=saved,
        )
    finally:
        bar.close()
    if result.steps and result.steps[-1].step % settings.output_every:
        write(result.steps[-1].step, result.steps[-1].time)
    if "probes" not in latest:  # restarted at the end: nothing new
        latest["probes"] = track_rotations(None, evaluate_points(model, list(probes.values())))
    extra = {
        "scheme": settings.parameters().name,
        "t_end": settings.t_end,
        "time_steps": len(result.steps),
        "restarted_from": t_restart,
        "energy": latest.get("energy"),
        "probe_history": {"csv": csv.name, "jsonl": jsonl.name},
        "stopped_by": result.stopped_by,
    }
    return result, extra, latest["probes"]


__all__ = ["motion_warnings", "run_transient"]
