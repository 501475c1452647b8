"""The star dome's snap-through: beamfx beside OpenSeesPy (corotational frame elements).

Run by ``make bench-peers``::

    python -m beamfx.bench.star_dome_peers export DIR       # DIR/star_dome_problem.json
    .venv-peers/bin/python peers/opensees_star_dome.py DIR  # DIR/opensees_star_dome.json
    python -m beamfx.bench.star_dome_peers DIR [REPORT]     # DIR/star_dome_compare.json,
                                                            # REPORT/star_dome.md and .png

Both codes trace the symmetric path of the dome of :mod:`~beamfx.bench.star_dome` (beamfx by
arc length, the demo scene through :func:`~beamfx.runner.run_scene`; OpenSees by displacement
control of the apex) on a sequence of meshes (elements per member; beamfx also the degree),
and report the limit load. Each sequence's convergence is judged on its own: the differences
between successive meshes, and the extrapolated value (Richardson, from the last three).
Two section variants (:data:`~beamfx.bench.star_dome.BENDING_SCALE`): the scene's I = 2.377 cm⁴
and the slender I = 0.2377 cm⁴, whose apex snaps through locally first.
"""

import json
import sys
import tempfile
from pathlib import Path

import numpy as np

from . import star_dome

OPENSEES_ELEMENTS = (1, 2, 4, 8, 16)
BEAMFX_SETTINGS = tuple((n, p) for p in (2, 3) for n in (1, 2, 4, 8))
STEP = 0.01  # cm: OpenSees' displacement increment of the apex
#: cm: how far the apex is pushed: past the limit point (about 8.5 cm), past the first limit
#: (about 1.1 cm) and the minimum (about 2.3 cm) of the slender dome
LIMITS = {"star_dome": 9.5, "star_dome_slender": 3.0}


def problem(variant="star_dome"):
    """The dome as plain data for the peer: nodes, members, supports (fixed dofs), apex, load,
    the stiffnesses of the (one) section, each member's vecxz, the peer's meshes and step."""
    from ..geometry.line_mesh import read_line_mesh

    frame = star_dome.scene_data(variant=variant)["frames"][0]
    mesh = read_line_mesh(star_dome.DEMOS / frame["mesh"])
    sections = {tuple(m["section"].items()) for m in frame["members"]}
    if len(sections) != 1 or frame["supports"][0]["fix"] != "pinned":
        raise ValueError("star_dome.toml: not the one-section pinned dome this comparison expects")
    section = frame["members"][0]["section"]
    nodes, members = mesh.points, mesh.members
    chords = nodes[members[:, 1]] - nodes[members[:, 0]]
    # I_y = I_z and one shear-rigid section: the results do not depend on the section axes
    vecxz = [
        [0.0, 0.0, 1.0] if abs(c[2]) < 0.9 * np.linalg.norm(c) else [1.0, 0.0, 0.0] for c in chords
    ]
    (apex,) = mesh.node_groups["apex"]
    return {
        "name": variant,
        "nodes": nodes.tolist(),
        "members": members.tolist(),
        "supports": [int(i) for i in mesh.node_groups["base"]],
        "fix": [1, 1, 1, 0, 0, 0],
        "apex": int(apex),
        "load": [*frame["loads"][0]["force"], 0.0, 0.0, 0.0],
        "stiffness": {k: section[k] for k in ("EA", "GJ", "EI_y", "EI_z")},
        "vecxz": vecxz,
        "elements": list(OPENSEES_ELEMENTS),
        "step": STEP,
        "displacement_limit": LIMITS[variant],
    }


