r"""Support reactions: the force and moment that each support (and spring to ground) exerts
on the structure, in global axes, and their balance with the applied loads.

**From the residual, not from the section resultants.** At equilibrium the assembled residual
F = F_int − λ f_ext vanishes at the free dofs; at a dof held by a Dirichlet condition it is the
force that holds it, r = F_int − λ f_ext (the solvers replace those rows, so it is assembled
here without the conditions). The discrete rigid-body motions lie in the finite-element space
(isoparametric geometry, the quaternion map q ↦ ½ (0, ω) ⊗ q is linear in q) and leave the
strain energy and the quaternion penalty unchanged, so F_int · Φ_rigid = 0 holds to round-off:
the reactions balance the loads as exactly as Newton converged. The stress resultants N, M at
an end section would not: they are recovered from Gauss points, miss the loads on the end
element, and a support joining several members would need a sum over members.

Rotation unknowns are turned into moments by the rigid rotation they take part in: for a
quaternion node with residual r_q (4), the moment m satisfies m · ω = r_q · δq for
δq = ½ (0, ω) ⊗ q, so m = ½ G(q)ᵀ r_q with G(q) = [−vᵀ; q0 I − hat(v)]; a rotation vector's
residual is its moment already, and the planar angle's is the moment about the plane normal.
The balance check sums every nodal load by the same rigid motions (about the global origin, at
the current positions for finite kinematics, the reference ones for linear), so follower and
distributed loads and gravity enter as the forms state them.

Supports in local axes and springs to ground are penalty springs in the energy
(``Pi_ground``): their reaction is the spring force, minus its energy gradient.

A transient reuses the per-point recovery on its step's residual, which holds the inertia
forces too (:mod:`beamfx.analyses.transient_reactions`).

Everything is MPI-correct by construction: vectors are assembled with the reverse scatter, each
rank sums its owned dofs, and the sums are reduced.
"""

import weakref
from functools import partial
from typing import NamedTuple

import numpy as np
import ufl
from mpi4py import MPI

from ..spec import DOF_NAMES
from . import condensed_reactions as condensed_parts
from .checks import model_size
from .dofs import constrained_dofs, owned_size


class Reaction(NamedTuple):
    """The reaction at a point (global axes): ``force``, ``moment`` about the point, and the
    point's ``position`` (current for finite kinematics)."""

    force: list
    moment: list
    position: list


class Balance(NamedTuple):
    """Σ reactions + Σ applied loads (forces, and moments about the origin), relative to the
    load scale: Σ|f| over the nodes, and Σ(|x||f| + |m|) for the moments."""

    force: float
    moment: float
    applied_force: list
    applied_moment: list


def imbalance(residual, f_scale, m_scale, reactions, length):
    """``(|ΣF|/scale, |ΣM|/scale)`` of the sums ``residual`` (force, moment about the origin)
    of the reactions and loads. The scales are the loads' (``f_scale`` Σ|f|, ``m_scale``
    Σ(|x||f| + |m|)), each at least the other's over (or times) the model's ``length``: an
    end moment alone, or a force at the origin, has no force (moment) scale of its own. With
    no loads (the supports' motion only), the reactions' own Σ|force| and Σ|moment|; 0 where
    every scale is zero."""
    if f_scale == 0.0 and m_scale == 0.0:
        f_scale = sum(float(np.linalg.norm(r.force)) for r in reactions.values())
        m_scale = sum(float(np.linalg.norm(r.moment)) for r in reactions.values())
    f_ref, m_ref = max(f_scale, m_scale / length), max(m_scale, f_scale * length)
    force, moment = (float(np.linalg.norm(part)) for part in (residual[:3], residual[3:6]))
    return (force / f_ref if f_ref > 0 else 0.0, moment / m_ref if m_ref > 0 else 0.0)


class _Layout(NamedTuple):
    """Owned nodes of the displacement and rotation subspaces as rows of ``W`` dofs."""

    u: np.ndarray  # (n, displacement comps) W dof indices
    axes: list  # global axis of each displacement component
    X: np.ndarray  # (n, 3) reference position of each displacement node
    q: np.ndarray  # (m, rotation comps) W dof indices
    normal: np.ndarray | None = None  # a planar model's normal (global axes)


def _layout(model):
    """Owned rows of the displacement and rotation nodes (a node's dofs share their owner)."""
    owned = owned_size(model.W)
    rows = []
    for sub in (0, 1):
        V, dofs = model.W.sub(sub).collapse()
        n = model.kin.displacement_size if sub == 0 else model.kin.rotation_size
        dofs = np.asarray(dofs).reshape(-1, n)
        keep = dofs[:, 0] < owned
        rows.append((dofs[keep], V.tabulate_dof_coordinates()[keep] if sub == 0 else None))
    kin = model.kin
    axes = [DOF_NAMES.index(name) for name, sub, _ in kin.dofs() if sub == 0]
    normal = np.eye(3)[DOF_NAMES.index(kin.dofs()[2][0]) - 3] if kin.plane else None
    return _Layout(rows[0][0], axes, rows[0][1], rows[1][0], normal)


