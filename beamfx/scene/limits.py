"""``[limits]``: the sizes a scene may ask for, raised only by a scene that says so.

A scene file may come from anyone: ``elements = 100000000``, a sweep of a million members or a
mesh file of gigabytes would otherwise run until killed. Every size is checked against these
bounds in ``beamfx check`` (and so before any ``run``); a user who means a larger problem
raises the bound in the same file, where a reader sees it::

    [limits]
    max_unknowns = 5_000_000

The defaults are far above every scene of the docs, demos and benchmarks.
"""

from dataclasses import dataclass

from ..settings import option

#: unknowns per mesh node of the largest formulation (quaternion: 3 displacements, 4 parameters)
UNKNOWNS_PER_NODE = 7


@dataclass(frozen=True)
class Limits:
    """What ``[limits]`` says (see docs/scenes.md)."""

    max_unknowns: int = option(
        1_000_000,
        positive=True,
        high=10**9,
        doc="unknowns of the model (7 per node: the elements of all beams times their degree)",
    )
    max_beams: int = option(
        5_000,
        positive=True,
        high=10**9,
        doc="`[[beams]]` tables (checking joints and supports costs a few ms per beam)",
    )
    max_count: int = option(
        1_000_000,
        positive=True,
        high=10**9,
        doc="any count a scene gives: load steps, arc-length steps, modes, time steps "
        "(t_end / dt), frames",
    )
    max_members: int = option(
        10_000, positive=True, high=10**9, doc="members of a `[[sweep]]` (product of its axes)"
    )
    max_file_mb: float = option(
        64.0, positive=True, doc="size of a file the scene names (gmsh `.geo`/`.msh`), in MB"
    )
    files_outside: bool = option(
        False,
        doc="allow files (gmsh curves) outside the scene file's folder; devices, FIFOs and "
        "other non-regular files are refused even then",
    )


def read_limits(top):
    """The :class:`Limits` of the top-level table ``top`` (defaults if it has no ``[limits]``)."""
    from .schema import read_settings

    return read_settings(Limits, top.table("limits", {}))


def unknowns(beams):
    """An upper estimate of the unknowns of ``beams`` (:class:`~beamfx.spec.Beam`): nodes of
    the highest degree's mesh times :data:`UNKNOWNS_PER_NODE`."""
    degree = max(b.degree for b in beams)
    cells = sum(max(b.elements, len(b.curve.kinks) + 1) for b in beams)  # a vertex per kink
    return UNKNOWNS_PER_NODE * (cells * degree + len(beams))


__all__ = ["Limits", "read_limits", "unknowns"]
