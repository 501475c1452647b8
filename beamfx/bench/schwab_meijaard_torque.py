r"""Schwab & Meijaard (2009), problem 2.7: a clamped shaft under a tip torque, and the kind of
the torque.

A straight circular shaft (length L, clamped at x = 0) carries a torque M along its axis at
the free end. Adjacent equilibrium (Ziegler 1968): no force acts, so the internal moment is the
tip moment everywhere; with z = v' + i w' (the slope of the bent centre line) and k = M/EI
the bending equations are z' = i k z − i(m_y + i m_z)/EI, z(0) = 0, where (m_y, m_z) are the
components of the tip moment normal to x that the tip rotation ψ = (φ, −w'(L), v'(L))
brings about. They depend on the kind of the torque (:func:`beamfx.physics.energy.moment_work`):

============== =============================== =========================================
kind            (m_y, m_z) / M                  adjacent equilibrium
============== =============================== =========================================
dead (axial)    0                               none: z ≡ 0 for every M
follower        (v'(L), w'(L))                  none: z(L) e^{ikL} = 0
semitangential  ½ (v'(L), w'(L))                e^{ikL} = −1:  M_cr = π EI/L
quasitangential (v'(L), 0), arm along y         cos kL = 0:   M_cr = π EI/(2L)
============== =============================== =========================================

The dead and the follower torque are not conservative (their tangent is unsymmetric); they
have no static critical load, and their instability is kinetic: about the twisted shaft the
(double) bending frequencies split into complex pairs at any torque (flutter), as
:func:`dense_modes` shows. The classical values ignore the twist before buckling, as does the
linear buckling analysis about the undeformed state (:func:`~beamfx.analyses.buckling.
solve_buckling`); at M_cr it is ML/GJ = π(1 + ν) ≈ 4.1 rad for this shaft.
"""

import numpy as np

from ..physics import sections
from ..spec import Beam, Model, PointLoad, Support
from ._builders import CLAMP, straight
from .registry import reference, register
from .schwab_meijaard_eigen import FILE, NU, RHO, SETTINGS, E, EigenCase, G, _buckling_solve, _same

P27 = reference(FILE, "sm27_torque_buckling")
L27 = P27["geometry"]["L"]
S27 = sections.tube(E, G, RHO, P27["section"]["d"], d_inner=0.0, nu=NU)
M_TH_27 = np.pi * S27.EI_y / L27
ARM = (0.0, 1.0, 0.0)  # arm of the quasitangential couple: the forces then act along z
#: M_cr / (π EI/L) of the conservative kinds, from the table of the module doc
CRITICAL = {"semitangential": 1.0, "quasitangential": 0.5}


def shaft(elements, degree, kind, torque=1.0, section=S27):
    """SM 2.7's shaft: clamped at "b:start", tip torque ``torque`` along x of ``kind``."""
    load = PointLoad(
        "b:end",
        moment=(torque, 0.0, 0.0),
        kind=kind,
        arm=ARM if kind == "quasitangential" else None,
    )
    return Model(
        beams=(Beam("b", straight(L27), section, elements, degree),),
        supports=(Support("b:start", CLAMP),),
        point_loads=(load,),
    )


def as_scene_chooses(spec):
    """``spec`` with the formulation a buckling scene of it gets (``[model] formulation =
    "auto"``, :func:`~beamfx.analyses.mixed.choose_formulation`): the displacement form for
    the shaft as it is (stiffness ratio 4e4), the mixed form from 1e8 (EA, GA × 1e4 in the
    stress matrix), where the displacement form's roots drift by round-off (2e-3 at × 1e8)."""
    from dataclasses import replace

    from ..analyses.mixed import choose_formulation

    return replace(spec, formulation=choose_formulation(spec, "buckling")[0])


def _torque(n, p):
    ratios, dofs = {}, 0
    for kind in CRITICAL:
        factors, dofs = _buckling_solve(as_scene_chooses(shaft(n, p, kind)))
        ratios[kind] = factors[0] / M_TH_27
    return ratios, dofs, 0


def _dense(A, free):
    return A.convert("dense").getDenseArray()[np.ix_(free, free)]


