"""The quaternion penalty ½ k_p (|q|² − 1)² seen only at the nodes of q (``penalty_rule =
"nodal"``): one condition per node, so the penalty fixes the nodal norms and cannot reach the
rotation field between them. With the model's Gauss rule (k + 1 points per element, k nodes of
its own) it holds |q_h| = 1 between the nodes too and the answer moves with k_p (locking).
"""

from dataclasses import replace

import numpy as np
import pytest

from beamfx.analyses.model import BeamModel
from beamfx.analyses.static import solve_static
from beamfx.bench import howcroft_2016 as bend45
from beamfx.bench._builders import arc, cantilever
from beamfx.io import evaluate_points
from beamfx.physics.energy import nodal_rule


def _bend45(elements, degree):
    """The 45° bend under its vertical tip load (bench case bend45_vertical), displacement form."""
    spec = cantilever(arc(bend45.V["geometry"]), bend45.SECTION, elements, degree, (0, 0, bend45.F))
    return replace(spec, formulation="displacement")


def _tip(spec, rule, factor):
    """Tip position and the largest |1 − |q_i|| over the nodes, with k_p = factor × the default."""
    model = BeamModel(spec, penalty_rule=rule)
    model.k_penalty.value = factor * float(model.k_penalty.value)
    solve_static(model, steps=10)
    q = model.w.sub(1).collapse().x.array.reshape(-1, 4)
    drift = float(np.abs(np.linalg.norm(q, axis=1) - 1).max())
    return np.asarray(evaluate_points(model, ["b:end"])["b:end"]["position"]), drift


@pytest.mark.parametrize("degree", [1, 2, 3, 4])
def test_nodal_rule_sits_on_the_nodes(degree):
    """The rule's points are the dof points of the rotation field's element and its weights
    integrate polynomials of degree 2k − 1 exactly (Simpson, Gauss–Lobatto–Legendre)."""
    import ufl

    element = ufl.VectorElement("Lagrange", ufl.interval, degree, dim=4)
    points, weights = nodal_rule(element)
    x = np.asarray(points)[:, 0]
    from ffcx.element_interface import convert_element

    nodes = convert_element(element.sub_elements()[0]).element.points[:, 0]
    assert np.allclose(np.sort(x), np.sort(nodes), atol=1e-14)
    assert min(weights) > 0
    for n in range(2 * degree):
        assert abs(np.dot(weights, x**n) - 1 / (n + 1)) < 1e-14, n


def test_nodal_penalty_does_not_depend_on_k_p():
    """bend45 at 4 × P2, k_p from 1e-2 to 1e2 times its default. Nodal rule: the nodal norms
    drift from 1 by O(1/k_p) and nothing else moves; rescaling the nodes of q by 1 + δ turns
    the interpolated rotation between them by O(δ), so the tip moves by less than the drift
    at the soft end (observed 1.7e-8 of the tip against a drift of 2.4e-6). Gauss rule: the
    tip moves by the locking, observed 8e-3 (bound: more than 1e-4), so the comparison can
    tell the two apart."""
    spec = _bend45(4, 2)
    moved, drift = {}, {}
    for rule in ("nodal", "quadrature"):
        (soft, drift[rule]), (stiff, drift_stiff) = (_tip(spec, rule, f) for f in (1e-2, 1e2))
        moved[rule] = np.linalg.norm(soft - stiff) / np.linalg.norm(stiff)
        if rule == "nodal":  # the norms at the nodes are what the penalty holds: drift ∝ 1/k_p
            assert drift_stiff < 1e-3 * drift[rule], (drift[rule], drift_stiff)
    assert moved["nodal"] < drift["nodal"], (moved, drift)
    assert moved["quadrature"] > 1e-4, moved


def test_default_rule_is_nodal():
    """The model's default is the nodal rule (the Gauss rule of ``dx`` stays on request, for
    the comparison above); an unknown rule is refused."""
    spec = _bend45(1, 2)
    assert BeamModel(spec).penalty_rule == "nodal"
    assert BeamModel(spec, penalty_rule="quadrature").penalty_rule == "quadrature"
    with pytest.raises(ValueError, match="penalty_rule"):
        BeamModel(spec, penalty_rule="gauss")
