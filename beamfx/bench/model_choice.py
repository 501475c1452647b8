"""The report's account of which model each case times: the scene builder's pick for a user's
scene (:func:`beamfx.scene.load.choose_model`, as ``beamfx run``), or the case's own, and why."""

#: the cases whose model changed when the bench took the user's path (issue 15):
#: (cases, model as built before, the model the scene builder picks, why)
MOVED = (
    (
        "bend45_vertical, bend45_follower",
        "full",
        "condensed",
        (
            "a static clamped cantilever under a tip force; not a plane problem (the force "
            "leaves the bend's plane)"
        ),
    ),
    (
        "mattiasson_k1, mattiasson_k5, mattiasson_k10",
        "full",
        "planar condensed (xz)",
        "a static clamped cantilever under a tip force in the xz plane",
    ),
    (
        "sm23_end_moments, sm24_quarter_circle",
        "full",
        "condensed",
        "a static clamped cantilever under tip loads that leave every coordinate plane",
    ),
    (
        (
            "sm21_shear_rigid, sm22_F_z, sm22_M_x, sm26_lateral_buckling, sm28_free_free_eigen, "
            "sm29_prestressed, lattice_buckling"
        ),
        "penalty limits",
        "mixed formulation",
        (
            "shear-rigid or inextensible: exact constraints instead of the penalty 1e8 EI/L² "
            '([model] formulation = "auto", issue 16)'
        ),
    ),
)


def intro_lines():
    """The report intro's paragraph and table on the model each case runs."""
    lines = [
        "",
        (
            "**Model.** Every case runs the model the scene builder picks for a user's scene of "
            "it (`beamfx.scene.load.choose_model`, the call behind `beamfx run`: the planar "
            "model where the scene is a plane problem, the statically condensed one for a "
            "static clamped cantilever under point loads), so its times are the times a user "
            "gets; the *model* column says which. A case marked *own* times a model of its own "
            "and its section says why. When the bench took this path (issue 15) the values of "
            "the cases below moved: the condensed models interpolate the rotation vector (or "
            "the plane angle) and integrate the centre line, the full model interpolates "
            "displacement and quaternion, so the two agree to the discretisation error, not to "
            "round-off. Every case still passes; where the discretisation error dominates the "
            "condensed model's error is the smaller one, and where both have converged they "
            "agree to the reference's own floor (Mattiasson: EA = 1e7 EI/L², about 1e-7 to "
            "1e-6; bend45: the finest setting of the same model)."
        ),
        "",
        "| cases | model before | model now | why the scene builder picks it |",
        "|---|---|---|---|",
    ]
    lines += [f"| {a} | {b} | {c} | {d} |" for a, b, c, d in MOVED]
    return lines


def formulation(entry):
    """What solved a run, from its results.json ``model`` entry: "planar condensed",
    "condensed", "planar" or "full", the last two with " mixed" for the mixed formulation."""
    if entry.get("condensed"):
        return "planar condensed" if entry.get("plane") else "condensed"
    kind = "planar" if entry.get("plane") else "full"
    mixed = (entry.get("formulation") or {}).get("name") == "mixed"
    return f"{kind} mixed" if mixed else kind


def _kind(row):
    """The model that solved a row: its formulation (or an adaptive row's model), or None."""
    return (row or {}).get("formulation") or (row or {}).get("model")


def model_cell(r, row):
    """The summary table's model of a case at ``row``: the formulation that solved it, or
    "own" where the case times a model of its own."""
    return "own" if r.get("own_model") else _kind(row) or "-"


def case_model_line(r):
    """A case section's line on its model: the scene builder's pick, or the case's own and
    why."""
    kinds = list(dict.fromkeys(_kind(row) for row in r["rows"] if _kind(row)))
    if r.get("own_model"):
        return f"Model: its own, not the scene builder's pick: {r['own_model']}."
    solved = f" ({', '.join(kinds)})" if kinds else ""
    return f"Model: the one `beamfx run` picks for the case's scene{solved}."
