"""Checks of a model before any solve."""

import numpy as np

from .spec import DOF_NAMES, resolve_point


def rigid_mode_rows(xyz, dofs, centre):
    """Values of the six rigid-body modes (3 translations, 3 small rotations about ``centre``)
    in the dofs ``dofs`` (names of :data:`DOF_NAMES`, global axes) at the point ``xyz``."""
    rows = []
    arm = np.asarray(xyz, float) - centre
    for d in dofs:
        i = DOF_NAMES.index(d)
        if i < 3:  # u_i of translation e_j is δ_ij; of rotation e_k it is (e_k × arm)_i
            rows.append(np.r_[np.eye(3)[i], [np.cross(np.eye(3)[k], arm)[i] for k in range(3)]])
        else:  # rotation component i-3: zero for translations, δ for rotations
            rows.append(np.r_[np.zeros(3), np.eye(3)[i - 3]])
    return rows


def free_rigid_modes(model):
    """Number of rigid-body motions that supports and springs leave free.

    Joints are rigid, so the only zero-energy motions of a beam model are rigid-body motions;
    they are free when the six mode vectors, restricted to the constrained dofs, lose rank.
    """
    points = [(resolve_point(model, s.at)[2], s.fix) for s in model.supports]
    points += [
        (resolve_point(model, s.at)[2], [DOF_NAMES[i] for i in range(3) if s.stiffness[i] > 0])
        for s in model.springs
    ]
    if not points:
        return 6
    centre = np.mean([p for p, _ in points], axis=0)
    size = max(1.0, max(np.linalg.norm(p - centre) for p, _ in points))
    rows = [
        r for p, dofs in points for r in rigid_mode_rows((p - centre) / size + centre, dofs, centre)
    ]
    if not rows:
        return 6
    sv = np.linalg.svd(np.array(rows), compute_uv=False)
    return 6 - int(np.sum(sv > 1e-9 * sv[0]))


def check_supported(model):
    """Raise ValueError if supports and springs leave rigid-body motion free."""
    n = free_rigid_modes(model)
    if n:
        given = [f"{s.at}: {list(s.fix)}" for s in model.supports]
        raise ValueError(
            f"supports leave {n} rigid-body motion(s) free; supports given: {given or 'none'}. "
            f"Fix more dofs (allowed: {list(DOF_NAMES)}) or add springs."
        )
