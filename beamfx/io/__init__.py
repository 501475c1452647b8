"""Output for people and for ParaView: probes, nodal fields, VTK/PVD/XDMF frames, JSON, logging.

MPI: :func:`evaluate_points`, :func:`nodal_fields` and the :class:`~.output.FrameWriter` are
collective; the frames are written by every rank (its own piece), JSON and logs by rank 0.
VTK (:mod:`.vtkfiles`) and DOLFINx are imported only where used.
"""

from .fields import local_fields, nodal_fields
from .log import Progress, log
from .output import FrameWriter, OutputSettings
from .probes import evaluate_points, track_rotations
from .results import check_writable, write_json_atomic
from .vtkfiles import write_vtu

__all__ = [
    "FrameWriter",
    "OutputSettings",
    "Progress",
    "check_writable",
    "evaluate_points",
    "local_fields",
    "log",
    "nodal_fields",
    "track_rotations",
    "write_json_atomic",
    "write_vtu",
]
