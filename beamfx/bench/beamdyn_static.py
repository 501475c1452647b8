"""Two large-deflection static cases of BeamDyn's regression tests (OpenFAST r-test,
``modules/beamdyn``), against the numbers BeamDyn printed (``bd_driver.out``).

The scenes are ``meshes/beamdyn_rtest/*.toml`` (see its README for the files and commits); they
read the 6×6 matrices from BeamDyn primary and blade files (``section = { type = "beamdyn" }``,
openfast-io). Conventions, each checked:

* BeamDyn's section axes (x1, x2, x3) are beamfx's (y, z, x); the beams run along global z with
  x1 = global x at the root, so ``orientation = [0, 1, 0]``.
* BeamDyn's ``initial_twist`` turns the section the other way round from ``twist_deg`` (right-
  hand rule about the tangent): ``twist_deg = −initial_twist``. The data decide it: the twisted
  beam is mirror-symmetric about the plane x = 0 except for the sense of its twist, so the
  sign of the tip's x displacement under the load along −y is the sign of the twist (linear:
  x = −2.18 m with twist_deg = +90°, +2.18 m with −90°; BeamDyn's nonlinear x is +1.72 m).
* BeamDyn's tip rotation is given by Wiener–Milenkovic parameters c, a rotation by
  φ = 4 atan(|c|/4) about c/|c| relative to the undeformed tip, in global axes: beamfx's
  ``rotation_vector`` (:func:`rotation_vector`).
* BeamDyn's root "reaction" is the force and moment the beam exerts on its root (its RootFxr …
  equal the applied load and its moment), beamfx's ``reactions`` the support's force on the
  beam: the bench compares BeamDyn's with minus beamfx's.

BeamDyn's numbers are its discretisation's (one element of order 5, resp. 7), not exact
solutions. The twisted case is scored against them, within how far BeamDyn agreed with ANSYS
in the paper; the gravity cantilever against the exact beam (:mod:`.beamdyn_lsfe`), with
BeamDyn's number and its estimated discretisation error beside it in the report. No
tolerance is fitted to the result.
"""

import math
import tomllib
from pathlib import Path

import numpy as np

from .matrix_cost import cost_lines, matrix_cost
from .registry import register
from .scenes import SceneCase

FOLDER = Path(__file__).resolve().parents[2] / "meshes" / "beamdyn_rtest"
GRAVITY = FOLDER / "cantilever_gravity.toml"
TWISTED = FOLDER / "twisted_beam.toml"

#: bd_driver.out of bd_static_cantilever_beam: tip displacement (m), tip rotation (WM c)
CANTILEVER_BD = {"u": (9.06014769, 0.0, -8.52177367), "c": (0.0, 1.61602534, 0.0)}
#: bd_driver.out of bd_static_twisted_with_k1: tip displacement, rotation, root force, moment
TWISTED_BD = {
    "u": (1.71810805, -3.59245231, -1.14114462),
    "c": (0.652044084, 0.340538298, -0.166342576),
    "F": (0.0, -4.0e6, 0.0),
    "M": (3.54354215e7, 0.0, -6.87243219e6),
}
#: Wang et al. (2017), the twisted beam's tip displacements by BeamDyn and ANSYS as the r-test
#: README quotes them, in the paper's axes (|x| is our |u_z|, |z| our |u_y|)
PAPER_BD = {"x": 1.132727, "z": 3.578671}
PAPER_ANSYS = {"x": 1.134192, "z": 3.584232}


def rotation_vector(c):
    """The rotation vector of Wiener–Milenkovic parameters ``c``: φ n, φ = 4 atan(|c|/4),
    n = c/|c| (Bauchau, Flexible Multibody Dynamics, 2011; BeamDyn's TipRD outputs)."""
    c = np.asarray(c, float)
    size = np.linalg.norm(c)
    return c * (4 * math.atan(size / 4) / size) if size > 0 else c


def _values(u, theta, keys, force=None, moment=None):
    named = {f"u{a}": v for a, v in zip("xyz", u)} | {f"r{a}": v for a, v in zip("xyz", theta)}
    if force is not None:
        named |= {f"F{a}": v for a, v in zip("xyz", force)}
        named |= {f"M{a}": v for a, v in zip("xyz", moment)}
    return {k: float(named[k]) for k in keys}


#: the compared quantities (the zero ones by symmetry or statics are left out of the relative
#: error; the tests check them)
CANTILEVER_KEYS = ("ux", "uz", "ry")
TWISTED_KEYS = ("ux", "uy", "uz", "rx", "ry", "rz", "Mx", "Mz")


def reference(case):
    """BeamDyn's values of ``case`` ("cantilever" or "twisted") in the bench's names."""
    if case == "cantilever":
        bd = CANTILEVER_BD
        return _values(bd["u"], rotation_vector(bd["c"]), CANTILEVER_KEYS)
    bd = TWISTED_BD
    return _values(bd["u"], rotation_vector(bd["c"]), TWISTED_KEYS, bd["F"], bd["M"])


def scene(path, elements, degree, **analysis):
    """The shipped scene ``path`` with ``elements`` x P``degree`` (and ``[analysis]`` keys)."""
    from ..scene.load import parse_scene

    data = tomllib.loads(path.read_text())
    data["beams"][0].update(elements=elements, degree=degree)
    data["analysis"].update(analysis)
    return parse_scene(data, str(path), path.parent)


def read(result, keys):
    """The compared quantities of a static run: tip probe and minus the root reaction."""
    last = result.path[-1]
    tip = last["probes"]["tip"]
    (root,) = last["reactions"].values()
    force, moment = -np.asarray(root["force"]), -np.asarray(root["moment"])
    return _values(tip["displacement"], tip["rotation_vector"], keys, force, moment)


