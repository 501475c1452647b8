"""Centre lines parametrised by arc length.

Every curve has ``length``, ``points(s)`` for an array of arc lengths (returns shape (n, 3))
and ``kinks``: arc lengths where the tangent jumps, at which the mesh must put a vertex.
Nodes are placed on the exact curve, so isoparametric P_k elements converge to it.
"""

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np


def _unit(v):
    v = np.asarray(v, dtype=float)
    n = np.linalg.norm(v)
    if n == 0:
        raise ValueError("zero-length direction vector")
    return v / n


@dataclass(frozen=True)
class Line:
    """Straight segment from ``start`` to ``end``."""

    start: tuple
    end: tuple

    @cached_property
    def length(self):
        """Arc length of the curve (computed once: frames ask it of 10⁵ members many times)."""
        return float(np.linalg.norm(np.subtract(self.end, self.start)))

    @property
    def kinks(self):
        """Arc lengths of the corners where the tangent jumps (none)."""
        return ()

    def points(self, s):
        """(n, 3) points of the curve at the arc lengths ``s`` from the start."""
        d = np.subtract(self.end, self.start) / self.length
        return np.asarray(self.start, float) + np.outer(s, d)


@dataclass(frozen=True)
class Arc:
    """Circular arc from ``start`` leaving along ``start_tangent`` around ``centre``.

    The plane is spanned by the tangent and the direction to the centre, so any plane works.
    """

    start: tuple
    start_tangent: tuple
    centre: tuple
    angle_deg: float

    @property
    def radius(self):
        """Radius of the arc (distance from the centre to ``start``)."""
        return float(np.linalg.norm(np.subtract(self.centre, self.start)))

    @property
    def length(self):
        """Arc length of the curve."""
        return self.radius * np.deg2rad(self.angle_deg)

    @property
    def kinks(self):
        """Arc lengths of the corners where the tangent jumps (none)."""
        return ()

    def points(self, s):
        """(n, 3) points of the curve at the arc lengths ``s`` from the start."""
        c = np.asarray(self.centre, float)
        e_r = _unit(np.subtract(self.start, c))  # from centre to start
        t = np.asarray(self.start_tangent, float)
        t = _unit(t - (t @ e_r) * e_r)
        phi = np.asarray(s) / self.radius
        return c + self.radius * (np.outer(np.cos(phi), e_r) + np.outer(np.sin(phi), t))


@dataclass(frozen=True)
class Helix:
    """Helix about ``axis`` through ``centre``: ``turns`` turns of ``radius`` and ``pitch``.

    Starts at ``centre + radius · start_direction`` (made normal to the axis).
    """

    centre: tuple
    axis: tuple
    radius: float
    pitch: float
    turns: float
    start_direction: tuple = (1.0, 0.0, 0.0)

    @property
    def _c(self):
        return np.hypot(2 * np.pi * self.radius, self.pitch)  # length per turn

    @property
    def length(self):
        """Arc length of the curve."""
        return self.turns * self._c

    @property
    def kinks(self):
        """Arc lengths of the corners where the tangent jumps (none)."""
        return ()

    def points(self, s):
        """(n, 3) points of the curve at the arc lengths ``s`` from the start."""
        a = _unit(self.axis)
        e1 = np.asarray(self.start_direction, float)
        e1 = _unit(e1 - (e1 @ a) * a)
        e2 = np.cross(a, e1)
        phi = 2 * np.pi * np.asarray(s) / self._c
        return (
            np.asarray(self.centre, float)
            + self.radius * (np.outer(np.cos(phi), e1) + np.outer(np.sin(phi), e2))
            + np.outer(self.pitch * phi / (2 * np.pi), a)
        )


@dataclass(frozen=True)
class Polyline:
    """Straight segments through ``vertices``; the beam is continuous and rigid at the kinks."""

    vertices: tuple

    @property
    def _cum(self):
        v = np.asarray(self.vertices, float)
        return np.r_[0, np.cumsum(np.linalg.norm(np.diff(v, axis=0), axis=1))]

    @property
    def length(self):
        """Arc length of the curve."""
        return float(self._cum[-1])

    @property
    def kinks(self):
        """Arc lengths of the inner vertices, where the tangent jumps."""
        return tuple(self._cum[1:-1])

    def points(self, s):
        """(n, 3) points of the curve at the arc lengths ``s`` from the start."""
        v = np.asarray(self.vertices, float)
        s = np.atleast_1d(np.asarray(s, float))
        return np.stack([np.interp(s, self._cum, v[:, i]) for i in range(3)], axis=1)


