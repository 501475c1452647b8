"""What a formulation provides to the analyses, the solvers' glue and the writers.

A formulation turns a :class:`~beamfx.spec.Model` into unknowns and forms on a shared
:class:`~beamfx.analyses.discretisation.Discretisation`. Two protocols name what the rest of
beamfx may use of one (``tests/unit/test_formulation.py`` checks that the analyses use nothing else):

* :class:`Formulation`, what a static solve, the probes and field writers and the runner use:
  :class:`~beamfx.analyses.model.BeamModel` (full or planar) and
  :class:`~beamfx.analyses.condensed.CondensedModel` provide it.
* :class:`BeamFormulation`, a Formulation whose unknowns are the Simo–Reissner displacement
  and rotation fields in one mixed space, with the energy the modal, buckling, transient,
  rotating and arc-length analyses differentiate: :class:`~beamfx.analyses.model.BeamModel`
  provides it; the condensed model (rotations only, static) does not.

The continuum beam (:mod:`beamfx.continuum`) builds on the same discretisation (mesh, end
points, measures) but has its own solves and provides neither protocol: its unknowns (centre
line and two section vectors) have no rotation field for the probes, section writers and beam
analyses to read.
"""

from typing import Protocol, runtime_checkable


@runtime_checkable
class Formulation(Protocol):
    """A discretised beam formulation: unknowns, residual, tangent, supports and output."""

    spec: object
    """The :class:`~beamfx.spec.Model` it discretises."""
    kin: object
    """Its :class:`~beamfx.physics.kinematics.Kinematics` (finite or linear, planar or not,
    shear, stretch)."""
    discretisation: object
    """The :class:`~beamfx.analyses.discretisation.Discretisation`: mesh, named points,
    section fields, reference frames, measures."""
    comm: object
    """MPI communicator (``discretisation.comm``)."""
    mesh: object
    """:class:`~beamfx.geometry.BeamMesh` (``discretisation.mesh``)."""
    degree: int
    """Polynomial degree of the geometry and the fields (``discretisation.degree``)."""
    W: object
    """The function space of the unknowns ``w``."""
    w: object
    """The unknowns (a dolfinx Function on ``W``); the solvers update it in place."""
    F: object
    """UFL residual, linear in the test function of ``W``; zero at equilibrium."""
    J: object
    """UFL tangent: the derivative of ``F`` with respect to ``w``."""
    bcs: list
    """Dirichlet conditions on ``W`` (their values follow :meth:`set_load_factor`)."""
    load_factor: object
    """``fem.Constant`` λ that scales the loads and prescribed values."""
    work: object
    """UFL virtual work of the loads at λ = 1 when ``F`` = F_int − λ ``work``, else None (no
    loads, or a residual that is not affine in λ)."""
    coupling: object
    """A non-local tangent term the forms cannot hold, or None
    (:class:`~beamfx.solvers.NewtonSolver` ``coupling``)."""

    def unknowns(self) -> int:
        """Global number of unknowns."""

    def reset(self) -> None:
        """Put ``w`` back to the undeformed state."""

    def set_load_factor(self, lam: float) -> None:
        """Set λ: loads and prescribed values scale with it."""

    def check_state(self) -> None:
        """Raise if the converged state left the formulation's range of validity."""

    def sync(self) -> None:
        """Bring fields derived from ``w`` up to date before output (collective)."""

    def section_parts(self) -> tuple:
        """(X, u, rotation output, Λ0, N, M) as UFL, for
        :func:`beamfx.io._sections.section_expression`: reference position, displacement
        (global axes), quaternion or rotation vector, reference frame, section force and
        moment (section axes)."""


@runtime_checkable
class BeamFormulation(Formulation, Protocol):
    """A :class:`Formulation` with the Simo–Reissner unknowns: ``W`` is the mixed space
    (displacement P_k, rotation P_k), ``W.sub(0)`` the displacement and ``W.sub(1)`` the
    rotation (quaternion, rotation vector or planar angle, as ``kin`` says). The mixed
    (Hellinger–Reissner) formulation adds the section force DG_{k−1} as the last subspace,
    ``W.sub(force_index)`` (:mod:`beamfx.physics.mixed`); it has no mass."""

    mixed: bool
    """Whether the section force is an unknown (the Hellinger–Reissner form)."""
    force_index: object
    """The subspace of the section force in ``W`` (None in the displacement form)."""

    def section_force(self, w=None):
        """UFL section force (section axes) of ``w`` (default ``self.w``); mixed form only."""

    Pi: object
    """UFL internal energy (strain energy, springs, penalties) of ``w``."""
    Pi_ground: object
    """UFL energy of the springs to ground and of the supports in local axes (stiff penalty
    springs), part of ``Pi``; None if there are none. Their forces are support reactions
    (:mod:`beamfx.analyses.reactions`)."""
    k_penalty: object
    """``fem.Constant`` of the quaternion unit-norm penalty (part of ``Pi`` for finite
    spatial kinematics)."""

    def penalty_measure(self):
        """UFL measure on which ``Pi`` integrates the quaternion penalty (the nodes of q by
        default): every other form of the penalty (the buckling penalty tangent) uses it."""

    strains: tuple
    """UFL (Γ, K) of ``w``, section axes (with the members' rotation at released ends), as in
    the strain energy."""
    penalty_motion: list
    """(UFL ∂Π/∂f, its ``fem.Constant`` f(t)) of each part of a support in local axes that a
    history moves: the support's work is ∫ ∂Π/∂f df."""

    def set_time(self, t: float) -> None:
        """Time of a transient: loads and supports with a history take their values at t."""


#: members of each protocol, for the checks of what the analyses use (tests/unit/test_formulation.py)
FORMULATION_MEMBERS = frozenset(
    name for name in vars(Formulation) if not name.startswith("_")
) | frozenset(Formulation.__annotations__)
BEAM_FORMULATION_MEMBERS = (
    FORMULATION_MEMBERS
    | frozenset(name for name in vars(BeamFormulation) if not name.startswith("_"))
    | frozenset(BeamFormulation.__annotations__)
)
