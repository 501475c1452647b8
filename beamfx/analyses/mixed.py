r"""Which formulation solves a scene: the displacement form or the mixed (Hellinger–Reissner)
one (:mod:`beamfx.physics.mixed`, issue 16).

In the displacement form the tangent holds EA and GA next to EI/L²: its condition number grows
with the stiffness ratio ρ = max(EA, GA)·L²/min(EI) (12 (L/h)² for a solid rectangle) and a
penalty model (shear-rigid, inextensible: ρ ≥ 1e8) sits at the edge of double precision. Buckling
loads and frequencies then keep only about 16 − log10(ρ) − 5 digits (the stress matrix: Euler's
load moves 2e-1 at ρ ≈ 1e10). The mixed form carries the section force as an unknown and the
compliance 1/EA, 1/GA (0 in the rigid limits) instead of EA, GA: its tangent does not grow with
them.

``[model] formulation``: "displacement", "mixed" or "auto" (the default): the mixed form where
the analysis takes it (:data:`MIXED_ANALYSES`), the model is not condensed, and it is
shear-rigid or inextensible (exact constraints instead of the penalty 1e8·EI/L² of
:meth:`~beamfx.physics.sections.Section.with_limits`) or its ρ reaches :data:`RATIO_LIMIT`.
The limit 1e8 is that penalty's ratio, where the displacement form keeps about 1e-5 of an
eigen or buckling answer (it loses about 1e-13·ρ); it lies above every elastic section of the
benchmarks (the stiffest, Mattiasson's, 1e7; a rectangle reaches it at L/h ≈ 2900), so no
elastic model of them changes.
"""

import numpy as np

FORMULATIONS = ("auto", "displacement", "mixed")
#: the analyses that solve the mixed form (its force block has no mass: the eigen solves by
#: shift-and-invert take it; the rotating one keeps the force unknowns out of its quadratic
#: eigen solve, :mod:`beamfx.solvers.eigen_shell`); the transient runs were not tried. The
#: arc length measures the kinematic unknowns only and counts the inertia less the force
#: unknowns (:func:`beamfx.solvers.arclength.inertia_offset`)
MIXED_ANALYSES = ("static", "linear_static", "modal", "buckling", "rotating", "arclength")
#: the stiffness ratio from which "auto" chooses the mixed form (module doc)
RATIO_LIMIT = 1e8


def stiffness_ratio(spec, samples=5):
    """max(EA, GA_y, GA_z)·L² / min(EI_y, EI_z) over the beams of ``spec`` (sampled at
    ``samples`` points along each), the rigid limits of its kinematics applied as penalties
    (what the displacement form would assemble)."""
    from ..physics.matrix_sections import section_matrices, with_limits

    kin, worst = spec.kinematics, 0.0
    # once per section and length: a frame's members share a few sections (the section is
    # kept in the key's value, so its id is not reused)
    done = {}
    for b in spec.beams:
        L = b.curve.length
        if (id(b.section), L) in done:
            continue
        done[id(b.section), L] = b.section
        C, _ = section_matrices(b.section, np.linspace(0.0, L, samples))
        C = with_limits(C, not kin.shear, not kin.stretch, L)
        diag = np.diagonal(C, axis1=1, axis2=2)
        ratio = diag[:, :3].max(axis=1) * L**2 / diag[:, 4:].min(axis=1)
        worst = max(worst, float(ratio.max()))
    return worst


def choose_formulation(spec, analysis, stated="auto", condensed=False):
    """(formulation, why) for the model ``spec`` under the analysis ``analysis``: ``stated``
    unless it is "auto" (module doc).

    Raises:
        ValueError: "mixed" stated for an analysis that does not take it.
    """
    if stated not in FORMULATIONS:
        raise ValueError(f"formulation {stated!r}: one of {list(FORMULATIONS)}")
    if stated == "mixed" and analysis not in MIXED_ANALYSES:
        raise ValueError(
            f"the mixed formulation solves the analyses {list(MIXED_ANALYSES)}, not {analysis!r}"
        )
    if stated != "auto":
        return stated, f"stated: [model] formulation = {stated!r}"
    if condensed:
        return "displacement", "the condensed model solves it"
    if analysis not in MIXED_ANALYSES:
        return "displacement", f"a {analysis} analysis takes the displacement form only"
    ratio = stiffness_ratio(spec)
    kin = spec.kinematics
    if not (kin.shear and kin.stretch):
        limits = " and ".join(
            x for x, on in (("shear-rigid", not kin.shear), ("inextensible", not kin.stretch)) if on
        )
        return "mixed", f"{limits}: exact constraints instead of a penalty (ratio {ratio:.2g})"
    if ratio >= RATIO_LIMIT:
        return "mixed", f"stiffness ratio max(EA, GA)·L²/EI = {ratio:.2g} ≥ {RATIO_LIMIT:g}"
    return "displacement", f"stiffness ratio max(EA, GA)·L²/EI = {ratio:.2g} < {RATIO_LIMIT:g}"


