"""OpenSeesPy on the linear space frames of `python -m beamfx.bench.frame_peers export DIR`:
reads DIR/frame_problems.json, writes DIR/opensees_frame.json.

Each member is one `ElasticTimoshenkoBeam` (3D, exact Timoshenko stiffness: the peer of
beamfx's linear kinematics) with E = G = 1 and the section data as stiffnesses: A = EA,
Avy = GA_y, Avz = GA_z, Jx = GJ, Iy = EI_y, Iz = EI_z, so the peer uses beamfx's stiffnesses
exactly. The member axes come from `geomTransf Linear` with vecxz = beamfx's section axis e3:
OpenSees takes y = vecxz × x and z = x × y, which are beamfx's e2 = e3 × t and e3. Linear
static analysis, one step; displacements, rotations and reactions (`ops.reactions()`) at every
node. Times per frame: ``first_s`` the first model build and solve in the process, ``whole_s``
the second (the whole run of a warm process: build, solve, results read back), ``wall_s`` the
solve alone (analyze and reactions) of that second run; ``meta.import_s`` a fresh
interpreter that imports openseespy (a user's script pays it once). OpenSees writes no files
here.

Runs in `.venv-peers` (openseespy, numpy; no beamfx), or in any interpreter with openseespy
(tests/scenes/test_frame_peers.py imports it by path).
"""

import json
import subprocess
import sys
import time
from importlib.metadata import version
from pathlib import Path


def solve(problem):
    """{"displacements": (n, 6) list, "reactions": {node: 6 list}, "solve_s": analyze and
    reactions wall time} of one frame problem."""
    import openseespy.opensees as ops

    ops.wipe()
    ops.model("basic", "-ndm", 3, "-ndf", 6)
    for i, x in enumerate(problem["nodes"]):
        ops.node(i + 1, *x)
    for node, dofs in problem["fixed"].items():
        ops.fix(int(node) + 1, *[1 if d in dofs else 0 for d in range(6)])
    for k, ((a, b), C, axes) in enumerate(
        zip(problem["members"], problem["stiffness"], problem["axes"])
    ):
        EA, GA_y, GA_z, GJ, EI_y, EI_z = C
        vecxz = [row[2] for row in axes]  # column e3 of Λ0
        ops.geomTransf("Linear", k + 1, *vecxz)
        ops.element(
            "ElasticTimoshenkoBeam", k + 1, a + 1, b + 1, 1.0, 1.0, EA, GJ, EI_y, EI_z,
            GA_y, GA_z, k + 1,
        )  # fmt: skip
    ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    for node, load in problem["loads"].items():
        ops.load(int(node) + 1, *load)
    ops.system("UmfPack")
    ops.numberer("RCM")
    ops.constraints("Plain")
    ops.integrator("LoadControl", 1.0)
    ops.algorithm("Linear")
    ops.analysis("Static")
    t0 = time.perf_counter()
    if ops.analyze(1) != 0:
        raise RuntimeError("OpenSees: the linear analysis failed")
    ops.reactions()
    solve_s = time.perf_counter() - t0
    n = len(problem["nodes"])
    return {
        "solve_s": solve_s,
        "displacements": [list(ops.nodeDisp(i + 1)) for i in range(n)],
        "reactions": {node: list(ops.nodeReaction(int(node) + 1)) for node in problem["fixed"]},
    }


def import_seconds():
    """A fresh interpreter that imports openseespy (the second of two: disk cache warm)."""
    for _ in range(2):
        t0 = time.perf_counter()
        cmd = [sys.executable, "-c", "import numpy, openseespy.opensees"]
        subprocess.run(cmd, check=True, capture_output=True)
        seconds = time.perf_counter() - t0
    return seconds


def run(out_dir):
    """Solve every problem of DIR/frame_problems.json twice; write DIR/opensees_frame.json."""
    out_dir = Path(out_dir)
    problems = json.loads((out_dir / "frame_problems.json").read_text())
    records = []
    for name, problem in problems.items():
        t0 = time.perf_counter()
        solve(problem)
        first = time.perf_counter() - t0
        t0 = time.perf_counter()
        values = solve(problem)
        whole = time.perf_counter() - t0
        records.append(
            {"problem": name, "code": "opensees", "element": "ElasticTimoshenkoBeam",
             "unknowns": 6 * len(problem["nodes"]), "wall_s": values.pop("solve_s"),
             "whole_s": whole, "first_s": first, "values": values}
        )  # fmt: skip
        print(f"opensees {name}: {len(problem['members'])} members, first {first:.3f} s, "
              f"whole {whole:.3f} s, solve {records[-1]['wall_s']:.3f} s")  # fmt: skip
    meta = {"openseespy": version("openseespy"), "import_s": import_seconds()}
    (out_dir / "opensees_frame.json").write_text(json.dumps({"meta": meta, "records": records}))


if __name__ == "__main__":
    run(sys.argv[1] if len(sys.argv) > 1 else "build/peers")