def _cross(a, b):
    """The cross product row by row of (n, 3) arrays (np.cross costs tens of µs a call)."""
    a0, a1, a2, b0, b1, b2 = a[:, 0], a[:, 1], a[:, 2], b[:, 0], b[:, 1], b[:, 2]
    return np.column_stack((a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0))


def _moment_about(moment, x, force):
    """``moment - x × force`` of three-vectors, as a list: :func:`_cross`'s products and
    differences in plain floats (the same IEEE operations, without its arrays)."""
    (m0, m1, m2), (x0, x1, x2), (f0, f1, f2) = moment.tolist(), x.tolist(), force.tolist()
    return [m0 - (x1 * f2 - x2 * f1), m1 - (x2 * f0 - x0 * f2), m2 - (x0 * f1 - x1 * f0)]


def _nodal_moments(model, layout, r):
    """Moment (global axes) of the rotation residual rows ``r`` at each owned rotation node."""
    kin = model.kin
    if kin.plane:
        return r[:, :1] * layout.normal
    if not kin.finite:
        return r
    q = model.w.x.array[layout.q]
    q0, v, r0, rv = q[:, :1], q[:, 1:], r[:, :1], r[:, 1:]
    return 0.5 * (q0 * rv - r0 * v + _cross(v, rv))


def positions(model, layout):
    """Positions of the owned displacement nodes: current for finite kinematics."""
    x = np.array(layout.X)
    if model.kin.finite:
        x[:, layout.axes] += model.w.x.array[layout.u]
    return x


def local_resultant(model, layout, values, mask=None, x=None):
    """This rank's part of :func:`resultant` (8 numbers), all dofs if ``mask`` is None, ``x``
    the nodes' :func:`positions` if known."""
    picked = values if mask is None else np.where(mask, values, 0.0)
    f = np.zeros((len(layout.u), 3))
    f[:, layout.axes] = picked[layout.u]
    x = positions(model, layout) if x is None else x
    m = _nodal_moments(model, layout, picked[layout.q])
    size = np.sqrt((f * f).sum(1))
    local = np.empty(8)
    local[:3] = f.sum(0)
    local[3:6] = _cross(x, f).sum(0) + m.sum(0)
    local[6] = size.sum()
    local[7] = (np.sqrt((x * x).sum(1)) * size).sum() + np.sqrt((m * m).sum(1)).sum()
    return local


def resultant(model, layout, values, mask):
    """Σ force and Σ moment about the origin of the nodal ``values`` (an array on ``W``,
    ghosts included) at the dofs where ``mask`` is true, with the scales of :class:`Balance`:
    (force, moment, force scale, moment scale), summed over ranks. Collective."""
    total = model.comm.allreduce(local_resultant(model, layout, values, mask), op=MPI.SUM)
    return total[:3], total[3:6], total[6], total[7]


def _vertex_dofs(model, at):
    """Local W dofs (ghosts included) of every unknown at the named point ``at``."""
    from dolfinx import fem

    verts = model.mesh.point_tags.find(model.mesh.points[at][0])
    sizes = (model.kin.displacement_size, model.kin.rotation_size)
    dofs = [
        fem.locate_dofs_topological(model.W.sub(sub).sub(comp), 0, verts)
        for sub in (0, 1)
        for comp in range(sizes[sub])
    ]
    return np.concatenate(dofs).astype(np.int64)


