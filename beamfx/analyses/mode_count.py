"""How many finite eigenvalues a model can have: the most modes a modal or buckling analysis
can find, checked against ``[analysis] modes`` before any solve.

A constrained dof is an identity row of K and a zero row of M (or K_g): its eigenvalue is
infinite (:mod:`beamfx.solvers.eigen`), and so is that of every free unknown without mass (the
quaternion's fourth component, the mixed form's section force, the rotations without rotary
inertia). Shift-and-invert converges the finite eigenvalues only: asking SLEPc for more than
there are ends in a breakdown (288 of 340 pairs on a clamped 16 x P3 cantilever of 343
unknowns: 48 free nodes x 6 dofs with mass). The count here is

    (nodes) x (dofs per node with mass) − (those fixed by Dirichlet supports)

with the nodes of the mesh the model builder makes, counted when the scene is read
(:func:`spec_nodes`: the vertices at named points and joints, shared vertices merged, as
:func:`beamfx.geometry.mesh.build_mesh` does) and again on the built mesh (:func:`mesh_nodes`).
It is exact for a clamped beam, and an upper bound where it cannot know which dofs have mass
(a single rotation fixed with ``rotary_inertia = "polar"``): so a refusal never refuses a
scene the solver could have taken.
"""

from typing import NamedTuple

from ..spec import DOF_NAMES, resolve_point
from ..spec.model import beam_index
from .checks import named_breaks
from .dofs import OUT_OF_PLANE

#: rotational dofs per node with rotary inertia, per ``rotary_inertia`` of a modal analysis
ROTARY_DOFS = {"full": 3, "polar": 1, "none": 0}


def spec_nodes(spec, points=()):
    """Nodes of the mesh the model builder makes of ``spec`` (a vertex at every named point,
    ``points`` too: the probes; joined beams sharing one), counted without building it."""
    from ..geometry import BeamSpec
    from ..geometry.mesh import node_count

    breaks = named_breaks(spec, points)[1]
    specs = [
        BeamSpec(b.name, b.curve, b.elements, tuple(breaks[i])) for i, b in enumerate(spec.beams)
    ]
    return node_count(specs, max(b.degree for b in spec.beams))


def _fixed(spec):
    """{point coordinates (rounded): dof names fixed there} of the Dirichlet supports (global
    axes; a support in local axes is a stiff spring, which leaves its dofs unknowns)."""
    index, out = beam_index(spec), {}
    for s in spec.supports:
        if s.axes != "global":
            continue
        try:
            x = resolve_point(spec, s.at, index)[2]
        except ValueError:  # a bad point: the scene reader names it (its own check)
            continue
        out.setdefault(tuple(round(float(c), 9) for c in x), set()).update(s.fix)
    return out


class Count(NamedTuple):
    """The free dofs with a finite eigenvalue: ``nodes`` x ``per_node`` + ``extra`` − ``fixed``."""

    nodes: int
    per_node: int  # nodal dofs (with mass, for a modal analysis)
    extra: int  # a point mass's rotations, a released joint's
    fixed: int  # of those, fixed by Dirichlet supports

    @property
    def total(self) -> int:
        """The most finite eigenvalues."""
        return max(self.nodes * self.per_node + self.extra - self.fixed, 0)


def count_dofs(spec, nodes, rotary=None):
    """The :class:`Count` of the model ``spec`` (:class:`~beamfx.spec.Model`) with ``nodes``
    nodes (:func:`spec_nodes`, :func:`mesh_nodes`): its nodal dofs with mass less the fixed
    ones.

    ``rotary``: a modal analysis's ``rotary_inertia`` (:data:`ROTARY_DOFS`; a point mass with
    rotary inertia gives its node all its rotations); None: every nodal dof counts (the
    geometric stiffness of buckling reaches translations and rotations alike). Where only some
    rotations have mass, fixed rotations count only where all are fixed (which of them have
    mass depends on the section axes: the bound stays an upper one).
    """
    plane = spec.kinematics.plane
    names = DOF_NAMES if not plane else tuple(n for n in DOF_NAMES if n not in OUT_OF_PLANE[plane])
    turns = 1 if plane else 3  # rotations per node
    if rotary is None or rotary == "full":
        moving = turns
    else:  # the planar model's rotation is about a bending axis: "polar" gives it no mass
        moving = 0 if plane else ROTARY_DOFS[rotary]
    counted = set(names[: len(names) - turns]) | (set(names) if moving == turns else set())
    spun = {m.at for m in spec.point_masses if any(any(r) for r in m.inertia)}
    extra = len(spun) * (turns - moving)
    if rotary is None:  # a released joint's own rotations (no mass: modal leaves them out)
        extra += sum(len(r.released) for r in spec.releases)
    rotations = set(names[len(names) - turns :])
    fixed = sum(
        len(at & counted) + (moving if moving < turns and rotations <= at else 0)
        for at in _fixed(spec).values()
    )
    return Count(nodes, len(names) - turns + moving, extra, fixed)


def free_dofs_of(spec, nodes, rotary=None):
    """The most finite eigenvalues of ``spec`` (:func:`count_dofs`)."""
    return count_dofs(spec, nodes, rotary).total


def modes_problem(spec, modes, what, nodes, rotary=None):
    """Why ``modes`` is too many for ``spec`` with ``nodes`` nodes (a message for
    ``[analysis] modes``), or None. ``what``: the analysis's name."""
    c = count_dofs(spec, nodes, rotary)
    if modes <= c.total:
        return None
    kind = f"dofs with mass (rotary_inertia = {rotary!r})" if rotary is not None else "dofs"
    extra = f" + {c.extra}" if c.extra else ""
    return (
        f"= {modes}: more than a {what} analysis can find: the model has {c.total} free dofs "
        f"with a finite eigenvalue ({c.nodes} nodes x {c.per_node} {kind}{extra} − {c.fixed} "
        f"fixed by the supports); allowed: an integer in [1, {c.total}] (or refine the mesh)"
    )


def mesh_nodes(model):
    """Nodes of a built formulation's mesh: its displacement dofs over the ranks, per node."""
    from .dofs import global_size

    V = model.W.sub(0).collapse()[0]
    return global_size(V) // V.dofmap.index_map_bs


def check_modes(model, spec, modes, what, file, rotary=None):
    """Raise a ValueError naming ``analysis.modes`` of ``file`` if the built ``model`` of
    ``spec`` has fewer free dofs with a finite eigenvalue than ``modes`` (before any solve;
    the count on reading is an upper one: joined beams share nodes)."""
    problem = modes_problem(spec, modes, what, mesh_nodes(model), rotary)
    if problem:
        raise ValueError(f"{file}: analysis.modes {problem}")


__all__ = [
    "ROTARY_DOFS",
    "Count",
    "check_modes",
    "count_dofs",
    "free_dofs_of",
    "mesh_nodes",
    "modes_problem",
    "spec_nodes",
]
