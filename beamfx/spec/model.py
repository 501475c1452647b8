"""Plain descriptions of a beam model: what the scene file says, as frozen dataclasses."""

from dataclasses import dataclass, field

import numpy as np

from ..physics.kinematics import Kinematics
from ..physics.sections import Section

DOF_NAMES = ("ux", "uy", "uz", "rx", "ry", "rz")


@dataclass(frozen=True)
class Beam:
    """A beam: centre line, section, mesh (elements, degree) and section orientation."""

    name: str
    curve: object
    section: Section
    elements: int
    degree: int = 2
    orientation: tuple | None = None  # reference vector for the section z axis (global)
    twist_deg: float = 0.0  # or a function of the arc length s (pre-twist along the span)


AXES = ("global", "local")
LOAD_KINDS = ("dead", "follower", "semitangential", "quasitangential")


@dataclass(frozen=True)
class Support:
    """Fixed dofs (names from :data:`DOF_NAMES`) at a point.

    ``axes`` "global": the names are global axes, and the conditions are exact (Dirichlet).
    "local": the names are the beam's reference section axes at the point (x the tangent, y
    and z the section's principal axes); the conditions are then stiff penalty springs
    (:meth:`BeamModel.penalty`), which leave a relative error of about 1e-9.
    ``displacement`` and ``rotation`` (a rotation vector) are prescribed values in the same
    axes, applied with the load factor; zero by default. In a transient, ``history`` f(t)
    scales both; ``displacement_history`` and ``rotation_history``, when given, scale only
    their own part instead (a hub that spins and is shaken: two schedules).
    """

    at: str
    fix: tuple
    displacement: tuple = (0.0, 0.0, 0.0)
    rotation: tuple = (0.0, 0.0, 0.0)
    axes: str = "global"
    history: object = None  # f(t) scaling displacement and rotation in a transient (None: 1)
    displacement_history: object = None  # f(t) scaling the displacement only (None: history)
    rotation_history: object = None  # f(t) scaling the rotation only (None: history)

    def history_of(self, part):
        """The history scaling ``part`` 0 (displacement) or 1 (rotation); None: constant."""
        own = self.displacement_history if part == 0 else self.rotation_history
        return self.history if own is None else own

    def histories(self):
        """(name, f) of every history given, in the order history, displacement, rotation."""
        names = ("history", "displacement_history", "rotation_history")
        return tuple((n, getattr(self, n)) for n in names if getattr(self, n) is not None)

    @property
    def timed(self):
        """Whether a history moves this support in a transient."""
        return bool(self.histories())


@dataclass(frozen=True)
class PointLoad:
    """Force and moment at a point; ``kind`` one of :data:`LOAD_KINDS` (see
    :func:`beamfx.physics.energy.moment_work`); ``arm`` the direction of the arm of a
    "quasitangential" moment (global axes, normal to the moment)."""

    at: str
    force: tuple = (0.0, 0.0, 0.0)
    moment: tuple = (0.0, 0.0, 0.0)
    kind: str = "dead"
    history: object = None  # f(t) scaling force and moment in a transient (None: 1)
    arm: tuple | None = None


@dataclass(frozen=True)
class DistributedLoad:
    """Force and moment per unit reference length on ``beam`` (all beams if None); ``kind``
    and ``arm`` as in :class:`PointLoad`. ``axes``: "global", or "section" for components in
    the section axes of the undeformed beam (a radial load on an arc: then a dead load keeps
    the undeformed radial direction and a follower load turns with the section, a pressure).
    ``profile``: a function of the arc length along ``beam`` that multiplies both."""

    beam: str | None = None
    force: tuple = (0.0, 0.0, 0.0)
    moment: tuple = (0.0, 0.0, 0.0)
    kind: str = "dead"
    history: object = None  # f(t) scaling force and moment in a transient (None: 1)
    arm: tuple | None = None
    axes: str = "global"
    profile: object = None  # f(s) along ``beam`` scaling force and moment (None: 1)

    def directions(self, beams):
        """The global force and moment per length along ``beams`` (sampled at 101 points of
        each), for checks of where the load points: ``[(force, moment)]``."""
        from ..geometry.frames import section_axes_at

        if self.axes == "global":
            return [(np.asarray(self.force, float), np.asarray(self.moment, float))]
        out = []
        for b in beams:
            if self.beam is not None and b.name != self.beam:
                continue
            for s in np.linspace(0.0, b.curve.length, 101):
                lam = section_axes_at(b.curve, s, b.orientation, b.twist_deg)
                out.append(
                    (lam @ np.asarray(self.force, float), lam @ np.asarray(self.moment, float))
                )
        return out