class ReactionRecovery:
    """Reactions of a :class:`~beamfx.analyses.formulation.BeamFormulation` at its current
    state (:meth:`__call__`). Built once per model: two forms compiled (the residual, and the
    gradient of ``Pi_ground`` if the model has springs or local-axes supports)."""

    def __init__(self, model):
        from ..solvers.forms import compile_form

        self.model, self.layout = model, _layout(model)
        self.length = model_size(model.spec)  # the balance's length scale
        self._F = self.b = None  # compiled at first use (a transient uses its own residual)
        self.ground = None
        if model.Pi_ground is not None:
            test = ufl.TestFunction(model.W)
            self.ground = compile_form(ufl.derivative(model.Pi_ground, model.w, test))
        n = len(model.w.x.array)
        held = np.zeros(n, bool)
        held[constrained_dofs(model.bcs)] = True
        self.points = {}  # at -> (Dirichlet mask, spring mask)
        self.dofs = {}  # at -> its dofs (located once: 2 ms a call on 16 cells)
        self.rows = {}  # at -> its row of layout.u on the rank that owns it (else none)
        self.near = {}  # at -> (the layout of its nodes only, their rows of layout.u)
        spring_points = [s.at for s in model.spec.springs]
        spring_points += [s.at for s in model.spec.supports if s.axes == "local"]
        for at in dict.fromkeys([s.at for s in model.spec.supports] + spring_points):
            at_point = np.zeros(n, bool)
            self.dofs[at] = _vertex_dofs(model, at)
            self.rows[at] = np.flatnonzero(np.isin(self.layout.u[:, 0], self.dofs[at]))[:1]
            at_point[self.dofs[at]] = True
            self.near[at] = _near(self.layout, self.dofs[at])
            ground = at_point if at in spring_points else np.zeros(n, bool)
            self.points[at] = (at_point & held, ground)

    @property
    def F(self):
        """The model's residual, compiled at first use."""
        if self._F is None:
            from ..solvers.forms import compile_form

            self._F = compile_form(self.model.F)
        return self._F

    def assemble(self, form, load_factor=None):
        """``form`` (a linear form on ``W``) assembled with no Dirichlet rows, ghosts
        updated; a copy of the array."""
        import dolfinx.fem.petsc as fp
        from petsc4py import PETSc

        if self.b is None:
            self.b = fp.create_vector(form)
        if load_factor is not None:
            self.model.load_factor.value = load_factor
        with self.b.localForm() as local:
            local.set(0.0)
        fp.assemble_vector(self.b, form)
        self.b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        self.b.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        with self.b.localForm() as local:
            return np.array(local.array)

    def applied(self):
        """The nodal load vector λ f_ext at the current state, F(λ=0) − F(λ=1) times λ."""
        lam = float(self.model.load_factor.value)
        try:
            f = self.assemble(self.F, 0.0) - self.assemble(self.F, 1.0)
        finally:
            self.model.load_factor.value = lam
        return lam * f

    def __call__(self):
        """``({point: Reaction}, Balance)`` at the current state. Collective."""
        load = self.applied()
        out, total, [applied] = self.at_points(self.assemble(self.F), [load])
        force, moment = applied[:3], applied[3:6]
        ratios = imbalance(total[:6] + applied[:6], applied[6], applied[7], out, self.length)
        balance = Balance(*ratios, force.tolist(), moment.tolist())
        return out, balance

    def at_points(self, residual, extra=()):
        """``({point: Reaction}, Σ (force, moment about the origin), [resultant of each of
        extra])`` of ``residual`` (an array on ``W``, owned entries at least; its held rows
        are the reactions) and of the springs at the current state; ``extra``: arrays whose
        :func:`resultant` over all dofs (8 numbers) is reduced in the same call. Collective:
        one reduction."""
        model, layout = self.model, self.layout
        spring = -self.assemble(self.ground) if self.ground is not None else None
        x = positions(model, layout)
        parts = []
        for at, (held, ground) in self.points.items():
            near, u_rows = self.near[at]  # (the other nodes add zeros)
            parts.append(local_resultant(model, near, residual, held, x[u_rows]))
            if spring is not None and ground.any():
                parts.append(local_resultant(model, near, spring, ground, x[u_rows]))
            else:  # (every rank adds its part: the reduction is collective)
                parts.append(np.zeros(8))
            rows = self.rows[at]
            parts.append(np.append(x[rows].sum(0), len(rows)))
        parts += [local_resultant(model, layout, v, None, x) for v in extra]
        total = np.concatenate(parts or [np.zeros(0)])
        if model.comm.size > 1:  # (on one rank the reduction is the identity: 50 µs saved)
            total = model.comm.allreduce(total, op=MPI.SUM)
        out, sums = {}, np.zeros(6)
        for i, at in enumerate(self.points):
            held, ground = total[20 * i : 20 * i + 8], total[20 * i + 8 : 20 * i + 16]
            p = total[20 * i + 16 : 20 * i + 20]  # Σ position, count (one rank has it)
            force, moment = held[:3] + ground[:3], held[3:6] + ground[3:6]
            sums[:3] += force
            sums[3:] += moment
            xp = p[:3] / max(p[3], 1)
            out[at] = Reaction(force.tolist(), _moment_about(moment, xp, force), xp.tolist())
        k = 20 * len(self.points)
        return out, sums, [total[k + 8 * j : k + 8 * j + 8] for j in range(len(extra))]


def _near(layout, dofs):
    """The :class:`_Layout` of the owned nodes among ``dofs`` (a point's), and their rows of
    ``layout.u``: a point's resultant over them is its resultant over all nodes."""
    u_rows = np.flatnonzero(np.isin(layout.u, dofs).any(1))
    q_rows = np.flatnonzero(np.isin(layout.q, dofs).any(1))
    u, X, q = layout.u[u_rows], layout.X[u_rows], layout.q[q_rows]
    near = _Layout(u, layout.axes, X, q, layout.normal)
    return near, u_rows


