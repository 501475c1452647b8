r"""Matrix sections of arbitrary cross-sections, from a finite-element section analysis by
`sectionproperties <https://github.com/robbievanleeuwen/section-properties>`_ (2.0.3, the
newest release that installs beside Debian's numpy 1.24).

Axes: the section axes (y, z) of beamfx (e2, e3 of the beam frame) are sectionproperties'
(x, y); its z axis, out of the drawing, is the beam axis x (both frames right-handed). A
shape is thus drawn as seen from the beam's tip looking back toward its start, y to the
right and z up.

Reference point: the beam's reference line passes through the point ``reference`` of the
shape's coordinates (the centroid unless said otherwise); every offset below is measured from
it. From the analysis (one material: E, G, ρ; ν enters the shear functions):

* A, the centroid c and the second moments about it, I_y = ∫z² dA, I_z = ∫y² dA and the
  product I_yz = ∫yz dA (principal axes: :attr:`ShapeProperties.principal_angle_deg`);
* J, the Saint-Venant torsion constant (FE warping function);
* the shear centre s (elasticity approach, Pilkey 2002) and the shear areas as a 2×2 matrix
  A_s = Δ_s² [[κ_y, κ_yz], [κ_yz, κ_z]]⁻¹ (the shear deformation coefficients; diagonal
  A_sy, A_sz for a section symmetric about y or z).

They map into a 6×6 section (:mod:`~beamfx.physics.matrix_sections`, order (Γ1, Γ2, Γ3, K1,
K2, K3)) by the fibre transformation T(ρ): extension and bending act at the centroid,

  C = T(c)ᵀ blockdiag(EA, 0, 0, 0, E [[I_y, −I_yz], [−I_yz, I_z]]) T(c)
    + T(s)ᵀ blockdiag(0, G A_s, GJ, 0, 0) T(s),

and the mass is ρA at the centroid with the rotary inertia ρ [[I_y + I_z, 0, 0], [0, I_y,
−I_yz], [0, −I_yz, I_z]] about it (:func:`~beamfx.physics.matrix_sections.offset_mass`).
The axial strain of the fibre (0, y, z) is Γ1 + K2 z − K3 y, hence the signs of I_yz.
"""

import time
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .matrix_sections import fibre_transform, offset_mass

_LIBRARY = {
    "primitive_sections": (
        "rectangular_section circular_section elliptical_section triangular_section "
        "cruciform_section"
    ),
    "steel_sections": (
        "circular_hollow_section elliptical_hollow_section rectangular_hollow_section "
        "polygon_hollow_section i_section mono_i_section tapered_flange_i_section "
        "channel_section tapered_flange_channel tee_section angle_section cee_section "
        "zed_section box_girder_section"
    ),
}
#: the built-in shapes by name: sectionproperties' function names
SHAPES = tuple(sorted(n for names in _LIBRARY.values() for n in names.split()))
#: defaults for the number of points on curves (sectionproperties has none)
POINT_DEFAULTS = {"n": 64, "n_r": 8}
#: without a mesh_size, the largest triangle area is the section's area over this
DEFAULT_TRIANGLES = 500


def shape_function(name):
    """The sectionproperties function that builds the shape ``name`` (one of :data:`SHAPES`)."""
    from importlib import import_module

    module = next(m for m, names in _LIBRARY.items() if name in names.split())
    return getattr(import_module(f"sectionproperties.pre.library.{module}"), name)


def shape_parameters(name):
    """{parameter: kind} of a built-in shape: "int" (point counts), "angle" (any finite
    number), "radius" (>= 0) or "length" (> 0), and whether it is required."""
    import inspect

    out = {}
    for p in inspect.signature(shape_function(name)).parameters.values():
        if p.name == "material":
            continue
        if p.annotation is int or p.name in POINT_DEFAULTS or p.name == "n_sides":
            kind = "int"
        elif p.name in ("alpha", "rot"):
            kind = "angle"
        elif p.name.startswith("r"):
            kind = "radius"
        else:
            kind = "length"
        required = p.default is inspect.Parameter.empty and p.name not in POINT_DEFAULTS
        out[p.name] = (kind, required)
    return out


@dataclass(frozen=True)
class ShapeProperties:
    """Geometric properties of a cross-section in the shape's coordinates (section axes y, z;
    module doc). Second moments are about the centroid; ``shear_areas`` is the 2×2 A_s."""

    area: float
    centroid: tuple
    I_y: float
    I_z: float
    I_yz: float
    J: float
    shear_centre: tuple
    shear_areas: tuple  # ((A_yy, A_yz), (A_yz, A_zz))
    elements: int
    seconds: float

    @property
    def principal_angle_deg(self):
        """The direction (degrees from y toward z) of the principal axis about
        which the bending second moment is largest (the strong axis), in [-90, 90)."""
        tensor = np.array([[self.I_z, self.I_yz], [self.I_yz, self.I_y]])  # ∫ [y, z]ᵀ[y, z]
        _, v = np.linalg.eigh(tensor)
        y, z = v[:, 0]  # smallest ∫(a·r)²: the axis of the largest ∫(distance to it)²
        angle = float(np.degrees(np.arctan2(z, y)))
        return (angle + 90.0) % 180.0 - 90.0