def _setting(path, keys):
    def build(elements, degree):
        return [(scene(path, elements, degree), lambda result: read(result, keys))]

    return build


def relative_spread(a, b):
    """The largest |a_k − b_k| / |b_k| over the keys of ``b``."""
    return max(abs(a[k] - b[k]) / abs(b[k]) for k in b)


#: BeamDyn against ANSYS in Wang et al. (2017): how far the published reference agrees with an
#: independent solver (1.6e-3), the tolerance of the twisted case
TWISTED_TOLERANCE = relative_spread(PAPER_BD, PAPER_ANSYS)


class BeamDynCase(SceneCase):
    """A :class:`SceneCase` that measures the 6×6 cost ratio (:func:`matrix_cost`) with its
    finest setting when ``extra["matrix_cost"]``."""

    def run_setting(self, elements, degree):
        """The setting's row, with ``matrix_cost`` at the finest setting."""
        row = super().run_setting(elements, degree)
        if self.extra.get("matrix_cost") and (elements, degree) == tuple(self.settings[-1]):
            row["matrix_cost"] = matrix_cost()
        return row


#: bd_static_cantilever_beam by :mod:`.beamdyn_lsfe`: one element of order 5 with 6 Gauss
#: points (BeamDyn's discretisation, planar) and the exact beam (tests/convergence checks them)
LSFE_ORDER5 = {"ux": 9.061264123996624, "uz": -8.528775108685556, "ry": 1.529017724336203}
EXACT = {"ux": 9.417614981449761, "uz": -8.389151489124796, "ry": 1.5636704629859577}
#: Roache's factor of safety on an error estimate (grid convergence index, 1.25)
SAFETY = 1.25


def beamdyn_lines(r):
    """Report lines of the gravity cantilever: its finest setting beside BeamDyn's number,
    their difference and BeamDyn's estimated discretisation error (nothing for other
    cases)."""
    if r["extra"].get("beamdyn") != "cantilever" or not r["rows"]:
        return []
    ours, theirs = r["rows"][-1]["values"], reference("cantilever")
    head = (
        "| quantity | beamfx (finest) | BeamDyn (1 element, order 5) | difference | BeamDyn's "
        "error (estimate x 1.25) | within |"
    )
    lines = ["", head, "|---|---|---|---|---|---|"]
    for k in CANTILEVER_KEYS:
        diff, error = ours[k] - theirs[k], SAFETY * abs(EXACT[k] - LSFE_ORDER5[k])
        lines.append(
            f"| {k} | {ours[k]:.8g} | {theirs[k]:.8g} | {diff:.4g} | {error:.4g} | "
            f"{'yes' if abs(diff) <= error else 'NO'} |"
        )
    return lines


def report_lines(r):
    """The extra report lines of these cases."""
    return beamdyn_lines(r) + cost_lines(r)


register(
    BeamDynCase(
        "bd_static_cantilever_beam",
        "OpenFAST r-test (BeamDyn regression test bd_static_cantilever_beam); exact beam here",
        "BeamDyn: 10 m cantilever bent by gravity into a near quarter circle (6x6 sections)",
        _setting(GRAVITY, CANTILEVER_KEYS),
        lambda values: values,
        EXACT,
        1e-4,
        tuple((n, p) for p in (2, 3, 4) for n in (1, 2, 4, 8, 16)),
        note="Reference: the exact beam (its planar boundary value problem solved to 1e-10, "
        "bench/beamdyn_lsfe.py), because BeamDyn's printed tip is that of one Legendre "
        "spectral element of order 5, not converged: a planar model of that element (the "
        "same module: order-5 Lagrange interpolation of displacements and Wiener-Milenkovic "
        "parameters, 6 Gauss points) gives ux 9.06126, uz -8.52878, ry 1.52902 against "
        "BeamDyn's 9.06015, -8.52177, 1.53582 (1.2e-4, 8.2e-4, 4.4e-3 relative), so "
        "BeamDyn's own discretisation error is about 3.9e-2 (ux), 1.6e-2 (uz), 2.3e-2 (ry) "
        "relative. The table below compares beamfx's finest setting with BeamDyn's number "
        "and that error (times Roache's factor of safety 1.25).",
        extra={"beamdyn": "cantilever"},
    )
)

register(
    BeamDynCase(
        "bd_static_twisted_with_k1",
        "OpenFAST r-test (bd_static_twisted_with_k1); Wang et al. 2017, Wind Energy, doi:10.1002/we.2101",
        "BeamDyn: twisted beam (0-90 deg) under a 4 MN tip force, tip and root reactions",
        _setting(TWISTED, TWISTED_KEYS),
        lambda values: values,
        reference("twisted"),
        TWISTED_TOLERANCE,
        tuple((n, p) for p in (2, 3, 4) for n in (1, 2, 4, 8, 16)),
        note="Reference: BeamDyn's printed tip displacement, rotation (Wiener-Milenkovic c "
        "as a rotation vector, phi = 4 atan(|c|/4)) and root moment (BeamDyn's root load is "
        "the beam's on the root: minus beamfx's reaction), one element of order 7. Tolerance: "
        "how far BeamDyn agreed with ANSYS in the paper (1.55e-3 relative, tip displacement). "
        "twist_deg = -initial_twist (the sign of u_x decides it; module doc). The row of the "
        "finest setting carries the 6x6 cost ratio below.",
        extra={"matrix_cost": True},
    )
)
