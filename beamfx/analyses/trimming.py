"""Model trimming: the planar model where the scene is a plane problem.

A 3D beam problem is a plane problem when the plane through its centre lines is a plane of
mirror symmetry of everything that acts on it: then the in-plane motion solves the 3D
equations exactly, and the planar model (two displacements and one angle per node,
:class:`~beamfx.physics.kinematics.Kinematics` ``plane``) reaches it with 3 instead of 7 (or 6)
unknowns per node. :func:`choose_plane` checks, for each coordinate plane xy, yz, xz:

* every centre line lies in the plane (up to an offset), sampled along its length;
* the plane's normal n is a principal axis of every section (n ∥ e2 or e3 of the reference
  frame Λ0, :func:`~beamfx.geometry.frames.section_axes_at`, twist included), or the section
  is symmetric (EI_y = EI_z, GA_y = GA_z, equal rotary inertias): in-plane bending then uses
  one EI and does not couple to torsion or out-of-plane bending;
* forces (point, distributed, gravity) lie in the plane and moments are normal to it;
* prescribed support displacements lie in the plane and prescribed rotations are normal to it
  (in the section axes for ``axes = "local"``, which also need n to be a principal axis);
* point masses have n as a principal axis of their inertia;
* an arc-length displacement limit is an in-plane component;
* the full model is supported (trimming never turns an unsupported scene into a solvable one).

It never trims modal, buckling or rotating analyses: a plane structure has out-of-plane modes
(lateral vibration, lateral-torsional buckling, flap of a rotor blade) that the planar model
cannot represent. A static or transient plane problem stays in its plane by symmetry, but the
planar model cannot tell whether that symmetric path is stable in 3D; a buckling analysis of
the full model answers that.
"""

from typing import NamedTuple

import numpy as np

from ..geometry.frames import section_axes_at
from ..physics.kinematics import PLANES
from ..spec import DOF_NAMES, resolve_point
from .checks import free_rigid_modes, leaves_plane, model_size

#: analyses whose answer includes out-of-plane motion of a plane structure
NEVER_TRIMMED = ("modal", "buckling", "rotating")
#: values of the scene key ``[model] plane``
PLANE_CHOICES = ("auto", "none", *PLANES)


class Trim(NamedTuple):
    """What the scene builder chose: ``plane`` (None: the full model), ``automatic`` (chosen by
    :func:`choose_plane` rather than stated) and ``reason`` (a sentence for the log); and why
    the formulation (:mod:`beamfx.analyses.mixed`), "" when not chosen by the builder."""

    plane: str | None
    automatic: bool
    reason: str
    formulation: str = ""


def _in_plane(model, n, tol):
    for b in model.beams:
        x = b.curve.points(np.linspace(0.0, b.curve.length, 201))
        if np.ptp(x[:, n]) > tol:
            return f"beam {b.name!r} leaves the plane"
    return None


def _symmetric(section, rtol=1e-12):
    """EI_y = EI_z, GA_y = GA_z and equal rotary inertias about y and z."""
    pairs = [(section.EI_y, section.EI_z), (section.GA_y, section.GA_z)]
    pairs.append((section.rho_I[1], section.rho_I[2]))
    return all(abs(a - b) <= rtol * max(abs(a), abs(b), 1e-300) for a, b in pairs)


def _matrix(model):
    """Why a model with a matrix (6×6) section is neither planar nor condensed, or None."""
    for b in model.beams:
        if not hasattr(b.section, "EA"):
            return f"beam {b.name!r} has a matrix section (its couplings may leave a plane)"
    return None


def _principal(model, n):
    """None if n is a principal axis of every section (or the section is symmetric)."""
    why = _matrix(model)
    if why:
        return why
    for b in model.beams:
        s = np.linspace(0.0, b.curve.length, 21)
        frames = [section_axes_at(b.curve, si, b.orientation, b.twist_deg) for si in s]
        normal = np.array([np.eye(3)[n] @ f for f in frames])  # (t, e2, e3)
        aligned = np.minimum(np.abs(normal[:, 1]), np.abs(normal[:, 2])) < 1e-9
        if aligned.all():
            continue
        if not all(_symmetric(x) for x in b.section.along(s[~aligned])):
            return (
                f"the plane's normal is not a principal axis of beam {b.name!r}'s section "
                "(orientation/twist_deg) and EI_y != EI_z: in-plane bending would couple "
                "out of the plane"
            )
    return None


