"""Section properties of sectionproperties' FE analysis (beamfx.physics.shape_sections) against
closed forms and thin-walled theory, and their mapping into 6×6 matrices.

The FE warping solution minimises the warping energy over a subspace, so the FE torsion
constant bounds the exact one from above and decreases under refinement (checked). Each
solve takes 1-5 s (pure-Python element loops of sectionproperties 2.0.3).
"""

import math

import numpy as np
import pytest

pytest.importorskip("sectionproperties")

from beamfx.physics import matrix_sections as ms
from beamfx.physics import shape_sections as ss
from beamfx.physics.sections import saint_venant_rectangle

NU = 0.3
B, D, T = 0.1, 0.2, 0.005  # I and channel: width, depth, wall (t/b = 0.05)


def _thin_walled(name):
    p = {"b": B, "d": D, "t_f": T, "t_w": T, "r": 0.0, "n_r": 1}
    area = 2 * B * T + (D - 2 * T) * T
    return ss.shape_properties(name, tuple(sorted(p.items())), NU, area / 250)


def test_rectangle_against_closed_forms_and_the_saint_venant_series():
    b, d = 0.05, 0.1  # b along y, d along z
    params = (("b", b), ("d", d))
    coarse, fine = (
        ss.shape_properties("rectangular_section", params, NU, m) for m in (5e-5, 1.25e-5)
    )
    assert coarse.area == pytest.approx(b * d, rel=1e-12)
    assert fine.I_y == pytest.approx(b * d**3 / 12, rel=1e-12)  # ∫z² dA
    assert fine.I_z == pytest.approx(d * b**3 / 12, rel=1e-12)
    assert abs(fine.I_yz) < 1e-12 * fine.I_y
    assert np.allclose(fine.centroid, (b / 2, d / 2), rtol=1e-12)
    exact = saint_venant_rectangle(d, b)  # Timoshenko & Goodier's series (50 terms)
    errors = [p.J / exact - 1 for p in (coarse, fine)]
    # an upper bound that converges at least as h² (h halves: error / 4); measured about
    # h^3.5: 3.4e-4 on 159 triangles, 2.9e-5 on 627
    assert 0 <= errors[1] < errors[0] / 4, errors
    assert errors[1] < 1e-4, errors
    assert abs(fine.principal_angle_deg) < 1e-6  # strong axis: y (d > b)


def test_circle_of_64_sides():
    n, R = 64, 0.05
    p = ss.shape_properties("circular_section", (("d", 2 * R), ("n", n)), NU, 1e-5)
    a = 2 * math.pi / n
    area = n / 2 * R**2 * math.sin(a)  # the regular 64-gon, exactly
    polar = n * R**4 * math.sin(a) * (2 + math.cos(a)) / 12
    assert p.area == pytest.approx(area, rel=1e-12)
    assert p.I_y + p.I_z == pytest.approx(polar, rel=1e-12)
    assert p.I_y == pytest.approx(p.I_z, rel=1e-12) and abs(p.I_yz) < 1e-12 * p.I_y
    # J of a circle is its polar moment; the polygon (I_p 3.2e-3 = a²/3 below the circle's)
    # warps only near its corners, O(a³): 2e-3 at n = 16 (measured), some 3e-5 at n = 64. A mesh
    # whose boundary edges are the sides cannot see it (the warping loads of neighbouring
    # sides cancel at their common node): J = I_p to 1e-12 here. So J is the polygon's I_p
    # to 1e-4, and the circle's to a²/3
    assert p.J == pytest.approx(polar, rel=1e-4)
    assert p.J == pytest.approx(math.pi * R**4 / 2, rel=a**2 / 3 * 1.01)
    # energy shear coefficient of the circle (exact elasticity solution, Renton 1991)
    k = 6 * (1 + NU) ** 2 / (7 + 14 * NU + 8 * NU**2)
    assert p.shear_areas[0][0] == pytest.approx(k * p.area, rel=a**2 / 3)
    assert p.shear_areas[1][1] == pytest.approx(k * p.area, rel=a**2 / 3)


def test_i_section_torsion_against_the_thin_walled_estimate():
    p = _thin_walled("i_section")
    thin = (2 * B * T**3 + (D - T) * T**3) / 3  # Σ b t³/3 on the centre lines
    # thin-walled theory is accurate to O(t/b): the free-end correction alone (−0.21 t⁴ per
    # flange tip) is −3 % here, the junctions add about as much; measured −0.1 %
    assert p.J == pytest.approx(thin, rel=T / B)
    assert np.allclose(p.shear_centre, p.centroid, atol=1e-5 * D)  # doubly symmetric


def test_channel_shear_centre_against_the_thin_walled_formula():
    p = _thin_walled("channel_section")
    h, b = D - T, B - T / 2  # centre-line depth and flange width
    e = 3 * b**2 * T / (6 * b * T + h * T)  # behind the web's centre line (Young & Budynas)
    # sectionproperties' channel: web at y in [0, t_w], flanges toward +y; the shear centre
    # lies on the far side of the web. Tolerance: thin-walled accuracy O(t/b), taken as
    # t/(2b) = 2.5 %; a datum at the web's face instead of its centre line is 7 % off.
    assert p.shear_centre[0] == pytest.approx(T / 2 - e, rel=T / (2 * B))
    assert p.shear_centre[1] == pytest.approx(D / 2, rel=1e-5)
    thin = (2 * b * T**3 + h * T**3) / 3
    assert p.J == pytest.approx(thin, rel=T / B)
    # zero by the symmetry about z = d/2, up to the triangle mesh's asymmetry (measured 7e-5)
    assert abs(p.shear_areas[0][1]) < 1e-3 * p.shear_areas[0][0]


def test_matrices_about_centroid_shear_centre_and_any_point():
    p = _thin_walled("channel_section")
    E, G, rho = 210e9, 210e9 / 2.6, 7850.0
    C, M = ss.shape_matrices(p, E, G, rho, p.centroid)
    assert C[0, 0] == pytest.approx(E * p.area) and C[3, 3] > G * p.J  # GJ + GA Δy² here
    assert np.allclose(C[0, 4:], 0.0, atol=1e-9 * C[0, 0])  # extension-bending: none
    assert C[2, 3] == pytest.approx(G * p.shear_areas[1][1] * (p.shear_centre[0] - p.centroid[0]))
    ms.check_stiffness(C)
    ms.check_mass(M)
    Cs, _ = ss.shape_matrices(p, E, G, rho, p.shear_centre)
    assert Cs[3, 3] == pytest.approx(G * p.J, rel=1e-12)
    assert np.allclose(Cs[3, :3], 0.0, atol=1e-12 * Cs[0, 0])  # no shear-torsion coupling
    r = np.array([0.03, -0.02])  # any point: the same section seen from elsewhere
    Cr, Mr = ss.shape_matrices(p, E, G, rho, tuple(r + p.centroid))
    T = ms.fibre_transform(*(np.array(p.centroid) - (r + p.centroid)))
    assert np.allclose(Cr, T.T @ C @ T, rtol=1e-12, atol=1e-9 * C.max())
    assert Mr[0, 0] == pytest.approx(rho * p.area) and Mr[3, 3] == pytest.approx(
        rho * (p.I_y + p.I_z + p.area * (r @ r))
    )
