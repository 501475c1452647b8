"""Mode shapes of modal and buckling analyses for the run's output: normalised, reported at
the probes, and written as one ParaView frame per mode."""

import numpy as np
from mpi4py import MPI

from ..geometry.mesh import mesh_size
from .dofs import point_displacement, point_displacement_dofs, subspace_dofs

PARAVIEW_STEPS = "one per mode (time = mode number), displacement scaled to 1/10 of the model size"


def normalise(model, modes):
    """Scale each mode (in place) so that its largest nodal displacement component (in
    absolute value; not the largest length of u) is 1."""
    u_dofs = subspace_dofs(model.W, 0)
    for mode in modes:
        local = np.max(np.abs(mode.x.array[u_dofs]), initial=0.0)
        peak = model.comm.allreduce(local, op=MPI.MAX)
        mode.x.array[:] /= peak or 1.0


def mode_report(model, probes, modes):
    """Mode shapes (normalised) at the probes (``{name: point}``): their displacement.

    Each point is looked up once, in the probes' order: the lookup is collective (DOLFINx
    exchanges the dofs found on shared vertices), so every rank must ask for the same points
    in the same order, which a ``set``'s (string hashes differ between processes) is not."""
    dofs = {at: point_displacement_dofs(model, at) for at in dict.fromkeys(probes.values())}
    return tuple(
        {
            name: point_displacement(model, dofs[at], mode.x.array).tolist()
            for name, at in probes.items()
        }
        for mode in modes
    )


def write_modes(model, modes, frames):
    """One frame per mode (time = mode number): the state plus the (normalised) mode, scaled
    to a tenth of the model's size."""
    size = mesh_size(model.mesh.mesh)  # the whole model's, not this rank's part's
    w0 = model.w.x.array.copy()
    for i, mode in enumerate(modes, start=1):
        model.w.x.array[:] = w0 + 0.1 * size * mode.x.array
        model.w.x.scatter_forward()
        frames.write(i, float(i))
    model.w.x.array[:] = w0
    model.w.x.scatter_forward()


def shapes(model, modes, ctx):
    """Normalise, report at the probes and write the modes; returns the probe report."""
    normalise(model, modes)
    report = mode_report(model, ctx.probes, modes)
    write_modes(model, modes, ctx.frames)
    return report


def prestress(model, steps, ctx, why):
    """The static solve under the scene's loads before an eigen-solve (``why`` is logged)."""
    from .static import solve_static

    ctx.log(why)
    return solve_static(model, steps=steps, options=ctx.solver_options, log=ctx.log)


__all__ = ["PARAVIEW_STEPS", "mode_report", "normalise", "prestress", "shapes", "write_modes"]