def _loads(model, n):
    off = [i for i in range(3) if i != n]
    for ld in (*model.point_loads, *model.distributed_loads):
        if leaves_plane(ld, model.beams, n, off):
            return f"a load (force {list(ld.force)}, moment {list(ld.moment)}) leaves the plane"
    if model.gravity[n]:
        return f"gravity {list(model.gravity)} leaves the plane"
    return None


def _supports(model, n):
    from ..spec import resolve_point

    off = [i for i in range(3) if i != n]
    for i, sup in enumerate(model.supports):
        d, r = np.asarray(sup.displacement, float), np.asarray(sup.rotation, float)
        if sup.axes == "local":
            b, s, _ = resolve_point(model, sup.at)
            beam = model.beams[b]
            frame = section_axes_at(beam.curve, s, beam.orientation, beam.twist_deg)
            local_n = frame.T[:, n]
            if np.sort(np.abs(local_n))[-1] < 1 - 1e-9:
                return f"supports[{i}] (local axes): the plane's normal is no section axis there"
            d, r = frame @ d, frame @ r
        if abs(d[n]) > 0 or np.any(np.abs(r[off]) > 0):
            return f"supports[{i}] prescribes motion out of the plane"
    for i, pm in enumerate(model.point_masses):
        J = np.asarray(pm.inertia, float)
        if np.any(np.abs(J[off, n]) > 1e-12 * max(np.abs(J).max(), 1e-300)):
            return f"masses[{i}]: the plane's normal is not a principal axis of its inertia"
    return None


def _settings(settings, n):
    limit = settings.get("displacement_limit") if settings else None
    if limit and DOF_NAMES.index(limit[0]) == n:
        return f"the arc-length displacement limit {limit[0]} is out of the plane"
    return None


def plane_fit(model, plane, settings=None):
    """None if ``model`` is a plane problem in ``plane`` ("xy", "yz", "xz"), else the reason
    it is not (a sentence)."""
    n = PLANES[plane][2]
    tol = 1e-9 * model_size(model)
    for check in (_in_plane, _principal, _loads, _supports, _settings):
        args = (model, n, tol) if check is _in_plane else (model, n)
        if check is _settings:
            args = (settings, n)
        why = check(*args)
        if why:
            return why
    return None


def choose_plane(model, analysis, settings=None, free_body=False):
    """The plane in which ``model`` (a full 3D :class:`~beamfx.spec.Model`) is a plane
    problem for ``analysis``, as a :class:`Trim`; ``plane`` None where it is not (or where the
    analysis needs out-of-plane motion, :data:`NEVER_TRIMMED`). ``free_body``: the analysis
    takes a free structure (then free rigid-body motion does not keep the full model)."""
    if analysis in NEVER_TRIMMED:
        return Trim(None, True, f"full model: a {analysis} analysis has out-of-plane modes")
    if free_rigid_modes(model) and not free_body:
        return Trim(None, True, "full model: the supports leave 3D rigid-body motion free")
    reasons = []
    for plane in PLANES:
        why = plane_fit(model, plane, settings)
        if why is None:
            return Trim(plane, True, f"planar model ({plane}): a plane problem")
        reasons.append(f"{plane}: {why}")
    return Trim(None, True, "full model: not a plane problem (" + "; ".join(reasons) + ")")


