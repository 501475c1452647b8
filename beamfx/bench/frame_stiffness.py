r"""Linear space frames solved exactly: the direct stiffness method with the closed-form
Timoshenko member stiffness (Przemieniecki 1968, §5.6), in NumPy.

A reference for beamfx's linear kinematics on frames of straight prismatic members loaded at
the joints: there the exact Timoshenko solution is cubic in the displacement and quadratic in
the rotation along each member, which P3 elements hold exactly, so beamfx must agree to
round-off. A released member end (``Model.releases``) has its own rotation, the node's plus
the released components along the joint axes (unknowns of their own); an offset end
(``FrameProblem.offsets``) hangs on its node by a rigid arm. Member axes are beamfx's (:func:`~beamfx.geometry.frames.frame_from_tangent`: x the
tangent, z the orientation vector made normal to it, y = z × x), stiffnesses (EA, GA_y, GA_z,
GJ, EI_y, EI_z) those of the member's section: EI_z and GA_y act in the x–y plane,
Φ_y = 12 EI_z / (GA_y L²), and EI_y, GA_z in the x–z plane.
"""

from typing import NamedTuple

import numpy as np

from ..geometry.frames import frame_from_tangent
from ..spec import DOF_NAMES, resolve_point


class FrameProblem(NamedTuple):
    """Nodes, members and their data, supports and nodal loads of a linear frame."""

    nodes: np.ndarray  # (n, 3)
    members: np.ndarray  # (m, 2) node indices
    stiffness: np.ndarray  # (m, 6) EA, GA_y, GA_z, GJ, EI_y, EI_z
    axes: np.ndarray  # (m, 3, 3) Λ0 of each member (columns x, y, z in global axes)
    fixed: dict  # {node: [dof index 0..5]}
    loads: dict  # {node: (6,) force and moment, global axes}
    releases: dict | None = None  # {(member, end 0|1): (3, k) released joint axes as columns}
    offsets: dict | None = None  # {(member, end 0|1): (3,) rigid arm from the node to the end}


def _bending(L, EI, GA, sign):
    """4×4 Timoshenko bending stiffness on (deflection, rotation) at both ends; ``sign`` −1
    for the x–z plane, where a positive rotation about y lowers w."""
    phi = 12 * EI / (GA * L**2)
    a, b = 6 * L * sign, L**2
    k = np.array(
        [
            [12, a, -12, a],
            [a, (4 + phi) * b, -a, (2 - phi) * b],
            [-12, -a, 12, -a],
            [a, (2 - phi) * b, -a, (4 + phi) * b],
        ]
    )
    return EI / (L**3 * (1 + phi)) * k


def member_stiffness(L, C):
    """12×12 stiffness in member axes, dofs (u, θ) at the start then the end."""
    EA, GA_y, GA_z, GJ, EI_y, EI_z = C
    k = np.zeros((12, 12))
    bar = np.array([[1.0, -1.0], [-1.0, 1.0]])
    k[np.ix_([0, 6], [0, 6])] = EA / L * bar
    k[np.ix_([3, 9], [3, 9])] = GJ / L * bar
    k[np.ix_([1, 5, 7, 11], [1, 5, 7, 11])] = _bending(L, EI_z, GA_y, 1.0)
    k[np.ix_([2, 4, 8, 10], [2, 4, 8, 10])] = _bending(L, EI_y, GA_z, -1.0)
    return k


def _hat(r):
    """The matrix of r × ·."""
    return np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])


def solve(problem):
    """Nodal displacements and rotations (n, 6) and the reactions {node: (6,)} (force and
    moment, global axes: K u − f at the fixed dofs)."""
    n = len(problem.nodes)
    releases = problem.releases or {}
    hinge = {key: E.shape[1] for key, E in releases.items()}
    size = 6 * n + sum(hinge.values())
    K = np.zeros((size, size))
    first = 6 * n  # a released member end: its rotation = the node's + E φ (φ: own unknowns)
    offsets = problem.offsets or {}
    for m, ((a, b), C, lam) in enumerate(zip(problem.members, problem.stiffness, problem.axes)):
        ends = [problem.nodes[n] + offsets.get((m, e), 0.0) for e, n in enumerate((a, b))]
        L = np.linalg.norm(ends[1] - ends[0])
        T = np.kron(np.eye(4), lam.T)
        G = np.zeros((12, size))  # member end dofs (global axes) from the unknowns
        G[:6, 6 * a : 6 * a + 6] = G[6:, 6 * b : 6 * b + 6] = np.eye(6)
        for end in (0, 1):
            E = releases.get((m, end))
            if E is not None:
                G[6 * end + 3 : 6 * end + 6, first : first + E.shape[1]] = E
                first += E.shape[1]
            r = offsets.get((m, end))
            if r is not None:  # a rigid arm: u_end = u_node + θ_end × r
                G[6 * end : 6 * end + 3] -= _hat(r) @ G[6 * end + 3 : 6 * end + 6]
        K += G.T @ T.T @ member_stiffness(L, C) @ T @ G
    f = np.zeros(size)
    for node, load in problem.loads.items():
        f[6 * node : 6 * node + 6] += load
    fixed = np.array([6 * node + d for node, ds in problem.fixed.items() for d in ds], int)
    free = np.setdiff1d(np.arange(size), fixed)
    u = np.zeros(size)
    u[free] = np.linalg.solve(K[np.ix_(free, free)], f[free])
    r = K @ u - f
    reactions = {
        node: np.where(np.isin(np.arange(6), ds), r[6 * node : 6 * node + 6], 0.0)
        for node, ds in problem.fixed.items()
    }
    return u[: 6 * n].reshape(n, 6), reactions


def problem_from_model(spec, tol=1e-9):
    """The :class:`FrameProblem` of a beamfx :class:`~beamfx.spec.Model` of straight beams
    with supports and dead point loads at their ends (global axes). Nodes are the beams' ends,
    merged by coordinates, numbered in order of first appearance."""
    keys, nodes = {}, []

    def node(x):
        key = tuple(np.round(np.asarray(x) / tol).astype(np.int64))
        if key not in keys:
            keys[key] = len(nodes)
            nodes.append(np.asarray(x, float))
        return keys[key]

    members, stiffness, axes = [], [], []
    for b in spec.beams:
        x0, x1 = b.curve.points([0.0, b.curve.length])
        members.append((node(x0), node(x1)))
        stiffness.append(b.section.stiffnesses())
        axes.append(frame_from_tangent((x1 - x0) / b.curve.length, b.orientation, b.twist_deg))
    fixed, loads = {}, {}
    for s in spec.supports:
        fixed.setdefault(node(resolve_point(spec, s.at)[2]), []).extend(
            DOF_NAMES.index(d) for d in s.fix
        )
    for p in spec.point_loads:
        i = node(resolve_point(spec, p.at)[2])
        loads[i] = loads.get(i, np.zeros(6)) + np.r_[p.force, p.moment]
    releases = {}
    names = [b.name for b in spec.beams]
    for rel in spec.releases:
        beam, _, where = rel.at.partition(":")
        cols = [np.asarray(rel.axes, float)[("rx", "ry", "rz").index(c)] for c in rel.released]
        releases[(names.index(beam), int(where == "end"))] = np.array(cols).T
    return FrameProblem(
        np.array(nodes),
        np.array(members),
        np.array(stiffness),
        np.array(axes),
        fixed,
        loads,
        releases,
    )


__all__ = ["FrameProblem", "member_stiffness", "problem_from_model", "solve"]
