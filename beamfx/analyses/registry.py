"""The analyses a scene can ask for, found by name: ``[analysis] type = "<name>"``.

Every module ``beamfx/analyses/<something>_run.py`` declares ``ANALYSES``, a tuple of
:class:`Analysis` entries; the registry collects them, so adding an analysis type means adding
its module (and its docs), nothing else. A module's top level imports no DOLFINx or PETSc (the
scene reader imports every one of them to know the names and their settings).
"""

import importlib
import pkgutil
from collections.abc import Callable
from functools import cache
from typing import NamedTuple


class Analysis(NamedTuple):
    """One analysis type.

    Attributes:
        name: the scene's ``[analysis] type``.
        settings: the frozen settings class read from ``[analysis]``
            (:func:`beamfx.scene.schema.read_settings`); its fields are the keys.
        run: ``run(model, settings, ctx) -> Result`` (:mod:`beamfx.analyses.result`,
            ``ctx`` a :class:`~beamfx.analyses.context.RunContext`).
        plane: whether the planar model may replace the full one when the scene is a plane
            problem (False where the analysis has out-of-plane modes).
        linear: the analysis uses linear kinematics whatever ``[model] kinematics`` says.
        doc: one line for the docs and ``beamfx check``.
        restart: ``beamfx run --restart`` goes on from the run's checkpoint (else a restart
            is a fresh run, and the log says so).
    """

    name: str
    settings: type
    run: Callable
    plane: bool = True
    linear: bool = False
    doc: str = ""
    restart: bool = False


@cache
def analyses() -> dict[str, Analysis]:
    """``{name: Analysis}`` of every ``*_run`` module of this package, in name order."""
    from . import __path__ as here

    found = {}
    for info in pkgutil.iter_modules(here):
        if not info.name.endswith("_run"):
            continue
        module = importlib.import_module(f"{__package__}.{info.name}")
        for entry in getattr(module, "ANALYSES", ()):
            if entry.name in found:
                raise RuntimeError(f"analysis {entry.name!r} is declared twice")
            found[entry.name] = entry
    return dict(sorted(found.items()))


def analysis(name: str) -> Analysis:
    """The :class:`Analysis` called ``name``.

    Raises:
        KeyError: naming the analyses there are.
    """
    table = analyses()
    if name not in table:
        raise KeyError(f"no analysis {name!r}; there are {list(table)}")
    return table[name]


__all__ = ["Analysis", "analyses", "analysis"]