def export(out_dir):
    """Write DIR/star_dome_problem.json: ``{"problems": [one per variant]}``."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    problems = {"problems": [problem(v) for v in LIMITS]}
    (out / "star_dome_problem.json").write_text(json.dumps(problems))


def beamfx_trace(elements, degree, folder, variant="star_dome"):
    """The arc-length trace by beamfx of one mesh through ``run_scene``: the first limit
    point, every extremum of the load, the path (load factor, apex uz), the run's wall time."""
    from .scenes import run_in_process

    data = star_dome.scene_data(elements, degree, variant)
    data["analysis"]["displacement_limit"] = ["uz", -LIMITS[variant]]
    data["analysis"]["arc_length"] = LIMITS[variant] / 30
    scene = star_dome.scene(data=data)
    run, seconds = run_in_process(scene, folder)
    path = run.result.path
    extrema = [(p["kind"], p["load_factor"], p["displacement"][2]) for p in run.result.limit_points]
    return {
        "variant": variant,
        "elements": elements,
        "degree": degree,
        **star_dome.read_limit(run.result),
        "extrema": extrema,
        "wall_s": seconds,
        "load": [p["load_factor"] for p in path],
        "uz": [p["displacement"][2] for p in path],
        "critical_points": [(c["kind"], c["interval"]) for c in run.result.critical_points],
    }


def richardson(values):
    """The limit of the last three values of a sequence that halves h (None if it does not
    converge monotonically there)."""
    if len(values) < 3:
        return None
    a, b, c = values[-3:]
    if (b - a) * (c - b) <= 0 or abs(c - b) >= abs(b - a):
        return None
    return c - (c - b) ** 2 / ((c - b) - (b - a))


def table(rows, label):
    """Markdown lines of one code's convergence table, a row per mesh (elements per member)."""
    lines = [
        f"| {label} | limit load P (kN) | apex uz (cm) | change | wall (s) |",
        "|---|---|---|---|---|",
    ]
    for i, r in enumerate(rows):
        change = "" if i == 0 else f"{r['limit_load'] - rows[i - 1]['limit_load']:+.2e}"
        lines.append(
            f"| {r['elements']} | {r['limit_load']:.6f} | {r['limit_uz']:.4f} | {change} | {r['wall_s']:.1f} |"
        )
    return lines


TITLES = {
    "star_dome": "I = 2.377 cm⁴ (the scene)",
    "star_dome_slender": "I = 0.2377 cm⁴ (the slender dome)",
}


def _extrema(r):
    return "; ".join(f"{k} {P:.4f} kN at uz {u:.3f} cm" for k, P, u in r["extrema"])


def variant_report(variant, runs, opensees):
    """Markdown lines of one variant: both codes' convergence tables of the first limit."""
    lines = [f"## {TITLES[variant]}", ""]
    for p in sorted({r["degree"] for r in runs}):
        rows = [r for r in runs if r["degree"] == p]
        lines += table(rows, f"beamfx P{p}, elements per member")
        x = richardson([r["limit_load"] for r in rows])
        lines += ["", f"Extrapolated (last three): {x:.6f} kN" if x else "", ""]
    lines += table(opensees, "OpenSees, elements per member")
    x = richardson([r["limit_load"] for r in opensees])
    lines += ["", f"Extrapolated (last three): {x:.6f} kN" if x else "", ""]
    finest = runs[-1]
    crit = "; ".join(
        f"{k} between load factors {a:.5g} and {b:.5g}" for k, (a, b) in finest["critical_points"]
    )
    lines += [
        (
            f"Extrema of the load along the traced path, beamfx {finest['elements']} "
            f"P{finest['degree']}: {_extrema(finest)}. OpenSees {opensees[-1]['elements']} "
            f"elements: {_extrema(opensees[-1])}."
        ),
        "",
        f"Critical points passed by beamfx's finest trace (inertia of the tangent): {crit}.",
        "",
    ]
    return lines


