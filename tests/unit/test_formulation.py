"""Formulations behind one protocol on one shared discretisation; the NumPy section frames."""

from dataclasses import replace

import numpy as np
import pytest

from beamfx.analyses.condensed import CondensedModel
from beamfx.analyses.discretisation import discretise
from beamfx.analyses.formulation import BeamFormulation, Formulation
from beamfx.analyses.model import BeamModel
from beamfx.bench._builders import CLAMP, FULL, cantilever, straight
from beamfx.geometry import Arc, Line
from beamfx.geometry.frames import default_reference, frame_from_tangent, section_axes_at
from beamfx.physics import sections
from beamfx.physics.kinematics import Kinematics
from beamfx.spec import Beam, Model, PointLoad, Support

SECTION = sections.rectangle(210e9, 80e9, 7850.0, 0.05, 0.03, nu=0.3)


def _spec(kinematics=FULL):
    return cantilever(straight(1.0), SECTION, 3, 2, force=(0, 0, 1.0), kinematics=kinematics)


@pytest.mark.parametrize(
    "kin", [Kinematics(), Kinematics(finite=False), Kinematics(plane="xz")], ids=str
)
def test_the_beam_model_is_a_beam_formulation(kin):
    model = BeamModel(_spec(kin))
    assert isinstance(model, Formulation) and isinstance(model, BeamFormulation)
    assert model.comm is model.discretisation.comm and model.mesh is model.discretisation.mesh


def test_the_condensed_model_is_a_formulation_only():
    """It solves statics and writes output like the full model, but has no mixed (u, rotation)
    space nor the energy the dynamic and buckling analyses differentiate."""
    model = CondensedModel(_spec())
    assert isinstance(model, Formulation)
    assert not isinstance(model, BeamFormulation)
    assert model.w.function_space is model.W and model.unknowns() == 3 * 7


def test_a_class_missing_a_member_is_no_formulation():
    model = BeamModel(_spec())

    class Partial:
        def __getattr__(self, name):
            if name == "section_parts":
                raise AttributeError(name)
            return getattr(model, name)

    assert not isinstance(Partial(), Formulation)


def test_condensed_and_full_models_share_the_discretisation():
    """Same mesh, named points, section fields and frames whichever formulation is built."""
    spec = replace(_spec(), point_loads=(PointLoad("b:0.5", (0, 1.0, 0)), *_spec().point_loads))
    a = BeamModel(spec, extra_points=["b:0.25"]).discretisation
    b = CondensedModel(spec, extra_points=["b:0.25"]).discretisation
    assert a.named.keys() == b.named.keys() and a.degree == b.degree
    assert np.array_equal(a.mesh.mesh.geometry.x, b.mesh.mesh.geometry.x)
    for field in ("stiffness", "inertia", "reference", "twist"):
        assert np.array_equal(getattr(a, field).x.array, getattr(b, field).x.array), field
    assert a.stiffness_scale == b.stiffness_scale == max(SECTION.EA, SECTION.GA_y, SECTION.GA_z)


def test_section_limits_follow_the_kinematics():
    """Shear-rigid: GA replaced by the penalty; the largest raw EA/GA is kept for the
    quaternion penalty's scale."""
    rigid = discretise(_spec(Kinematics(shear=False)))
    C = rigid.stiffness.x.array.reshape(-1, 6)
    assert np.all(C[:, 1] > SECTION.GA_y) and np.all(C[:, 0] == SECTION.EA)
    assert rigid.stiffness_scale == max(SECTION.EA, SECTION.GA_y, SECTION.GA_z)


def _lam0_at_midpoints(d):
    from dolfinx import fem

    n = d.mesh.mesh.topology.index_map(1).size_local
    expr = fem.Expression(d.Lam0, np.array([[0.5]]))
    return expr.eval(np.arange(n, dtype=np.int32)).reshape(n, 3, 3)


@pytest.mark.parametrize("orientation, twist", [(None, 0.0), ((0.0, 0.4, 1.0), 35.0)])
def test_numpy_frames_are_the_model_frames(orientation, twist):
    """geometry.frames (NumPy: the solid, the checks, trimming) and the model's UFL Λ0 give
    one frame: on a skew line, at every cell's midpoint. The NumPy tangent is a difference
    over ±1e-6 L, so it carries a round-off of about ε|x|/(1e-6 L) ≈ 1e-10."""
    line = Line((0.0, 0.0, 0.0), (0.6, -0.5, 0.3))
    spec = Model(
        beams=(Beam("b", line, SECTION, 4, 2, orientation=orientation, twist_deg=twist),),
        supports=(Support("b:start", CLAMP),),
    )
    d = discretise(spec)
    ufl_frames = _lam0_at_midpoints(d)  # owned cells: the first of the local ones
    s_mid = d.cell_arc_lengths([0.5])[: len(ufl_frames), 0]
    numpy = [section_axes_at(line, s, orientation, twist) for s in s_mid]
    assert np.allclose(ufl_frames, np.reshape(numpy, (-1, 3, 3)), atol=1e-9, rtol=0)


def test_frame_from_tangent():
    t = np.array([0.6, -0.5, 0.3]) / np.linalg.norm([0.6, -0.5, 0.3])
    orientation = np.array([0.0, 0.4, 1.0])
    F = frame_from_tangent(t, orientation)
    assert np.allclose(F.T @ F, np.eye(3), atol=1e-15) and np.isclose(np.linalg.det(F), 1.0)
    assert np.allclose(F[:, 0], t) and abs(F[:, 2] @ orientation) > 0  # e3 leans on it
    assert np.isclose(np.linalg.det(np.column_stack([t, orientation, F[:, 2]])), 0.0)
    turned = frame_from_tangent(t, orientation, twist_deg=90.0)  # e2 -> e3, e3 -> -e2
    assert np.allclose(turned[:, 1], F[:, 2]) and np.allclose(turned[:, 2], -F[:, 1])
    # the default reference: global z, or global x along z
    assert np.allclose(frame_from_tangent(np.array([1.0, 0, 0]))[:, 2], [0, 0, 1])
    assert np.allclose(frame_from_tangent(np.array([0, 0, -1.0]))[:, 2], [1, 0, 0])
    assert np.array_equal(default_reference([[0, 0, 1.0], [0, 1.0, 0]]), [[1, 0, 0], [0, 0, 1]])


def test_section_axes_follow_an_arc():
    arc = Arc((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 0.0), 90.0)
    for s in (0.0, arc.length / 3, arc.length):
        phi = s  # unit radius: the angle is the arc length
        F = section_axes_at(arc, s)
        assert np.allclose(F[:, 0], [-np.sin(phi), np.cos(phi), 0.0], atol=1e-6)
        assert np.allclose(F[:, 2], [0, 0, 1])  # the default reference, normal to the plane
