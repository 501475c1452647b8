"""A rotating analysis of a scene (``[analysis] type = "rotating"``, behind ``beamfx run``):
steady state and rotating-frame frequencies at each speed, the Campbell diagram as
``campbell.csv`` and ``campbell.png``, one ParaView step per speed (the steady state)."""

from types import SimpleNamespace

import numpy as np
from mpi4py import MPI

from .campbell import campbell, write_campbell
from .rotating import RotatingFrame
from .spec import resolve_point


def hub_point(scene):
    """Coordinates of the scene's hub: the named point, else the first support's point."""
    at = scene.settings.get("hub") or scene.model.supports[0].at
    return at, resolve_point(scene.model, at)[2]


def run_rotating(model, scene, write, log, out):
    """Solve the scene's rotating analysis and write the Campbell files into ``out``. Returns
    (result with ``steps`` and ``seconds``, entries for ``results.json``)."""
    settings = scene.settings
    mass = model.comm.allreduce(float(np.max(model.inertia.x.array, initial=0.0)), op=MPI.MAX)
    if mass <= 0 and not any(pm.mass for pm in getattr(scene.model, "point_masses", ())):
        raise ValueError(
            f"{scene.file}: a rotating analysis needs mass: give [material] rho, or rho_A and "
            "rho_I of the general sections"
        )
    hub_at, hub = hub_point(scene)
    frame = RotatingFrame(model, settings["axis"], hub, settings["rotary_inertia"])
    log(
        f"rotating about {frame.axis.round(6).tolist()} through {hub_at} "
        f"{np.round(hub, 6).tolist()}, {len(settings['speeds_rad_s'])} speed(s)"
    )
    result = campbell(
        frame,
        settings["speeds_rad_s"],
        settings["modes"],
        steps=scene.steps,
        options=scene.solver_options,
        on_speed=lambda i, speed: write(i, float(speed)),  # ParaView: the steady state
        log=log,
    )
    frame.destroy()
    write_campbell(result, out, model.comm)
    branches = [
        {
            "branch": b + 1,
            "frequencies_hz": result.branches_hz[:, b].tolist(),
            "growth_rate_1_s": result.branches_growth[:, b].tolist(),
            "mac": result.mac[:, b].tolist(),
            "out_of_plane": result.out_of_plane[:, b].tolist(),
        }
        for b in range(result.branches_hz.shape[1] if len(result.speeds) else 0)
    ]
    extra = {
        "axis": frame.axis.tolist(),
        "hub": {"at": hub_at, "position": np.asarray(hub).tolist()},
        "rotary_inertia": settings["rotary_inertia"],
        "speeds_rad_s": result.speeds.tolist(),
        "frequencies_hz": result.frequencies_hz.tolist(),
        "stable": result.stable.tolist(),
        "campbell": branches,
        "stopped_by": result.stopped_by,
        "files": {"csv": "campbell.csv", "png": "campbell.png"},
        "steady_newton_iterations": [s.newton_iterations for s in result.steady],
    }
    steps = result.steady[-1].steps if result.steady else ()
    seconds = {"total": float(sum(s.seconds["total"] for s in result.steady))}
    return SimpleNamespace(steps=tuple(steps), seconds=seconds), extra
