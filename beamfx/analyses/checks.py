"""Checks of a model before any solve."""

import numpy as np

from ..geometry.curves import Line
from ..geometry.frames import section_axes_at
from ..spec import DOF_NAMES, resolve_point
from ..spec.model import beam_index
from .dofs import OUT_OF_PLANE


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


def model_size(model):
    """The spread of the beams' end points (at least 1): the length scale of a model spec."""
    ends = np.vstack([b.curve.points([0.0, b.curve.length]) for b in model.beams])
    return max(float(np.ptp(ends)), 1.0)


def closest_arc_length(curve, x, samples=400):
    """Arc length of the point of ``curve`` closest to ``x``, and the distance."""
    if isinstance(curve, Line):  # closed form: the projection, clipped to the segment
        start, L = np.asarray(curve.start, float), curve.length
        d = (np.asarray(curve.end, float) - start) / L
        s = float(np.clip((np.asarray(x, float) - start) @ d, 0.0, L))
        return s, float(np.linalg.norm(start + s * d - x))
    a, b, n = 0.0, curve.length, samples
    for _ in range(8):  # sample, bracket the nearest sample, refine: 16x narrower per pass
        s = np.linspace(a, b, n + 1)
        dist = np.linalg.norm(curve.points(s) - x, axis=1)
        i = int(np.argmin(dist))
        a, b, n = s[max(i - 1, 0)], s[min(i + 1, n)], 32
    return float(s[i]), float(dist[i])