@dataclass(frozen=True)
class Spring:
    """Linear springs to ground: translational (per global axis) and rotational (on the
    rotation vector, per global axis)."""

    at: str
    stiffness: tuple = (0.0, 0.0, 0.0)
    rotational: tuple = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class PointMass:
    """A rigid body attached at a point: ``mass`` and the rotary inertia ``inertia`` about the
    point (3x3, global axes in the reference state; it turns with the section)."""

    at: str
    mass: float = 0.0
    inertia: tuple = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))


@dataclass(frozen=True)
class Release:
    """A member end joined to its node with some rotations free (a hinge, a pin): ``at`` is
    ``beam:start`` or ``beam:end``; ``released`` a subset of ("rx", "ry", "rz"), components
    in the joint axes ``axes`` (rows x, y, z: an orthonormal basis, global coordinates in the
    reference state; they turn with the joint). ``joint`` names it in messages."""

    at: str
    released: tuple = ("rx", "ry", "rz")
    axes: tuple = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    joint: str = ""


@dataclass(frozen=True)
class Model:
    """The whole structure: beams, supports, loads, springs, masses and kinematics options."""

    beams: tuple
    supports: tuple = ()
    point_loads: tuple = ()
    distributed_loads: tuple = ()
    springs: tuple = ()
    gravity: tuple = (0.0, 0.0, 0.0)
    kinematics: Kinematics = field(default_factory=Kinematics)
    point_masses: tuple = ()
    releases: tuple = ()  #: :class:`Release` of member ends (joints that are not rigid)
    #: "displacement" (unknowns u, rotation) or "mixed" (and the section force: the
    #: Hellinger–Reissner form of :mod:`beamfx.physics.mixed`)
    formulation: str = "displacement"

    def beam(self, name):
        """The beam named ``name`` (KeyError if none)."""
        for b in self.beams:
            if b.name == name:
                return b
        raise KeyError(name)


def beam_index(model):
    """{beam name: index} of ``model.beams`` (the first beam of a name), for
    :func:`resolve_point` of many points."""
    out = {}
    for i, b in enumerate(model.beams):
        out.setdefault(b.name, i)
    return out


def resolve_point(model, at, index=None):
    """Beam index, arc length and coordinates of a point name ``beam:start|end|<fraction>``.

    ``index``: :func:`beam_index` of ``model``, given by a caller that resolves many points
    (else it is built at every call: O(beams) each).

    Raises:
        ValueError: with the allowed forms, if ``at`` names no point of a beam.
    """
    index = beam_index(model) if index is None else index
    beam_name, colon, where = str(at).partition(":")
    if not colon:
        raise ValueError(f"{at!r}: write 'beam:start', 'beam:end' or 'beam:<fraction of length>'")
    if beam_name not in index:
        raise ValueError(
            f"{at!r} names no beam; beams are {[b.name for b in model.beams]} (write "
            "'beam:start', 'beam:end' or 'beam:<fraction of length>')"
        )
    b = index[beam_name]
    L = model.beams[b].curve.length
    if where in ("start", "end"):
        s = 0.0 if where == "start" else L
    else:
        try:
            f = float(where)
        except ValueError:
            raise ValueError(
                f"{at!r}: after ':' write start, end or a fraction in [0, 1]"
            ) from None
        if not 0.0 <= f <= 1.0:
            raise ValueError(f"{at!r}: the fraction must lie in [0, 1]")
        s = f * L
    return b, s, np.asarray(model.beams[b].curve.points([s])[0], float)
