"""Howcroft et al. (2016): the 45-degree bend (Bathe & Bolourchi 1979), vertical and follower."""

import numpy as np

from ..physics import sections
from ._builders import arc, cantilever
from .registry import Case, reference, register

FILE = "howcroft_2016.json"
V = reference(FILE, "bend45_vertical")
SIZES = reference(FILE, "bend45_problem_size")
S = V["section"]
E = S["E"]
SECTION = sections.rectangle(E, E / 2, 1.0, 1.0, 1.0, torsion=S["GJ"] / (E / 2), nu=0.0)
F = V["loads"]["F_z"]
PUBLISHED = np.array(list(V["reference_tip_position"].values()))
SETTINGS = tuple((n, p) for p in (2, 3, 4) for n in (1, 2, 4, 8, 16))


def _measure(values):
    x = values["tip"]["position"]
    return {"x": x[0], "y": x[1], "z": x[2]}


def _build(follower):
    return lambda n, p: (
        cantilever(arc(V["geometry"]), SECTION, n, p, (0, 0, F), follower=follower),
        10,
    )


register(
    Case(
        "bend45_vertical",
        "Howcroft et al. 2016",
        "45-degree bend, vertical tip load",
        _build(False),
        _measure,
        None,
        1e-3,
        SETTINGS,
        scale=1.0,
        note="published tip positions spread over x 15.54-15.9, y 46.84-47.23, z 53.37-53.71; "
        "the check is that the converged tip lies inside that spread. 1 mm criterion: the "
        "smallest model whose tip moves by less than 1 mm when its unknowns are doubled.",
        extra={
            "published": V["reference_tip_position"],
            "problem_size": SIZES["published"],
            "spread": [PUBLISHED.min(axis=0).tolist(), PUBLISHED.max(axis=0).tolist()],
        },
    )
)
register(
    Case(
        "bend45_follower",
        "Howcroft et al. 2016",
        "45-degree bend, follower tip load",
        _build(True),
        _measure,
        None,
        1e-3,
        SETTINGS,
        scale=1.0,
        note="reference withheld: converged here (finest setting is the reference). The force "
        "turns with the tip section (initially along global z).",
        extra={"problem_size": SIZES["published"]},
    )
)