def dense_pencil(model):
    """All critical load factors μ of det(K0 + μ K_g) = 0 about the undeformed state, complex
    ones included (SciPy, dense: a small serial model). The same K0 and K_g (stress stiffness
    plus load-stiffness rate) as :func:`~beamfx.analyses.buckling.solve_buckling`."""
    import dolfinx.fem.petsc as fp
    import scipy.linalg
    from dolfinx import fem

    from ..analyses import buckling as bk
    from ..analyses.dofs import constrained_dofs
    from ..solvers.forms import compile_form

    if model.comm.size > 1:
        raise ValueError("dense_pencil is serial: build the model on MPI.COMM_SELF")
    model.reset()
    model.set_load_factor(0.0)
    J_form, F_form = compile_form(model.J), compile_form(model.F)
    dw = bk.path_tangent(model, J_form, F_form)
    w_star = fem.Function(model.W)
    w_star.x.array[:] = model.w.x.array
    S_form = compile_form(bk.stress_stiffness_ufl(model, w_star, dw))
    K = fp.assemble_matrix(J_form, bcs=model.bcs, diagonal=1.0)
    K.assemble()
    Kg = bk.stress_stiffness(model, J_form, S_form)
    free = np.setdiff1d(np.arange(K.getSize()[0]), constrained_dofs(model.bcs))
    mu = scipy.linalg.eigvals(_dense(K, free), -_dense(Kg, free))
    K.destroy()
    Kg.destroy()
    mu = mu[np.isfinite(mu)]
    return mu[np.argsort(np.abs(mu))]


def dense_modes(model, rotary="polar"):
    """All ω² of det(K − ω² M) = 0 about the current state, complex ones included (SciPy,
    dense: a small serial model); K is the (unsymmetric, for non-conservative loads) tangent."""
    import scipy.linalg

    from ..analyses.dofs import constrained_dofs
    from ..analyses.modal import assemble_pair, mass_ufl
    from ..solvers.forms import compile_form

    if model.comm.size > 1:
        raise ValueError("dense_modes is serial: build the model on MPI.COMM_SELF")
    K, M = assemble_pair(compile_form(model.J), compile_form(mass_ufl(model, rotary)), model.bcs)
    free = np.setdiff1d(np.arange(K.getSize()[0]), constrained_dofs(model.bcs))
    lam = scipy.linalg.eigvals(_dense(K, free), _dense(M, free))
    K.destroy()
    M.destroy()
    lam = lam[np.isfinite(lam)]
    return lam[np.argsort(np.abs(lam))]


NOTE = (
    "Clamped circular shaft, tip torque M along its axis; columns M_cr/(pi EI/L) for a "
    "semitangential torque (theory 1, the paper's case) and for a quasitangential one (the "
    "couple of two dead forces on an arm that turns with the section; theory 1/2). "
    "**The kind of the torque decides the problem.** With no force, the internal moment is "
    "the tip moment; its bending part comes from how the tip moment turns with the tip "
    "rotation. A dead (axial) torque does not turn: the slope obeys z' = i (M/EI) z with "
    "z(0) = 0, so there is no adjacent equilibrium at any M. A follower torque turns fully "
    "with the section: none either. Both are non-conservative (unsymmetric tangent): the "
    "linear buckling analysis finds no real root (the discrete pencil has complex roots "
    "only, several times pi EI/L, which do not converge as the mesh is refined: the continuous "
    "one has none), and their instability is "
    "kinetic: about the twisted shaft the double bending frequency splits into a complex "
    "pair at any torque, Im(omega) proportional to M (flutter; tests/convergence/test_torque_buckling.py). "
    "The semitangential torque (potential -M.psi) turns by half the rotation: "
    "exp(iML/EI) = -1, M_cr = pi EI/L. The quasitangential couple turns with the rotation "
    "about its forces' direction only: cos(ML/EI) = 0, M_cr = pi EI/(2L); the mean of the "
    "two couples with crossed arms is the semitangential torque. Both are conservative: with "
    "the torsion made rigid, a modal analysis about the loaded state finds the same critical "
    "torques (the first frequency goes to 0 there). "
    "The mode has no shear force and the shear term is integrated at p Gauss points, so the "
    "rotations are free continuous P_p fields: quadratic elements then reproduce the "
    "paper's BEAMNL column (slopes of C1 cubics, the same space) to its ten digits, and the "
    "error falls as h^(2p). As in the theory, the twist before buckling (ML/GJ = pi (1 + nu) "
    "= 4.1 rad at M_cr) is ignored: the analysis is about the undeformed state. About the "
    'twisted state (about = "current") these two loads change: the semitangential torque is '
    "defined through the total rotation vector and the couple's arm has turned with the twist, "
    "so the critical torque found there differs unless the torsion is (nearly) rigid."
)

register(
    EigenCase(
        "sm27_torque_buckling",
        "Schwab & Meijaard 2009, 2.7",
        "Torque buckling of a clamped shaft: semitangential and quasitangential torque",
        _torque,
        _same,
        CRITICAL,
        1e-6,
        SETTINGS,
        note=NOTE,
        own_model=(
            "its own solver path (the buckling solve called directly for each kind of the "
            "torque), not a scene; the model and its formulation are the ones a buckling scene "
            "gets (full, never trimmed or condensed; the mixed form from a stiffness ratio of "
            "1e8, as_scene_chooses)"
        ),
    )
)