def _material(nu):
    from sectionproperties.pre.pre import Material

    return Material("beamfx", 1.0, nu, 1.0, 1.0, "grey")


def _analyse(geometry, mesh_size):
    """ShapeProperties of a sectionproperties Geometry with unit E (ν set by its material)."""
    from sectionproperties.analysis.section import Section

    start = time.perf_counter()
    geometry.create_mesh(mesh_sizes=[mesh_size or geometry.geom.area / DEFAULT_TRIANGLES])
    sec = Section(geometry, time_info=False)
    sec.calculate_geometric_properties()
    sec.calculate_warping_properties()
    p = sec.section_props
    d2 = p.Delta_s**2  # A_s = Δ_s²/κ: back to the coefficients κ, then the 2×2 inverse
    kappa = np.array([[d2 / p.A_sx, d2 / p.A_sxy], [d2 / p.A_sxy, d2 / p.A_sy]])
    As = d2 * np.linalg.inv(kappa)
    values = [p.area, p.ixx_c, p.iyy_c, p.ixy_c, p.j, p.x_se, p.y_se, *As.ravel()]
    if not (np.all(np.isfinite(values)) and p.j > 0 and np.all(np.linalg.eigvalsh(As) > 0)):
        raise ValueError(
            f"the FE section analysis failed on {len(sec.elements)} triangles (J = {p.j:g}, "
            "a singular warping system): try another mesh_size"
        )
    return ShapeProperties(
        area=float(p.area),
        centroid=(float(p.cx), float(p.cy)),
        I_y=float(p.ixx_c),
        I_z=float(p.iyy_c),
        I_yz=float(p.ixy_c),
        J=float(p.j),
        shear_centre=(float(p.x_se + p.cx), float(p.y_se + p.cy)),
        shear_areas=tuple(tuple(float(v) for v in row) for row in As),
        elements=len(sec.elements),
        seconds=time.perf_counter() - start,
    )


@lru_cache(maxsize=64)
def shape_properties(name, params, nu, mesh_size):
    """ShapeProperties of the built-in shape ``name`` with ``params`` (a tuple of (key,
    value) pairs), Poisson's ratio ``nu`` and the largest triangle area ``mesh_size`` (None:
    the area / :data:`DEFAULT_TRIANGLES`); computed once per distinct section. Raises ValueError on a shape it cannot build."""
    try:
        geometry = shape_function(name)(**dict(params), material=_material(nu))
    except Exception as e:  # sectionproperties raises what shapely or its own checks raise
        raise ValueError(f"sectionproperties cannot build it: {e}") from e
    _check_geometry(geometry.geom)
    return _analyse(geometry, mesh_size)


@lru_cache(maxsize=64)
def polygon_properties(points, holes, nu, mesh_size):
    """ShapeProperties of the polygon ``points`` ((y, z) pairs) with the polygonal ``holes``;
    see :func:`shape_properties`. Raises ValueError on an invalid polygon (self-intersecting,
    degenerate, a hole outside)."""
    from sectionproperties.pre.geometry import Geometry
    from shapely.geometry import Polygon
    from shapely.geometry.polygon import orient

    if _on_one_line(points):  # shapely calls it a "Self-intersection"
        raise ValueError(
            "zero area: the points lie on one line; allowed: at least 3 points not on one "
            "line, in order around the section"
        )
    polygon = Polygon(points, holes)
    _check_geometry(polygon)
    return _analyse(Geometry(orient(polygon), material=_material(nu)), mesh_size)


def _on_one_line(points):
    """Whether the points (y, z) span no area: all on one line (or one point)."""
    xy = np.asarray(points, float)
    if len(xy) < 3:
        return True
    sv = np.linalg.svd(xy - xy.mean(axis=0), compute_uv=False)
    return not sv[1] > 1e-12 * max(sv[0], 1e-300)


def _check_geometry(geom):
    from shapely.validation import explain_validity

    if not geom.is_valid:
        raise ValueError(f"not a valid polygon: {explain_validity(geom)}")
    if not geom.area > 0:
        raise ValueError("its area is zero")


def shape_matrices(props, E, G, rho, reference=(0.0, 0.0)):
    """(C, M): the 6×6 stiffness and mass matrices (beamfx order) of a section with the
    properties ``props``, about the point ``reference`` of the shape's coordinates (module
    doc)."""
    c = np.subtract(props.centroid, reference)
    s = np.subtract(props.shear_centre, reference)
    Iy, Iz, Iyz = props.I_y, props.I_z, props.I_yz
    axial = np.zeros((6, 6))
    axial[0, 0] = E * props.area
    axial[4:, 4:] = E * np.array([[Iy, -Iyz], [-Iyz, Iz]])
    shear = np.zeros((6, 6))
    shear[1:3, 1:3] = G * np.array(props.shear_areas)
    shear[3, 3] = G * props.J
    Tc, Ts = fibre_transform(*c), fibre_transform(*s)
    C = Tc.T @ axial @ Tc + Ts.T @ shear @ Ts
    inertia = rho * np.array([[Iy + Iz, 0, 0], [0, Iy, -Iyz], [0, -Iyz, Iz]])
    M = offset_mass(rho * props.area, inertia, tuple(c))
    return 0.5 * (C + C.T), M
