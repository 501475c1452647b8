"""Small model builders shared by the benchmark modules."""

from ..geometry import Arc, Line
from ..physics.kinematics import Kinematics
from ..spec import Beam, Model, PointLoad, Support

FULL = Kinematics()
CLAMP = ("ux", "uy", "uz", "rx", "ry", "rz")


def cantilever(
    curve,
    section,
    elements,
    degree,
    force=(0, 0, 0),
    moment=(0, 0, 0),
    follower=False,
    kinematics=FULL,
):
    """One clamped beam named "b" with a tip load at "b:end" (probe "tip")."""
    beam = Beam("b", curve, section, elements, degree)
    return Model(
        beams=(beam,),
        supports=(Support("b:start", CLAMP),),
        point_loads=(
            PointLoad("b:end", tuple(force), tuple(moment), "follower" if follower else "dead"),
        ),
        kinematics=kinematics,
    )


def straight(L):
    return Line((0.0, 0.0, 0.0), (L, 0.0, 0.0))


def arc(geometry):
    """The arc of a reference file's ``geometry`` entry."""
    return Arc(
        tuple(geometry["start"]),
        tuple(geometry["start_tangent"]),
        tuple(geometry["centre"]),
        geometry["angle_deg"],
    )