def load_balance(reactions, applied, f_scale, m_scale, length):
    """:class:`Balance` of ``reactions`` ({at: Reaction}) with the loads of resultant
    ``applied`` (6: Σ force, Σ moment about the origin) and scales ``f_scale``, ``m_scale``:
    |Σ reactions + Σ loads| relative to the scales (:func:`imbalance`)."""
    total = np.array(applied, float)
    for r in reactions.values():
        force = np.asarray(r.force, float)
        total[:3] += force
        total[3:] += np.asarray(r.moment, float) + np.cross(r.position, force)
    ratios = imbalance(total, f_scale, m_scale, reactions, length)
    return Balance(*ratios, list(map(float, applied[:3])), list(map(float, applied[3:6])))


def condensed_reactions(model, evaluate, cache):
    """``({support: Reaction}, Balance, gap)`` of the statically condensed cantilever at its
    current state (:mod:`~beamfx.analyses.condensed_reactions`): the clamp's reaction (the
    section force, the moment of the loads about it) and its balance with the point loads,
    taken from the model's load data at the current load factor, rotations and positions;
    ``gap``: |recovered section moment − that moment| over the moment scale.
    ``evaluate(names)``: the probe values of the points (collective); ``cache``: a dict kept
    across calls for the load points' dofs. Collective."""
    values = evaluate(condensed_parts.points(model))
    loads = condensed_parts.applied_loads(model, cache)
    parts, recovered = condensed_parts.section_reactions(model, values, loads)
    out = {at: Reaction(*p) for at, p in parts.items()}
    positions = {at: v["position"] for at, v in values.items()}
    applied, f_scale, m_scale = condensed_parts.load_resultant(loads, positions)
    balance = load_balance(out, applied, f_scale, m_scale, model_size(model.spec))
    gap = max((float(np.linalg.norm(recovered[at] - out[at].moment)) for at in out), default=0.0)
    return out, balance, gap / max(m_scale, 1e-300) if gap else 0.0


#: model -> its ReactionRecovery (forms compiled once), or for a model that is no
#: BeamFormulation (the condensed one) the dict of its load points' dofs: the Protocol's
#: isinstance, about 50 µs, asked once
_recoveries = weakref.WeakKeyDictionary()


def entries(model):
    """The ``reactions`` ({point: {force, moment, position}}) and ``reaction_balance``
    entries of results.json at the model's current state; the condensed model's balance
    (:mod:`~beamfx.analyses.condensed_reactions`) says ``reactions_from``. Collective."""
    from .formulation import BeamFormulation

    if model not in _recoveries:
        beam = isinstance(model, BeamFormulation)
        _recoveries[model] = ReactionRecovery(model) if beam else {}
    recovery = _recoveries[model]
    if isinstance(recovery, ReactionRecovery):
        reactions, balance = recovery()
        balance = balance._asdict()
    else:
        from ..io import evaluate_points

        evaluate = partial(evaluate_points, model, recover=False, full="sections")
        reactions, balance, gap = condensed_reactions(model, evaluate, recovery)
        balance = {
            **balance._asdict(),
            "reactions_from": CONDENSED_SOURCE,
            "recovered_moment_gap": gap,
        }
    return {
        "reactions": {at: r._asdict() for at, r in reactions.items()},
        "reaction_balance": balance,
    }


#: ``reaction_balance.reactions_from`` of the statically condensed model
CONDENSED_SOURCE = (
    "the statics of the loads at their computed positions (statically condensed model)"
)


def balance_line(entry):
    """One log line of :func:`entries`: the reaction points and the balance residuals."""
    n, balance = len(entry["reactions"]), entry["reaction_balance"]
    if balance is not None and "inertia_force" in balance:  # a transient's (its last row)
        inertia = np.round(balance["inertia_force"], 9).tolist()
        return (
            f"reactions: {n} point(s) at the output steps; balance with the applied loads and "
            f"the inertia forces (last, t = {balance['time']:.6g}: inertia force {inertia}): "
            f"max |ΣF|/scale = {balance['max_force']:.1e}, "
            f"max |ΣM|/scale = {balance['max_moment']:.1e}"
        )
    source = balance.get("reactions_from")
    where = f"{n} support(s), from {source}" if source else f"{n} point(s)"
    applied = np.round(balance["applied_force"], 12).tolist()
    return (
        f"reactions: {where}; balance with the applied loads (force {applied}): "
        f"|ΣF|/scale = {balance['force']:.1e}, |ΣM|/scale = {balance['moment']:.1e}"
    )


__all__ = [
    "Balance",
    "Reaction",
    "ReactionRecovery",
    "balance_line",
    "condensed_reactions",
    "entries",
    "load_balance",
    "resultant",
]
