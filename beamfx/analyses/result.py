"""What an analysis returns: a frozen dataclass with ``to_json()``, one shape for success and
failure (``status`` and ``reason``), extended by each analysis with its own fields."""

import dataclasses
from dataclasses import dataclass, field
from typing import Any

import numpy as np

#: the types :func:`plain` returns as they are (checked first: a run's path holds thousands)
_SCALARS = frozenset((float, int, str, bool, type(None)))


def plain(obj: object) -> object:
    """``obj`` as JSON-ready lists, dicts and numbers (NumPy, NamedTuples, dataclasses)."""
    kind = type(obj)
    if kind in _SCALARS:
        return obj
    if kind is dict:  # the exact containers before the checks for NumPy, NamedTuples and
        return {k: plain(v) for k, v in obj.items()}  # dataclasses (none of them is one)
    if kind is list or kind is tuple:
        if all(type(v) is float for v in obj):  # a vector: copied as it is
            return list(obj)
        return [plain(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    if hasattr(obj, "_asdict"):
        return {k: plain(v) for k, v in obj._asdict().items()}
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {f.name: plain(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    if isinstance(obj, dict):
        return {k: plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [plain(v) for v in obj]
    return obj


STATUSES = ("converged", "stopped", "failed")


@dataclass(frozen=True, kw_only=True)
class Result:
    """The part every analysis has.

    Attributes:
        analysis: the analysis type.
        status: "converged" (done as asked), "stopped" (ended early by a physical stop the
            scene allows, e.g. a lost steady state; ``reason`` says which) or "failed".
        reason: why it stopped or failed (None when converged).
        load_steps: the accepted load steps (:class:`~beamfx.solvers.stepping.LoadStep`) of
            the last static solve, if any.
        newton_iterations: Newton iterations of the analysis.
        seconds: wall time split (compile, assemble_F, assemble_J, solve, total, ...).
        cause, remedy: of a numerical failure (see :mod:`beamfx.solvers.convergence`).
        failure: what a failed solve tried (attempts and their residuals, eigenvalues found).
    """

    analysis: str
    status: str = "converged"
    reason: str | None = None
    load_steps: tuple = ()
    newton_iterations: int = 0
    seconds: dict = field(default_factory=dict)
    cause: str | None = None
    remedy: str | None = None
    failure: dict | None = None

    def to_json(self) -> dict:
        """The analysis's entries of ``results.json`` (plain lists and numbers)."""
        out = {"analysis": self.analysis, "converged": self.status == "converged"}
        out["status"] = self.status
        for key in ("reason", "cause", "remedy", "failure"):
            if getattr(self, key) is not None:
                out[key] = plain(getattr(self, key))
        out["load_steps"] = [
            {
                "step": s.step,
                "load_factor": s.load_factor,
                "newton_iterations": s.iterations,
                "residuals": list(s.residuals),
                "cutbacks": s.cutbacks,
                "converged_by": getattr(s, "converged_by", "residual"),
                "force_scale": getattr(s, "force_scale", 0.0),
            }
            for s in self.load_steps
        ]
        out["newton_iterations"] = int(self.newton_iterations)
        base = {f.name for f in dataclasses.fields(Result)}
        for f in dataclasses.fields(self):
            if f.name not in base:
                out[f.name] = plain(getattr(self, f.name))
        return out

    def summary(self) -> dict:
        """The numbers of a sweep table (beyond probes and unknowns): by default none."""
        return {}


def failed(analysis: str, error: Exception, seconds: dict | None = None) -> "Result":
    """The :class:`Result` of an analysis that raised ``error`` (a
    :class:`~beamfx.solvers.snes.SolveFailed`): status "failed", the first line of its message
    as the reason, its cause, remedy and details, and the load steps it had accepted."""
    steps = tuple(s for s in getattr(error, "history", ()) if hasattr(s, "load_factor"))
    return Result(
        analysis=analysis,
        status="failed",
        reason=str(error).splitlines()[0] if str(error) else type(error).__name__,
        load_steps=steps,
        newton_iterations=int(sum(s.iterations for s in steps)),
        seconds=dict(seconds or {}),
        cause=getattr(error, "cause", None),
        remedy=getattr(error, "remedy", None),
        failure=dict(getattr(error, "details", None) or {}) or None,
    )


def entry(doc: str = "") -> Any:
    """A result field (documentation only; every field goes into ``results.json``)."""
    return field(metadata={"doc": doc})


__all__ = ["STATUSES", "Result", "entry", "failed", "plain"]