def force_unknowns(model):
    """The section force unknowns of the mixed form (0 in the displacement form): each adds
    one negative eigenvalue to the saddle-point tangent [[A, Bᵀ], [B, −S]] (S ≥ 0, B of full
    rank), so the inertia of the tangent on (u, θ) is the count less this."""
    from .dofs import global_size

    if not getattr(model, "mixed", False):
        return 0
    return global_size(model.W.sub(model.force_index).collapse()[0])


def owned_force_dofs(model):
    """Owned local indices of the section force unknowns (no mass, no gyroscopic terms: the
    massless unknowns of :mod:`beamfx.solvers.eigen_shell`), or None in the displacement
    form."""
    from .dofs import owned_size, subspace_dofs

    if not getattr(model, "mixed", False):
        return None
    dofs = subspace_dofs(model.W, model.force_index)
    return dofs[dofs < owned_size(model.W)]


#: c in the mixed form's quaternion penalty k_p = c·max(EI, GJ)/h_min² (:func:`quaternion_penalty`)
PENALTY_FACTOR = 1e3


def quaternion_penalty(d):
    """The mixed form's quaternion penalty k_p on the discretisation ``d``: its tangent holds
    no EA or GA, and k_p must not either (the displacement form's is 10·max(EA, GA)).
    :data:`PENALTY_FACTOR` times the largest bending or torsion stiffness over the shortest
    element squared, the size of the bending terms on the rotation unknowns.

    With the penalty at the nodes of q (the model's default ``penalty_rule``) the answer moves
    only by the nodal norm drift: R(q) is scale-free pointwise, but the interpolant of
    quaternions whose nodal norms differ turns between the nodes, so the strain energy has a
    gradient in the nodal norms that the penalty balances by a drift ∝ 1/k_p (issue 16: the
    star dome, 1 × P2, static at 60 kN, moves 9.4e-4/c relative, exactly ∝ 1/c from c = 10
    to 1e10; 2 × P2: 1.4e-5/c; a 3D roll-up past 2π, 8 × P3: 2e-9/c). c = 1e3 holds it
    to 9.4e-7 on that coarsest dome (whose discretisation error is 6e-2), 1.4e-8 at 2 × P2,
    far below the discretisation error at every mesh. A larger c costs ∝ c: the scaled
    condition estimate of the tangent (dome 1 × P2: 626 at c = 10, 596 at 1e3, 3.8e4 at
    1e6, the displacement form's 1.4e9; it does not depend on EA, GA) and Newton's round-off
    floor k_p·ε on the quaternion rows: from c = 1e5 the steps end by the floor criterion
    (static dome 31 iterations at c = 10, 33 at 1e3, 59 at 1e6; arc-length dome 33 → 170 at
    1e6), and at c = 1e7 the star dome 4 × P2 with EA, GA ×1e8 ran out of its 300 arc-length
    steps. c = 1e3 is the largest c that costs no iterations. With
    ``penalty_rule="quadrature"`` it holds |q| = 1 at the Gauss points, between the nodes,
    and moves the answer at the discretisation error: there a small k_p is the more accurate
    (45° bend, 8 × P2 tip error 1.3e-5 with 10·EI/h², 1.1e-3 with 10 EA, from a 32 × P4
    reference). The two forms agree to round-off with the same k_p (the model's
    ``k_penalty`` is a Constant). Collective."""
    from mpi4py import MPI

    bend = d.stiffness.x.array.reshape(-1, 6)[:, 3:]  # diagonals, matrix sections too
    top = d.comm.allreduce(float(bend.max()) if len(bend) else 0.0, op=MPI.MAX)
    return PENALTY_FACTOR * top / d.min_cell_length() ** 2
