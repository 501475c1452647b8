"""The description of a beam model: what the scene file says, as frozen dataclasses (beams,
supports, loads, springs, point masses, the model) and the point names ``beam:where``.

Below the analyses: the formulations (:mod:`beamfx.analyses`) discretise a :class:`Model`,
the scene reader (:mod:`beamfx.scene`) and the benchmarks build one.
"""

from .model import (
    AXES,
    DOF_NAMES,
    LOAD_KINDS,
    Beam,
    DistributedLoad,
    Model,
    PointLoad,
    PointMass,
    Release,
    Spring,
    Support,
    resolve_point,
)

__all__ = [
    "AXES",
    "DOF_NAMES",
    "LOAD_KINDS",
    "Beam",
    "DistributedLoad",
    "Model",
    "PointLoad",
    "PointMass",
    "Release",
    "Spring",
    "Support",
    "resolve_point",
]
