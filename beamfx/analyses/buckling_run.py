"""Linear buckling of a scene (``[analysis] type = "buckling"``): load factors and modes about
the undeformed state or about the current (loaded) one; one frame per mode."""

from dataclasses import dataclass

from ..settings import option
from .context import RunContext
from .formulation import BeamFormulation
from .registry import Analysis
from .result import Result as _Base
from .result import entry


@dataclass(frozen=True)
class Settings:
    """``[analysis]`` of a buckling analysis."""

    modes: int = option(4, positive=True, doc="number of buckling modes")
    about: str = option(
        "undeformed",
        choices=("undeformed", "current"),
        doc="linearise about the undeformed state or the state under the scene's loads",
    )
    steps: int = option(10, positive=True, doc="load steps to the current state")


@dataclass(frozen=True, kw_only=True)
class Result(_Base):
    """Buckling load factors and mode shapes."""

    load_factors: tuple = entry("critical load factors, ascending")
    about: str = entry("the state linearised about")
    mode_shapes: tuple = entry("each mode's displacement at the probes (largest nodal = 1)")
    paraview_steps: str = entry("what the ParaView frames hold")

    def summary(self) -> dict:
        """The numbers of a sweep table: the critical load factors."""
        return {"load_factors": list(self.load_factors)}


def run(model: BeamFormulation, settings: Settings, ctx: RunContext) -> Result:
    """The buckling eigenproblem (K + λ K_G) φ = 0 about the chosen state."""
    from .buckling import solve_buckling
    from .mode_shapes import PARAVIEW_STEPS, prestress, shapes

    steps = ()
    if settings.about == "current":
        steps = prestress(
            model, settings.steps, ctx, "buckling about the current state: static solve"
        ).steps
    res = solve_buckling(model, settings.modes, about=settings.about, options=ctx.solver_options)
    for i, lam in enumerate(res.load_factors, start=1):
        ctx.log(f"  buckling mode {i}: load factor {lam:.8g}")
    return Result(
        analysis=ctx.analysis,
        load_steps=tuple(steps),
        newton_iterations=int(sum(s.iterations for s in steps)),
        seconds=dict(res.seconds),
        load_factors=tuple(res.load_factors.tolist()),
        about=settings.about,
        mode_shapes=shapes(model, res.modes, ctx),
        paraview_steps=PARAVIEW_STEPS,
    )


ANALYSES = (Analysis("buckling", Settings, run, plane=False, doc="linear buckling loads"),)
