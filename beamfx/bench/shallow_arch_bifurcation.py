"""Howcroft et al. (2016) §4.2 without shear and extension flexibility: the antisymmetric
bifurcation of the shallow pinned arch (``beamfx/scenes/shallow_arch_bifurcation.toml``).

The perfect inextensible arch under a uniform radial load keeps its shape (the mixed
formulation's exact constraints, which "auto" chooses; a penalty would shorten it by q R/EA,
1e-5) until its tangent has a zero eigenvalue with an antisymmetric null vector:
the arc-length trace counts the negative eigenvalues (inertia) at every point, locates the
change by regula falsi on the arc length and switches onto the secondary branch.

Two theories bracket the load. Shallow-arch theory (:func:`.shallow_arch.shallow_theory` with
EA → ∞): the antisymmetric mode's own Euler thrust H = 4π²EI/S² reached at H ≈ qR (the
membrane state), q = 4π²EI/(S²R) ≈ 6667 N/m; it neglects the arch's depth, O((rise/span)²)
≈ 1 %. The deep-arch formula for a pressure that stays normal to the arch (Timoshenko & Gere
§7.5), q = (EI/R³)(π²/α² − 1) = 6562.5 N/m, α = π/8 the half angle. A dead radial load
(fixed direction) differs from a follower pressure by its load stiffness: here the direction
is fixed, and the point lies between the two. The independent check on the same mesh is the
linear buckling analysis about the current state (``about = "current"``) just below the
point, on the planar model: with no pre-buckling rotation the path is linear and its
critical load is the located one up to the location's precision.
"""

import numpy as np

from .registry import register
from .scenes import SceneCase
from .shallow_arch import ANGLE, A, E, I, R, _scene, scene_data, theory_loads

Q_BIF = 7500.0  # N/m, the scene's reference load (load factor 1)
Q_BELOW = 6500.0  # N/m, the state of the linear buckling check (below both theories)
PENALTY = 1e8  # [model] stretch = false: EA raised to about 1e8·EI/L² (sections.with_limits)


def theories():
    """The two theoretical bifurcation loads, N/m: shallow (inextensible) and deep (follower)."""
    alpha = ANGLE / 2
    return {
        "q_shallow": theory_loads(PENALTY * E * A)["q_bifurcation"],
        "q_deep_follower": E * I / R**3 * (np.pi**2 / alpha**2 - 1),
    }


def buckling_data(n=None, p=None, q=Q_BELOW):
    """The scene's arch, in the plane, under ``q`` N/m: linear buckling about that state."""
    data = scene_data("shallow_arch_bifurcation", n, p)
    data["loads"][0]["force_per_length"] = [0.0, -q, 0.0]
    data["model"]["plane"] = "yz"  # the in-plane modes (the 3D arch buckles out of plane first)
    # the arc-length trace's model: "auto" takes the mixed form for both (exact constraints,
    # 5.7e-6 above the penalty's load at 16 × P3); stated, so that both sides keep one model
    data["model"]["formulation"] = "mixed"
    data["analysis"] = {"type": "buckling", "about": "current", "modes": 1, "steps": 5}
    data.pop("probes", None)
    return data


def _read_bifurcation(result):
    point = next(c for c in result.critical_points if c["kind"] == "bifurcation")
    lo, hi = point["load_factor_bracket"]
    return {"q_bifurcation": point["load_factor"] * Q_BIF, "q_bracket": (hi - lo) * Q_BIF}


def _read_buckling(result):
    return {"q_buckling": result.load_factors[0] * Q_BELOW}


def _settings(n, p):
    name = "shallow_arch_bifurcation"
    return [
        (_scene(n, p, name), _read_bifurcation),
        (_scene(n, p, name, buckling_data(n, p)), _read_buckling),
    ]


THEORY = theories()

register(
    SceneCase(
        "shallow_arch_bifurcation",
        "Howcroft et al. 2016, 4.2",
        "Shallow pinned arch, shear-rigid and inextensible: antisymmetric bifurcation load",
        _settings,
        lambda values: values,
        None,
        1e-6,
        tuple((n, p) for p in (3, 4) for n in (4, 8, 16, 32)),  # 2 cubics: no membrane state
        scale=THEORY["q_shallow"],  # error relative to the load (the bracket is a width)
        note='Arc-length trace of the scene as shipped (7500 N/m, branch = "secondary"): '
        "q_bifurcation is the located point (regula falsi on the arc length; q_bracket the "
        "width of the load interval the inertia puts it in), q_buckling the in-plane linear "
        f"buckling load about the state at {Q_BELOW:.0f} N/m on the same mesh (independent "
        "check). Reference withheld: the finest setting is the reference. Theories: shallow "
        f"arch, inextensible, {THEORY['q_shallow']:.1f} N/m (O(1 %)); deep arch under a "
        f"follower pressure {THEORY['q_deep_follower']:.1f} N/m (Timoshenko & Gere); the dead "
        "radial load lies between. The full 3D model buckles out of plane first (about "
        "6357 N/m with these supports).",
    )
)