def end_contacts(model, rtol=1e-8):
    """(i, j, s): the end of beam i lies on beam j at its arc length s (to rtol of the model).

    The candidate pairs (an end inside the box of another beam) are tested at once: straight
    beams in closed form with numpy, the others one by one (:func:`closest_arc_length`, which
    also gives the arc length of every contact inside a span, where a T-joint puts a vertex).
    """
    if len(model.beams) < 2:  # one beam: no end of another on it (and no k-d tree to build)
        return []
    tol = rtol * model_size(model)
    lo, hi = _boxes(model, tol)
    ends = np.vstack([a.curve.points([0.0, a.curve.length]) for a in model.beams])
    found = _box_search(lo, hi, ends)
    end = np.repeat(np.arange(len(ends)), [len(f) for f in found])
    j = np.concatenate(found) if len(found) else np.zeros(0, dtype=np.int64)
    x = ends[end]
    keep = (j != end // 2) & np.all((lo[j] <= x) & (x <= hi[j]), axis=1)  # boxes holding x
    end, j, x = end[keep], j[keep], x[keep]
    s, dist, length = _closest_on_lines(model, j, x)
    exact = np.isnan(dist) | ((tol < s) & (s < length - tol))  # not a line, or a T-joint
    for k in np.flatnonzero(exact):
        s[k], dist[k] = closest_arc_length(model.beams[j[k]].curve, x[k])
    hit = dist < tol
    return list(zip((end[hit] // 2).tolist(), j[hit].tolist(), s[hit].tolist()))


def _closest_on_lines(model, j, x):
    """(s, distance, length of beam j) of the points ``x`` to the straight beams ``j`` (the
    projection clipped to the segment, vectorised); distance NaN where beam j is not a line."""
    n = len(model.beams)
    start, step, length = np.full((n, 3), np.nan), np.zeros((n, 3)), np.ones(n)
    for b, beam in enumerate(model.beams):
        if isinstance(beam.curve, Line):
            start[b], length[b] = beam.curve.start, beam.curve.length
            step[b] = (np.asarray(beam.curve.end, float) - start[b]) / length[b]
        else:
            length[b] = beam.curve.length
    s = np.clip(np.einsum("ij,ij->i", x - start[j], step[j]), 0.0, length[j])
    return s, np.linalg.norm(start[j] + s[:, None] * step[j] - x, axis=1), length[j]


def _box_search(lo, hi, points):
    """Per point, the sorted indices of the boxes whose centre is within the largest box
    half-diagonal of it (a superset of the boxes holding it): a k-d tree, so that a frame of
    10⁵ members is not checked pairwise."""
    from scipy.spatial import cKDTree

    centre, radius = (lo + hi) / 2, float(np.max(np.linalg.norm(hi - lo, axis=1))) / 2
    found = cKDTree(centre).query_ball_point(points, radius * (1 + 1e-12))
    return [np.array(sorted(f), dtype=np.int64) for f in found]


def _boxes(model, tol, samples=64):
    """(lo, hi): boxes around each beam, (n_beams, 3) each. Every point of a curve lies
    within L/samples (arc length) of a sample, so the samples' box padded by that holds it;
    an end point outside a beam's box is farther than ``tol`` from the beam."""
    lo, hi = [], []
    for b in model.beams:
        x = b.curve.points(np.linspace(0.0, b.curve.length, samples + 1))
        pad = b.curve.length / samples + tol
        lo.append(x.min(axis=0) - pad)
        hi.append(x.max(axis=0) + pad)
    return np.array(lo), np.array(hi)


def joint_breaks(model, rtol=1e-8):
    """(beam index, arc length) where the end of another beam meets a beam inside its span
    (a T-joint): the mesh needs a vertex there for the joint to exist."""
    tol = rtol * model_size(model)
    return [
        (j, s)
        for _, j, s in end_contacts(model, rtol)
        if tol < s < model.beams[j].curve.length - tol
    ]


def named_breaks(spec, extra_points=()):
    """Named points (every 'at' of supports, loads, springs, masses and ``extra_points``) as
    {at: (beam, s, xyz)}, and the arc lengths {beam index: [s]} where the mesh needs a vertex:
    those points, T-joints and the stations of matrix sections that ask for them.

    Raises:
        ValueError: if a point names no point of a beam.
    """
    ats = [x.at for x in (*spec.supports, *spec.point_loads, *spec.springs, *spec.point_masses)]
    index = beam_index(spec)
    named = {at: resolve_point(spec, at, index) for at in dict.fromkeys(ats + list(extra_points))}
    breaks = {i: [] for i in range(len(spec.beams))}
    for b, s, _ in named.values():
        breaks[b].append(s)
    for b, s in joint_breaks(spec):
        breaks[b].append(s)
    for i, b in enumerate(spec.beams):  # matrix sections that ask for vertices at stations
        breaks[i].extend(getattr(b.section, "station_breaks", list)())
    return named, breaks


def connected_beams(model, rtol=1e-8):
    """Groups of beam indices joined by shared points (ends, T-joints), as sorted lists."""
    group = list(range(len(model.beams)))

    def root(i):
        while group[i] != i:
            group[i] = group[group[i]]  # path halving: near-flat trees on large frames
            i = group[i]
        return i

    for i, j, _ in end_contacts(model, rtol):
        group[root(i)] = root(j)
    groups = {}
    for i in range(len(model.beams)):
        groups.setdefault(root(i), []).append(i)
    return sorted(groups.values())


def _constraint_rows(model, beams, centre, size):
    """Rows of the rigid-body modes restricted to the constrained dofs on ``beams``."""
    rows = []

    def add(at, dofs, frame=None):
        b, _, x = resolve_point(model, at)
        if b not in beams:
            return
        r = rigid_mode_rows((x - centre) / size + centre, DOF_NAMES, centre)
        r = np.array(r)
        if frame is not None:  # local axes: combine the global rows with Λ0
            r = np.vstack([frame.T @ r[:3], frame.T @ r[3:]])
        rows.extend(r[[DOF_NAMES.index(d) for d in dofs]])

    for sup in model.supports:
        frame = None
        if sup.axes == "local":
            b, s, _ = resolve_point(model, sup.at)
            beam = model.beams[b]
            frame = section_axes_at(beam.curve, s, beam.orientation, beam.twist_deg)
        add(sup.at, sup.fix, frame)
    for sp in model.springs:
        k = np.r_[sp.stiffness, sp.rotational]
        add(sp.at, [DOF_NAMES[i] for i in range(6) if k[i] > 0])
    plane = model.kinematics.plane
    if plane:  # the planar model has no out-of-plane motion
        add(f"{model.beams[beams[0]].name}:start", OUT_OF_PLANE[plane])
    return rows


def free_rigid_modes(model):
    """Number of rigid-body motions that supports and springs leave free, summed over the
    groups of connected beams.

    Joints are rigid, so the only zero-energy motions of a beam model are rigid-body motions of
    each connected group; they are free when the six mode vectors, restricted to the
    constrained dofs of the group, lose rank.
    """
    return sum(n for _, n in free_modes_by_group(model))


def free_modes_by_group(model):
    """[(beam names of a connected group, free rigid-body motions of it)]."""
    out = []
    for beams in connected_beams(model):
        ends = np.vstack(
            [model.beams[b].curve.points([0.0, model.beams[b].curve.length]) for b in beams]
        )
        centre = ends.mean(axis=0)
        size = max(1.0, float(np.max(np.linalg.norm(ends - centre, axis=1))))
        rows = _constraint_rows(model, beams, centre, size)
        rank = 0
        if rows:
            sv = np.linalg.svd(np.array(rows), compute_uv=False)
            rank = int(np.sum(sv > 1e-9 * sv[0]))
        out.append(([model.beams[b].name for b in beams], 6 - rank))
    return out


def check_supported(model):
    """Raise ValueError if supports and springs leave rigid-body motion free."""
    bad = [(names, n) for names, n in free_modes_by_group(model) if n]
    if bad:
        given = [f"{s.at}: {list(s.fix)}" for s in model.supports]
        groups = "; ".join(f"{n} rigid-body motion(s) free on beams {names}" for names, n in bad)
        raise ValueError(
            f"supports leave {groups}; supports given: "
            f"{given or 'none'}. Fix more dofs (allowed: {list(DOF_NAMES)}) or add springs; "
            "beams that share no point are separate bodies and each needs its own supports."
        )


def takes_free_body(settings, model):
    """Whether the analysis of ``settings`` takes ``model`` without supports: its settings say
    so with ``free_body(model) -> bool`` (a modal analysis without pre-stress, a transient from
    rest: their operators K - ω²M and M/(β Δt²) + K are regular); False if they have no say."""
    return bool(getattr(settings, "free_body", lambda model: False)(model))


def check_supports_for(model, settings):
    """:func:`check_supported`, unless the analysis takes a free structure
    (:func:`takes_free_body`)."""
    if not takes_free_body(settings, model):
        check_supported(model)


def leaves_plane(load, beams, n, off):
    """Whether a load's force leaves the plane normal to axis ``n`` or its moment turns out of
    it (a distributed load in section axes, along the beams it acts on)."""
    pairs = load.directions(beams) if hasattr(load, "directions") else [(load.force, load.moment)]
    scale = max((np.abs(np.r_[f, m]).max() for f, m in pairs), default=0.0)
    tol = 1e-12 * scale
    return any(abs(f[n]) > tol or any(abs(m[i]) > tol for i in off) for f, m in pairs)


def check_planar(model):
    """Raise ValueError if a planar model's geometry or loads leave its plane."""
    from ..physics.kinematics import PLANES

    plane = model.kinematics.plane
    if not plane:
        return
    n = PLANES[plane][2]
    tol = 1e-9 * model_size(model)
    for b in model.beams:
        x = b.curve.points(np.linspace(0.0, b.curve.length, 101))
        if np.ptp(x[:, n]) > tol:
            raise ValueError(f"planar model ({plane}): beam {b.name!r} leaves the plane")
    for ld in (*model.point_loads, *model.distributed_loads):
        if leaves_plane(ld, model.beams, n, [i for i in range(3) if i != n]):
            raise ValueError(
                f"planar model ({plane}): a load has out-of-plane components "
                f"(force {list(ld.force)}, moment {list(ld.moment)})"
            )
    if model.gravity[n]:
        raise ValueError(f"planar model ({plane}): gravity {list(model.gravity)} leaves the plane")
