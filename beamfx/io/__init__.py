"""Output for people and for ParaView: probes, nodal fields, VTU/PVD/XDMF, JSON, logging.

MPI: :func:`evaluate_points` and :func:`nodal_fields` are collective; writers act on rank 0
only and may be called from every rank.
"""

from .fields import nodal_fields
from .log import Progress, log
from .paraview import PvdSeries, XdmfSeries, write_vtu
from .probes import evaluate_points, track_rotations
from .results import check_writable, write_json_atomic

__all__ = [
    "Progress",
    "PvdSeries",
    "XdmfSeries",
    "check_writable",
    "evaluate_points",
    "log",
    "nodal_fields",
    "track_rotations",
    "write_json_atomic",
    "write_vtu",
]
