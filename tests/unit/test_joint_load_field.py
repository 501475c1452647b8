"""Dead point loads at joints of more than two elements share one density field
(:meth:`~beamfx.analyses.discretisation.Discretisation.joint_load_density`): the load vector
equals the sum of one weighted term per load (the former form) to round-off, and the form
holds one field however many loads there are."""

import numpy as np
import pytest
import ufl
from mpi4py import MPI

from beamfx.analyses.joints import joint_density
from beamfx.bench.frame_scaling import lattice_scene
from beamfx.physics import energy


def _assemble(form):
    import dolfinx.fem.petsc as fp

    from beamfx.solvers.forms import compile_form

    return fp.assemble_vector(compile_form(form)).array.copy()


@pytest.mark.parametrize("kinematics", ["linear", "finite"])
def test_joint_loads_in_one_field_equal_one_term_per_load(tmp_path, kinematics):
    from beamfx.analyses.discretisation import cell_field
    from beamfx.analyses.planar_condensed import build_model

    scene = lattice_scene(tmp_path, 2, kinematics, "iterative", MPI.COMM_WORLD)
    model = build_model(scene.model, MPI.COMM_WORLD, [], False)
    d, loads = model.discretisation, model.spec.point_loads
    assert len(loads) > 2 and all(d.elements_at(ld.at) > 2 for ld in loads)
    fields = [c for c in model.work.coefficients() if "DG" in str(c.ufl_element())]
    assert len(fields) == 1  # one density for all the loads (no moments: no moment field)
    v_u, v_rot = ufl.split(ufl.TestFunction(model.W))[:2]
    rot = ufl.split(model.w)[1]
    per_load = 0
    for ld in loads:  # the former form: the load's constant times its own weight field
        psi = cell_field(d.mesh.mesh, d.degree, joint_density(d, ld.at))
        F = ufl.as_vector([float(c) for c in ld.force])
        M = ufl.as_vector([0.0, 0.0, 0.0])
        per_load += energy.load_work(model.kin, rot, v_u, v_rot, F, M, "dead") * psi * d.dx
    one, many = _assemble(model.work), _assemble(per_load)
    scale = np.abs(many).max()
    assert scale > 0
    np.testing.assert_allclose(one, many, rtol=0, atol=8 * np.finfo(float).eps * scale)