def trimming_summary(trim, kin, unknowns, condensed=False):
    """Log line and results entry of the trimming, with the unknowns the planar model saves
    (a planar model has 3 unknowns per node; the full one 7 with quaternions, 6 if linear).
    ``condensed``: ``unknowns`` are those of the planar condensed model (1 per node), and
    the line names the planar model's."""
    entry = {"plane": trim.plane, "automatic": trim.automatic, "reason": trim.reason}
    if not kin.plane:
        return trim.reason, entry
    nodes = unknowns // (1 if condensed else 3)
    unknowns = 3 * nodes
    full = 3 + (4 if kin.finite else 3)
    entry.update(unknowns=unknowns, unknowns_full_model=nodes * full, per_node=(3, full))
    line = (
        f"planar model ({kin.plane}{', automatic' if trim.automatic else ''}): 3 unknowns per "
        f"node instead of {full}, {unknowns} instead of {nodes * full}"
    )
    return line, entry


#: moments the statically condensed model takes (analyses/condensed.py)
MOMENT_KINDS = ("dead", "follower", "semitangential")


def condensed_fit(model, analysis="static"):
    """None if the condensed model applies to ``model`` and ``analysis``, else why not.

    It applies to planar and spatial models alike: a planar model (``kinematics.plane``, as
    :func:`choose_plane` set it) is condensed to the plane angle, one unknown per node
    (:mod:`beamfx.analyses.planar_condensed`), a spatial one to the rotation vector, three.
    """
    kin = model.kinematics
    if analysis != "static":
        return f"it solves static analyses only, not {analysis!r}"
    if not kin.finite:
        return "the kinematics are linear (one linear solve already)"
    if len(model.beams) != 1:
        return "it models one beam"
    if model.releases:
        return "released joints are not implemented in it"
    if len(model.supports) != 1:
        return "it models a cantilever (one support, clamped)"
    sup = model.supports[0]
    if set(sup.fix) != set(DOF_NAMES) or any(sup.displacement) or any(sup.rotation):
        return "the support is not a clamp with zero displacement and rotation"
    if sup.timed or resolve_point(model, sup.at)[1] != 0.0:
        return "the clamp is not at the beam's start"
    if model.distributed_loads or any(model.gravity):
        return "distributed loads (and gravity) are not implemented in it"
    if model.springs or model.point_masses:
        return "springs and point masses are not implemented in it"
    if _matrix(model):
        return _matrix(model)
    for ld in model.point_loads:
        if ld.history is not None:
            return "a load has a history"
        if any(ld.moment) and ld.kind not in MOMENT_KINDS:
            return f"a {ld.kind} moment is not implemented in it (allowed {list(MOMENT_KINDS)})"
    return None


def condensing_summary(kin, unknowns):
    """Log line and results entry of a condensed model of kinematics ``kin`` with
    ``unknowns`` unknowns: which one (planar: the angle, 1 per node; spatial: the rotation
    vector, 3 per node), the unknowns of the model it replaces, and why it applies."""
    per_node, full = (1, 3) if kin.plane else (3, 3 + kin.rotation_size)
    nodes = unknowns // per_node
    name = "planar statically condensed" if kin.plane else "statically condensed"
    field = f"the angle about the plane's normal ({kin.plane})" if kin.plane else "the rotations"
    kept = (
        ", ".join([w for w, on in (("shear", kin.shear), ("stretch", kin.stretch)) if on])
        or "neither shear nor stretch"
    )
    line = (
        f"{name} (a cantilever under point loads: the section force is known): {field} the "
        f"only unknown, {per_node} per node instead of {full}, {unknowns} instead of "
        f"{nodes * full}; {kept} kept" + ("; any number of turns" if kin.plane else "")
    )
    entry = {
        "model": "planar_condensed" if kin.plane else "condensed",
        "unknowns": unknowns,
        "unknowns_replaced_model": nodes * full,
        "per_node": (per_node, full),
        "reason": "a static cantilever under point loads (condensed_fit)",
    }
    return line, entry


__all__ = [
    "MOMENT_KINDS",
    "NEVER_TRIMMED",
    "PLANE_CHOICES",
    "Trim",
    "choose_plane",
    "condensed_fit",
    "condensing_summary",
    "plane_fit",
    "trimming_summary",
]
