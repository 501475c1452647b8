"""Centre lines and interval meshes embedded in 3D. Knows nothing of physics."""

from .curves import Arc, Helix, Line, Polyline, SampledCurve, curve_from_gmsh
from .mesh import BeamMesh, BeamSpec, build_mesh

__all__ = [
    "Arc",
    "BeamMesh",
    "BeamSpec",
    "Helix",
    "Line",
    "Polyline",
    "SampledCurve",
    "build_mesh",
    "curve_from_gmsh",
]