@dataclass(frozen=True)
class SampledCurve:
    """Smooth curve through ``through`` (cubic spline), re-parametrised by arc length.

    Used for splines through points and for curves read from gmsh. The arc length is computed
    on a fine sampling (Simpson), accurate to about 1e-10 of the length for smooth curves.
    """

    through: tuple
    samples: int = 4001
    _table: tuple = field(default=None, compare=False, repr=False)

    def __post_init__(self):
        from scipy.integrate import cumulative_trapezoid
        from scipy.interpolate import CubicSpline

        pts = np.asarray(self.through, float)
        if len(pts) < 2:
            raise ValueError("a curve needs at least two points")
        chord = np.r_[0, np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))]
        spline = CubicSpline(chord, pts, bc_type="not-a-knot")
        p = np.linspace(0, chord[-1], self.samples)
        speed = np.linalg.norm(spline(p, 1), axis=1)
        s = cumulative_trapezoid(speed, p, initial=0)
        # Richardson-correct the trapezoid rule with a half-resolution pass (Simpson accuracy)
        s_half = cumulative_trapezoid(speed[::2], p[::2], initial=0)
        s_fine = s[::2] + (s[::2] - s_half) / 3
        object.__setattr__(self, "_table", (spline, CubicSpline(s_fine, p[::2])))

    @property
    def length(self):
        """Arc length of the curve."""
        return float(self._table[1].x[-1])

    @property
    def kinks(self):
        """Arc lengths of the corners where the tangent jumps (none)."""
        return ()

    def points(self, s):
        """(n, 3) points of the curve at the arc lengths ``s`` from the start."""
        spline, p_of_s = self._table
        return spline(p_of_s(np.atleast_1d(s)))


def _quiet_fltk():
    """Stop FLTK (linked into gmsh) from rewriting its preference files.

    ``gmsh.initialize`` sets the default of ``General.Tooltips`` with ``Fl::option``, whose
    first call reads *and rewrites* ``/etc/fltk/fltk.org/fltk.prefs`` and
    ``~/.fltk/fltk.org/fltk.prefs`` (as root, both). Marking FLTK's options as already read
    (its static ``Fl::options_read_``) skips that: the options keep FLTK's built-in defaults,
    which a run without a window never uses. Where FLTK is not found, nothing is done.
    """
    import ctypes

    for name in ("libfltk.so.1.3", "libfltk.so"):
        try:
            ctypes.c_uint8.in_dll(ctypes.CDLL(name), "_ZN2Fl13options_read_E").value = 1
            return
        except (OSError, ValueError):
            continue


def curve_from_gmsh(path, curve_tag=None, samples=400):
    """The curve of a gmsh ``.geo`` or ``.msh`` file, as a :class:`SampledCurve`.

    With several curves, ``curve_tag`` picks one; consecutive curves of a ``.geo`` are not
    joined: describe each as its own beam sharing end points. The file is read by
    :func:`read_gmsh` (a ``.geo`` scanned first).

    Raises:
        ValueError: naming the file, for a refused or unreadable file.
    """
    xyz = read_gmsh(path, lambda gmsh: _gmsh_curve_points(gmsh, str(path), curve_tag, samples))
    return SampledCurve(tuple(map(tuple, xyz)))


def read_gmsh(path, read):
    """``read(gmsh)`` with the gmsh file at ``path`` open, and its result: the one way beamfx
    opens gmsh files. A ``.geo`` file is scanned first
    (:func:`~beamfx.geometry.geo_scan.check_geo`: plain geometry only, nothing that runs,
    writes, reads or loops); gmsh reads no configuration file and writes no preference file.

    Raises:
        ValueError: naming the file, for a refused or unreadable file (gmsh's errors too).
    """
    import gmsh

    from .geo_scan import check_geo

    path = str(path)
    if path.lower().endswith(".geo"):
        with open(path, encoding="utf-8", errors="strict") as f:
            check_geo(f.read())
    _quiet_fltk()
    gmsh.initialize(readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setString("General.TmpFileName", "")  # nothing to remove in the home folder
        gmsh.open(path)
        return read(gmsh)
    except Exception as e:  # gmsh raises a bare Exception with its last error message
        if isinstance(e, ValueError):
            raise
        raise ValueError(f"{path}: gmsh could not read it: {e}") from None
    finally:
        gmsh.finalize()


def _gmsh_curve_points(gmsh, path, curve_tag, samples):
    """Points along the chosen 1D entity of the open gmsh model."""
    curves = [tag for dim, tag in gmsh.model.getEntities(1)]
    if not curves:
        raise ValueError(f"{path}: no curve (1D entity) in the file")
    if curve_tag is None:
        if len(curves) > 1:
            raise ValueError(f"{path}: {len(curves)} curves {curves}; give curve_tag")
        curve_tag = curves[0]
    if curve_tag not in curves:
        raise ValueError(f"{path}: curve_tag {curve_tag} not in {curves}")
    lo, hi = gmsh.model.getParametrizationBounds(1, curve_tag)
    u = np.linspace(lo[0], hi[0], samples)
    xyz = np.reshape(gmsh.model.getValue(1, curve_tag, u), (-1, 3))
    if np.allclose(xyz, xyz[0]):
        # discrete curve from a .msh: use its mesh nodes in order
        _, coords, _ = gmsh.model.mesh.getNodes(1, curve_tag, includeBoundary=True)
        xyz = np.reshape(coords, (-1, 3))
    if not np.all(np.isfinite(xyz)) or len(xyz) < 2:
        raise ValueError(f"{path}: curve {curve_tag} has no finite points")
    return xyz
