"""OpenSeesPy on the 24-member star dome of `python -m beamfx.bench.star_dome_peers export DIR`:
reads DIR/star_dome_problem.json, writes DIR/opensees_star_dome.json.

Each member is cut into n `elasticBeamColumn` elements (Euler-Bernoulli) with the
`Corotational` transformation (OpenSees' geometrically nonlinear frame element), E = G = 1 and
the section data as stiffnesses (A = EA, Jx = GJ, Iy = EI_y, Iz = EI_z). The apex is pushed
down by displacement control (`DisplacementControl` on its uz, Newton), so the path is traced
through the load's extrema (the apex's displacement grows monotonically along this path: no
snap-back in it); each extremum is the vertex of the parabola through it and its neighbours. (`ElasticTimoshenkoBeam` is not used: with a
`Corotational` transformation it stays linear in OpenSees 3.x.)

Runs in `.venv-peers` (openseespy, numpy; no beamfx).
"""

import json
import sys
import time
from importlib.metadata import version
from pathlib import Path

import numpy as np


def build(problem, n):
    """The OpenSees model of the dome with ``n`` elements per member."""
    import openseespy.opensees as ops

    ops.wipe()
    ops.model("basic", "-ndm", 3, "-ndf", 6)
    nodes = np.asarray(problem["nodes"], float)
    for i, x in enumerate(nodes):
        ops.node(i + 1, *x)
    for i in problem["supports"]:
        ops.fix(i + 1, *problem["fix"])
    EA, GJ, EI_y, EI_z = (problem["stiffness"][k] for k in ("EA", "GJ", "EI_y", "EI_z"))
    tag, element = len(nodes), 0
    for k, (a, b) in enumerate(problem["members"]):
        ids = [a + 1]
        for j in range(1, n):
            tag += 1
            ops.node(tag, *(nodes[a] + (nodes[b] - nodes[a]) * j / n))
            ids.append(tag)
        ids.append(b + 1)
        ops.geomTransf("Corotational", k + 1, *problem["vecxz"][k])
        for j in range(n):
            element += 1
            ops.element(
                "elasticBeamColumn", element, ids[j], ids[j + 1], EA, 1.0, 1.0, GJ, EI_y, EI_z,
                k + 1,
            )  # fmt: skip


def trace(problem, n):
    """Displacement-controlled path of the apex: arrays (load factor, apex uz)."""
    import openseespy.opensees as ops

    build(problem, n)
    apex = problem["apex"] + 1
    ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    ops.load(apex, *problem["load"])
    ops.system("UmfPack")
    ops.numberer("RCM")
    ops.constraints("Plain")
    ops.test("NormDispIncr", 1e-10, 50)
    ops.algorithm("Newton")
    ops.integrator("DisplacementControl", apex, 3, -problem["step"])
    ops.analysis("Static")
    path = [(0.0, 0.0)]
    while -path[-1][1] < problem["displacement_limit"]:
        if ops.analyze(1) != 0:
            raise RuntimeError(f"OpenSees: no convergence at apex uz {path[-1][1]:.4g}")
        path.append((ops.getLoadFactor(1), ops.nodeDisp(apex, 3)))
    return np.array(path).T


def extrema(load, uz):
    """[(kind, load, uz)] of every interior extremum of the load along the path, each at the
    vertex of the parabola through it and its two neighbours."""
    out = []
    for i in range(1, len(load) - 1):
        rise, fall = load[i] - load[i - 1], load[i + 1] - load[i]
        if rise * fall < 0:
            c = np.polyfit(uz[i - 1 : i + 2], load[i - 1 : i + 2], 2)
            u = -c[1] / (2 * c[0])
            out.append(("maximum" if rise > 0 else "minimum", float(np.polyval(c, u)), float(u)))
    return out


def run(out_dir):
    """Trace every refinement of every problem of DIR/star_dome_problem.json; write
    DIR/opensees_star_dome.json."""
    out_dir = Path(out_dir)
    problems = json.loads((out_dir / "star_dome_problem.json").read_text())["problems"]
    records = []
    for problem in problems:
        for n in problem["elements"]:
            t0 = time.perf_counter()
            load, uz = trace(problem, n)
            seconds = time.perf_counter() - t0
            found = extrema(load, uz)
            first = next((e for e in found if e[0] == "maximum"), None)
            if first is None:
                raise RuntimeError(f"OpenSees: {problem['name']}: no load maximum")
            records.append(
                {"variant": problem["name"], "elements": n, "limit_load": first[1],
                 "limit_uz": first[2], "extrema": found, "wall_s": seconds,
                 "load": load.tolist(), "uz": uz.tolist()}
            )  # fmt: skip
            print(f"opensees {problem['name']}, {n} per member: first limit {first[1]:.6g} "
                  f"at uz {first[2]:.5g} ({seconds:.1f} s)")  # fmt: skip
    meta = {"openseespy": version("openseespy"), "element": "elasticBeamColumn, Corotational"}
    (out_dir / "opensees_star_dome.json").write_text(json.dumps({"meta": meta, "records": records}))


if __name__ == "__main__":
    run(sys.argv[1] if len(sys.argv) > 1 else "build/peers")