def report(runs, opensees, meta):
    """The markdown report: both variants' convergence tables and extrapolated limits."""
    lines = [
        "# Star dome snap-through: beamfx beside OpenSeesPy",
        "",
        (
            "Made by `python -m beamfx.bench.star_dome_peers` (`make bench-peers`). The 24-member "
            "star dome of demos/scenes/star_dome.toml (units cm, kN; pinned supports, shear-rigid "
            "members, E = 3030, G = 1096, A = 3.17, J = 2.1), apex load P: the first limit load "
            "of the symmetric path. beamfx: arc length through `run_scene`; OpenSeesPy "
            f"{meta.get('openseespy', '?')}: {meta.get('element', '?')}, displacement control of "
            f"the apex in steps of {STEP} cm, each extremum at the vertex of a parabola through "
            "three points. No published limit load could be checked offline. Wall times: one "
            "run each on a shared, loaded 2-core machine (noisy); OpenSees' are long because of "
            "its many small displacement steps, not a like-for-like cost comparison. beamfx "
            "places a limit point by a quadratic fit between arc-length steps, to about 1e-4 "
            "of the load: a sequence whose last change is below that (its sign flips) gets no "
            "extrapolated value. Along both variants' paths the apex keeps moving down (no "
            "snap-back in its displacement), so displacement control traces them too."
        ),
        "",
        (
            "Section values: I_y = I_z = 2.377 cm⁴ with A = 3.17 cm² (I/A² = 0.24) needs a hollow "
            "section, whose J would be about 2I = 4.75 cm⁴, not 2.1; if the literature's values "
            "were in mm (A = 317 mm², I = 2377 mm⁴), I = 0.2377 cm⁴, which no section with "
            "I_y = I_z reaches (I/A² = 0.024 < 1/(4π)). Both are traced: the scene's values "
            "(the dome snaps through as a whole, the apex near the base plane) and the slender "
            "dome (the apex snaps through locally first)."
        ),
        "",
    ]
    for variant in LIMITS:
        mine = [r for r in runs if r["variant"] == variant]
        theirs = [r for r in opensees if r["variant"] == variant]
        if mine and theirs:
            lines += variant_report(variant, mine, theirs)
    lines += ["![load-apex displacement](star_dome.png)", ""]
    return "\n".join(lines)


def plot(runs, opensees, path):
    """Load against apex displacement, one panel per variant: beamfx's finest trace of each
    degree and OpenSees' finest, the extrema marked."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(LIMITS), figsize=(11, 4.5))
    for ax, variant in zip(axes, LIMITS):
        mine = [r for r in runs if r["variant"] == variant]
        finest = [max((r for r in mine if r["degree"] == p), key=lambda r: r["elements"])
                  for p in sorted({r["degree"] for r in mine})]  # fmt: skip
        for r in finest:
            label = f"beamfx arc length, {r['elements']} P{r['degree']} per member"
            ax.plot(-np.array(r["uz"]), r["load"], ".-", ms=3, label=label)
        o = [r for r in opensees if r["variant"] == variant][-1]
        label = f"OpenSees corotational, {o['elements']} elements per member"
        ax.plot(-np.array(o["uz"]), o["load"], "k--", lw=1, label=label)
        for r in [*finest, o]:
            ax.plot([-u for _, _, u in r["extrema"]], [P for _, P, _ in r["extrema"]], "rx")
        ax.set_xlabel("apex displacement downward (cm)")
        ax.set_ylabel("apex load P (kN)")
        ax.set_title(f"24-member star dome, {TITLES[variant]}", fontsize=10)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def compare(out_dir, report_dir=None):
    """Run beamfx's sequences, read OpenSees' (DIR/opensees_star_dome.json), write
    DIR/star_dome_compare.json and, with ``report_dir``, star_dome.md and star_dome.png."""
    out = Path(out_dir)
    peer = json.loads((out / "opensees_star_dome.json").read_text())
    runs = []
    with tempfile.TemporaryDirectory(prefix="beamfx-star-dome-") as tmp:
        for variant in LIMITS:
            for n, p in BEAMFX_SETTINGS:
                runs.append(beamfx_trace(n, p, Path(tmp) / f"{variant}-{n}-{p}", variant))
                limit = runs[-1]["limit_load"]
                print(f"beamfx {variant}, {n} P{p} per member: first limit {limit:.6g}")
    (out / "star_dome_compare.json").write_text(
        json.dumps({"beamfx": runs, "opensees": peer["records"], "meta": peer["meta"]})
    )
    if report_dir is not None:
        folder = Path(report_dir)
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "star_dome.md").write_text(report(runs, peer["records"], peer["meta"]))
        plot(runs, peer["records"], folder / "star_dome.png")


def main(argv):
    """``export DIR`` or ``DIR [REPORT_DIR]``."""
    from .frame_peers import cli

    cli(argv, export, compare, "beamfx.bench.star_dome_peers")


if __name__ == "__main__":
    main(sys.argv[1:])
