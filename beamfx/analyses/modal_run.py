"""Modal analysis of a scene (``[analysis] type = "modal"``): natural frequencies about the
unloaded state or, under loads, about the pre-stressed one; one frame per mode."""

from collections.abc import Iterator
from dataclasses import dataclass
from functools import partial
from typing import TYPE_CHECKING

import numpy as np

from ..settings import option
from .context import RunContext
from .formulation import BeamFormulation
from .registry import Analysis
from .result import Result as _Base
from .result import entry

if TYPE_CHECKING:
    from ..spec import Model

ROTARY = ("full", "polar", "none")


@dataclass(frozen=True)
class Settings:
    """``[analysis]`` of a modal analysis."""

    modes: int = option(6, positive=True, doc="number of modes")
    target_hz: float = option(
        0.0, low=0.0, doc="the modes nearest this frequency (Hz), nearest first"
    )
    rotary_inertia: str = option("full", choices=ROTARY, doc="rotary inertia of the sections")
    prestress: bool = option(True, doc="about the static state under the scene's loads")
    steps: int = option(10, positive=True, doc="load steps of the pre-stressing solve")

    def free_body(self, spec: "Model") -> bool:
        """A structure without supports has its rigid-body modes at 0 Hz; only pre-stress
        (a static solve) needs supports."""
        return not (self.prestress and _loaded(spec))

    def problems_on_mesh(self, spec: "Model", points: tuple) -> Iterator[tuple[str, str]]:
        """No more modes than the free dofs with mass of the mesh of ``spec`` with vertices
        at ``points`` too (:mod:`.mode_count`)."""
        from .mode_count import modes_problem, spec_nodes

        nodes = spec_nodes(spec, points)
        problem = modes_problem(spec, self.modes, "modal", nodes, self.rotary_inertia)
        if problem:
            yield "modes", problem


def _loaded(spec):
    """Whether the scene's model (a :class:`~beamfx.spec.Model`) carries any load."""
    return bool(spec.point_loads or spec.distributed_loads or any(spec.gravity))


@dataclass(frozen=True, kw_only=True)
class Result(_Base):
    """Frequencies and mode shapes."""

    frequencies_hz: tuple = entry("natural frequencies (Hz), ascending")
    effective_mass: tuple = entry("effective modal masses per mode and global direction")
    omega_rad_s: tuple = entry("circular frequencies (rad/s)")
    prestressed: bool = entry("solved about a loaded static state")
    rigid_body_modes: int = entry("how many of the first modes are free rigid-body motions")
    mode_shapes: tuple = entry("each mode's displacement at the probes (largest nodal = 1)")
    paraview_steps: str = entry("what the ParaView frames hold")

    def summary(self) -> dict:
        """The numbers of a sweep table: the frequencies (Hz)."""
        return {"frequencies_hz": list(self.frequencies_hz)}


def run(model: BeamFormulation, settings: Settings, ctx: RunContext) -> Result:
    """Pre-stress (if loaded and asked), then the modes nearest ``target_hz``."""
    from .modal import effective_masses, solve_modes
    from .modal_target import solve_nearest_hz
    from .mode_count import check_modes, free_dofs_of, mesh_nodes
    from .mode_shapes import PARAVIEW_STEPS, prestress, shapes

    ctx.require_mass(model, "modal")
    check_modes(model, ctx.spec, settings.modes, "modal", ctx.file, settings.rotary_inertia)
    spec, steps = ctx.spec, ()
    if settings.prestress and _loaded(spec):
        steps = prestress(
            model, settings.steps, ctx, "pre-stress: static solve under the scene's loads"
        )
        steps = steps.steps
    target = (2 * np.pi * settings.target_hz) ** 2
    solve = partial(
        solve_modes,
        model,
        target=target,
        rotary=settings.rotary_inertia,
        options=ctx.solver_options,
    )
    if settings.target_hz > 0:  # nearest in Hz, not in ω² (modal_target.py)
        most = free_dofs_of(spec, mesh_nodes(model), settings.rotary_inertia)
        res = solve_nearest_hz(solve, settings.modes, settings.target_hz, most)
    else:
        res = solve(settings.modes)
    rigid = _rigid_modes(spec, settings, res.omega)
    for i, (f, w) in enumerate(zip(res.hz, res.omega), start=1):
        kind = " rigid-body (0 Hz to round-off)" if i <= rigid else ""
        ctx.log(f"  mode {i}: {f:.6g} Hz ({w:.6g} rad/s){kind}")
    m_eff = effective_masses(model, res.modes, settings.rotary_inertia, res.mass_form)
    return Result(
        analysis=ctx.analysis,
        load_steps=tuple(steps),
        newton_iterations=int(sum(s.iterations for s in steps)),
        seconds=dict(res.seconds),
        frequencies_hz=tuple(res.hz.tolist()),
        effective_mass=tuple(m_eff.tolist()),
        omega_rad_s=tuple(res.omega.tolist()),
        prestressed=bool(steps),
        rigid_body_modes=rigid,
        mode_shapes=shapes(model, res.modes, ctx),
        paraview_steps=PARAVIEW_STEPS,
    )


def _rigid_modes(spec, settings, omega):
    """How many of the first modes are free rigid-body motions: at most as many as the
    supports leave free, looking from 0 Hz, and each below 1e-2 of the highest frequency found
    (a rigid rotation without rotary inertia has no finite frequency and is not among them)."""
    from .checks import free_rigid_modes

    free = free_rigid_modes(spec) if settings.target_hz == 0 else 0
    top = np.max(np.abs(omega), initial=0.0)
    return int(np.sum(np.abs(omega[:free]) < 1e-2 * top))


ANALYSES = (Analysis("modal", Settings, run, plane=False, doc="natural frequencies and modes"),)
