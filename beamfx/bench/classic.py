"""Classic cases with exact references (classic_cases.json): roll-up and Mattiasson's elastica."""

import numpy as np

from ..geometry import Line
from ..physics.sections import Section
from ._builders import cantilever, straight
from .registry import Case, reference, register

ROLL = reference("classic_cases.json", "ROLLUP")
L = 10.0
ROLL_SECTION = Section(EA=1770e3, GA_y=1770e3, GA_z=1770e3, GJ=8.16e3, EI_y=86.9e3, EI_z=215e3)


#: one to four P1 elements (closed-form centre line), one P2 (quadrature), and the P3/P4 meshes
#: the full model needed
ROLL_SETTINGS = ((1, 1), (2, 1), (4, 1), (1, 2), (4, 3), (4, 4))


def _rollup(lam):
    phi = 2 * np.pi * lam
    M = phi * ROLL_SECTION.EI_y / L

    def build(n, p):
        # a moment -M about y rolls the beam up towards +z
        return cantilever(straight(L), ROLL_SECTION, n, p, moment=(0, -M, 0)), max(4, int(8 * lam))

    ref = {"x": L * np.sin(phi) / phi, "y": 0.0, "z": L * (1 - np.cos(phi)) / phi}
    return build, ref


def _position(values):
    x = values["tip"]["position"]
    return {"x": x[0], "y": x[1], "z": x[2]}


for lam in ROLL["spec"]["lambda_values"]:
    build, ref = _rollup(lam)
    register(
        Case(
            f"rollup_{lam:g}",
            "Simo & Vu-Quoc 1986 (classic)",
            f"Roll-up, tip moment {lam:g}·2πEI/L",
            build,
            _position,
            ref,
            1e-6,
            ROLL_SETTINGS,
            scale=L,
            note="exact circle x = L sin φ/φ, z = L(1 - cos φ)/φ; error relative to L. The "
            "scene builder picks the planar statically condensed model (a plane cantilever "
            "under an end moment): the angle, linear in s, is exact on any mesh and the centre "
            "line is integrated in closed form, so one P1 element is exact to round-off.",
        )
    )

MATT = reference("classic_cases.json", "MATTIASSON")
EI_M = 1.0
MATT_SECTION = Section(EA=1e7, GA_y=1e7, GA_z=1e7, GJ=1.0, EI_y=EI_M, EI_z=EI_M)


def _mattiasson(row):
    k, u, w, phi = row

    def build(n, p):
        return cantilever(
            Line((0, 0, 0), (1.0, 0, 0)), MATT_SECTION, n, p, force=(0, 0, k * EI_M)
        ), 10

    return build, {"u": u, "w": w, "phi": phi}


def _elastica(values):
    t = values["tip"]
    return {"u": -t["displacement"][0], "w": t["displacement"][2], "phi": t["angle"]}


for row in MATT["reference"]["table"]:
    if row[0] in (1, 5, 10):
        build, ref = _mattiasson(row)
        register(
            Case(
                f"mattiasson_k{row[0]:g}",
                "Mattiasson 1981 (classic)",
                f"Elastica cantilever, k = {row[0]:g}",
                build,
                _elastica,
                ref,
                1e-5,
                tuple((n, p) for p in (3, 4) for n in (4, 8, 16)),
                scale=1.0,
                note="EA = GA = 1e7 EI/L^2 approximates the inextensible, unshearable rod (error ~1e-7); "
                "table values to 7 digits.",
            )
        )
