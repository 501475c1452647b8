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
"""

import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from . import star_dome

OPENSEES_ELEMENTS = (1, 2, 4, 8, 16)
BEAMFX_SETTINGS = tuple((n, p) for p in (2, 3) for n in (1, 2, 4, 8))
STEP = 0.01  # cm: OpenSees' displacement increment of the apex
DISPLACEMENT_LIMIT = 9.5  # cm: past the limit point (about 8.5 cm)


def problem():
    """The dome as plain data for the peer: nodes, members, supports (fixed dofs), apex, load,
    the stiffnesses of the (one) section, each member's vecxz, the peer's meshes and step."""
    from ..geometry.line_mesh import read_line_mesh

    data = star_dome.scene_data()
    frame = data["frames"][0]
    mesh = read_line_mesh(star_dome.DEMOS / frame["mesh"])
    sections = {m["section"]["EA"] for m in frame["members"]}
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
        "displacement_limit": DISPLACEMENT_LIMIT,
    }


def export(out_dir):
    """Write DIR/star_dome_problem.json."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    (out / "star_dome_problem.json").write_text(json.dumps(problem()))


def beamfx_trace(elements, degree, folder):
    """The arc-length trace by beamfx of one mesh through ``run_scene``: the limit point, the path
    (load factor, apex uz) and the whole run's wall time."""
    from ..runner import run_scene

    data = star_dome.scene_data(elements, degree)
    data["analysis"]["displacement_limit"] = ["uz", -DISPLACEMENT_LIMIT]
    scene = star_dome.scene(data=data)
    t0 = time.perf_counter()
    run = run_scene(scene.file, folder, log=lambda *a, **k: None, scene=scene)
    seconds = time.perf_counter() - t0
    path = run.result.path
    return {
        "elements": elements,
        "degree": degree,
        **star_dome.read_limit(run.result),
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
    """Markdown lines of one code's convergence table."""
    lines = [
        f"| {label} | limit load P (kN) | apex uz (cm) | change | wall (s) |",
        "|---|---|---|---|---|",
    ]
    for i, r in enumerate(rows):
        change = "" if i == 0 else f"{r['limit_load'] - rows[i - 1]['limit_load']:+.2e}"
        lines.append(
            f"| {r['setting']} | {r['limit_load']:.6f} | {r['limit_uz']:.4f} | {change} | {r['wall_s']:.1f} |"
        )
    return lines


def _rows(records, key):
    return [{**r, "setting": key(r)} for r in records]


def report(beamfx_runs, opensees, meta):
    """The markdown report: both convergence tables and their extrapolated limits."""
    lines = [
        "# Star dome snap-through: beamfx beside OpenSeesPy",
        "",
        (
            "Made by `python -m beamfx.bench.star_dome_peers` (`make bench-peers`). The 24-member "
            "star dome of demos/scenes/star_dome.toml (units cm, kN; pinned supports, shear-rigid "
            "members, E = 3030, G = 1096, A = 3.17, I_y = I_z = 2.377, J = 2.1), apex load P: the "
            "limit load of the symmetric path. beamfx: arc length through `run_scene`; OpenSeesPy "
            f"{meta.get('openseespy', '?')}: {meta.get('element', '?')}, displacement control of "
            f"the apex in steps of {STEP} cm, limit at the vertex of a parabola through the three "
            "highest points. No published limit load could be checked offline for these values."
        ),
        "",
    ]
    for p in sorted({r["degree"] for r in beamfx_runs}):
        rows = [r for r in beamfx_runs if r["degree"] == p]
        lines += table(_rows(rows, lambda r: r["elements"]), f"beamfx P{p}, elements per member")
        x = richardson([r["limit_load"] for r in rows])
        lines += ["", f"Extrapolated (last three): {x:.6f} kN" if x else "", ""]
    lines += table(_rows(opensees, lambda r: r["elements"]), "OpenSees, elements per member")
    x = richardson([r["limit_load"] for r in opensees])
    lines += ["", f"Extrapolated (last three): {x:.6f} kN" if x else "", ""]
    crit = beamfx_runs[-1]["critical_points"]
    lines += [
        "Critical points passed by beamfx's finest trace (inertia of the tangent): "
        + "; ".join(f"{k} between load factors {a:.4g} and {b:.4g}" for k, (a, b) in crit)
        + ". The bifurcation (two negative eigenvalues: the pair of asymmetric modes) comes "
        "just before the symmetric limit; both codes stay on the symmetric path.",
        "",
        "![load-apex displacement](star_dome.png)",
        "",
    ]
    return "\n".join(lines)


def plot(beamfx_runs, opensees, path):
    """Load against apex displacement: beamfx's finest trace of each degree and OpenSees'
    finest, the limit points marked."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    finest = [max((r for r in beamfx_runs if r["degree"] == p), key=lambda r: r["elements"])
              for p in sorted({r["degree"] for r in beamfx_runs})]  # fmt: skip
    for r in finest:
        label = f"beamfx arc length, {r['elements']} P{r['degree']} per member"
        ax.plot(-np.array(r["uz"]), r["load"], ".-", ms=3, label=label)
    o = opensees[-1]
    label = f"OpenSees corotational, {o['elements']} elements per member"
    ax.plot(-np.array(o["uz"]), o["load"], "k--", lw=1, label=label)
    for r in [*finest, o]:
        ax.plot(-r["limit_uz"], r["limit_load"], "rx")
    ax.set_xlabel("apex displacement downward (cm)")
    ax.set_ylabel("apex load P (kN)")
    ax.set_title("24-member star dome, apex load")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def compare(out_dir, report_dir=None):
    """Run beamfx's sequence, read OpenSees' (DIR/opensees_star_dome.json), write
    DIR/star_dome_compare.json and, with ``report_dir``, star_dome.md and star_dome.png."""
    out = Path(out_dir)
    peer = json.loads((out / "opensees_star_dome.json").read_text())
    runs = []
    with tempfile.TemporaryDirectory(prefix="beamfx-star-dome-") as tmp:
        for n, p in BEAMFX_SETTINGS:
            runs.append(beamfx_trace(n, p, Path(tmp) / f"{n}-{p}"))
            print(f"beamfx star dome, {n} P{p} per member: limit {runs[-1]['limit_load']:.6g}")
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
    if len(argv) == 2 and argv[0] == "export":
        export(argv[1])
    elif len(argv) in (1, 2) and argv[0] != "export":
        compare(*argv)
    else:
        raise SystemExit(
            "usage: python -m beamfx.bench.star_dome_peers export DIR | DIR [REPORT_DIR]"
        )


if __name__ == "__main__":
    main(sys.argv[1:])
