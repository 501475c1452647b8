"""Modal and buckling analyses of a scene: solve, then report modes at the probes and write one
ParaView step per mode (behind ``beamfx run`` for ``[analysis] type = "modal"/"buckling"``)."""

import numpy as np
from mpi4py import MPI

from .continuation import point_displacement, point_displacement_dofs


def _normalise(model, modes):
    """Scale each mode (in place) so that its largest nodal displacement is 1."""
    _, u_dofs = model.W.sub(0).collapse()
    for mode in modes:
        local = np.max(np.abs(mode.x.array[u_dofs]), initial=0.0)
        peak = model.comm.allreduce(local, op=MPI.MAX)
        mode.x.array[:] /= peak or 1.0


def _mode_report(model, scene, modes):
    """Mode shapes (normalised) at the probes: their displacement."""
    dofs = {at: point_displacement_dofs(model, at) for at in set(scene.probes.values())}
    return [
        {
            name: point_displacement(model, dofs[at], mode.x.array).tolist()
            for name, at in scene.probes.items()
        }
        for mode in modes
    ]


def _write_modes(model, modes, write):
    """One ParaView step per mode (time = mode number): the state plus the (normalised) mode,
    scaled to a tenth of the model's size."""
    x = model.mesh.mesh.geometry.x
    size = model.comm.allreduce(float(np.ptp(x, axis=0).max()) if len(x) else 0.0, op=MPI.MAX)
    w0 = model.w.x.array.copy()
    for i, mode in enumerate(modes, start=1):
        model.w.x.array[:] = w0 + 0.1 * size * mode.x.array
        model.w.x.scatter_forward()
        write(i, float(i))
    model.w.x.array[:] = w0
    model.w.x.scatter_forward()


def run_eigen(model, scene, write, log):
    """Solve the scene's modal or buckling analysis. Returns (result with ``steps``, results
    entries for ``results.json``)."""
    from types import SimpleNamespace

    from .buckling import solve_buckling
    from .modal import effective_masses, solve_modes
    from .static import solve_static

    settings = scene.settings
    steps = ()
    if scene.analysis == "modal":
        mass = model.comm.allreduce(float(np.max(model.inertia.x.array, initial=0.0)), op=MPI.MAX)
        if mass <= 0 and not scene.model.point_masses:
            raise ValueError(
                f"{scene.file}: a modal analysis needs mass: give [material] rho, or rho_A and "
                "rho_I of the general sections, or [[masses]]"
            )
        loaded = (
            scene.model.point_loads or scene.model.distributed_loads or any(scene.model.gravity)
        )
        if settings["prestress"] and loaded:
            log("pre-stress: static solve under the scene's loads")
            steps = solve_static(
                model, steps=scene.steps, options=scene.solver_options, log=log
            ).steps
        target = (2 * np.pi * settings["target_hz"]) ** 2
        res = solve_modes(
            model,
            settings["modes"],
            target,
            rotary=settings["rotary_inertia"],
            options=scene.solver_options,
        )
        for i, (f, w) in enumerate(zip(res.hz, res.omega), start=1):
            log(f"  mode {i}: {f:.6g} Hz ({w:.6g} rad/s)")
        m_eff = effective_masses(model, res.modes, settings["rotary_inertia"])
        _normalise(model, res.modes)
        shapes = _mode_report(model, scene, res.modes)
        extra = {
            "frequencies_hz": res.hz.tolist(),
            "effective_mass": m_eff.tolist(),
            "omega_rad_s": res.omega.tolist(),
            "prestressed": bool(steps),
            "mode_shapes": shapes,
            "paraview_steps": "one per mode (time = mode number), displacement scaled to 1/10 of the model size",
        }
    else:
        if settings["about"] == "current":
            steps = solve_static(
                model, steps=scene.steps, options=scene.solver_options, log=log
            ).steps
        res = solve_buckling(
            model, settings["modes"], about=settings["about"], options=scene.solver_options
        )
        for i, lam in enumerate(res.load_factors, start=1):
            log(f"  buckling mode {i}: load factor {lam:.8g}")
        _normalise(model, res.modes)
        shapes = _mode_report(model, scene, res.modes)
        extra = {
            "load_factors": res.load_factors.tolist(),
            "about": settings["about"],
            "mode_shapes": shapes,
            "paraview_steps": "one per mode (time = mode number), displacement scaled to 1/10 of the model size",
        }
    _write_modes(model, res.modes, write)
    return SimpleNamespace(steps=tuple(steps), seconds=dict(res.seconds)), extra
