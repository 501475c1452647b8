"""What a fully coupled 6×6 matrix section costs per Newton iteration against the same
beam with only its diagonal (``type = "general"``): issue 18 asks for at most 1.5×.

The beam is the coupled cantilever (beamfx/scenes/coupled_cantilever.toml, every entry of the
6×6 non-zero) on a finer mesh, the full model of a nonlinear static run (no planar or
condensed trimming); the diagonal variant keeps the six diagonal stiffnesses. Same mesh,
unknowns and load: a Newton iteration is the assembly of the residual and the tangent and a
MUMPS LU factorisation and solve (the static solver's default), at the undeformed state (the
cost of the compiled kernels does not depend on the values), timed in CPU seconds of this
process (on a shared machine the wall time carries the other processes' share), the two
variants alternated and the least of each kept. A whole run's per-iteration wall time
(``results.json`` ``wall_time_s``) scattered by 2x between identical runs on the shared
2-core machine this was written on, which hid the ratio.
"""

import time

import numpy as np


def _cost_scene(section, elements, degree):
    """The coupled cantilever (beamfx/scenes/coupled_cantilever.toml) with ``section``, as a
    nonlinear static run of the full model (no planar or condensed trimming)."""
    from ..scene.load import parse_scene
    from .coupled_cantilever import SCENE, _data

    data = _data()
    data["beams"][0].update(elements=elements, degree=degree, section=section)
    data["analysis"] = {"type": "static", "steps": 1}
    data["model"] = {"condense": "none", "plane": "none"}
    return parse_scene(data, SCENE)


def _diagonal(stiffness):
    keys = ("EA", "GA_y", "GA_z", "GJ", "EI_y", "EI_z")
    return {"type": "general"} | {k: float(v) for k, v in zip(keys, np.diag(stiffness))}


def cpu_seconds(f, budget=0.2, repeats=5):
    """CPU seconds of this process per call of ``f()``: the least mean over ``repeats``
    batches of about ``budget`` seconds (CPU time, not wall time: on a shared machine the
    other processes' share does not count)."""
    import timeit

    t = time.process_time()
    f()
    number = max(1, int(budget / max(time.process_time() - t, 1e-6)))
    return min(timeit.repeat(f, number=number, repeat=repeats, timer=time.process_time)) / number


def iteration_seconds(model, budget=0.2, repeats=5):
    """Seconds of one Newton iteration of ``model`` at its current state, split: assembly of
    the residual and the tangent (supports applied), and the linear solve (MUMPS LU
    factorisation and solve, the static solver's default) as a whole iteration's time less
    the assembly's; CPU seconds (:func:`cpu_seconds`)."""
    from petsc4py import PETSc

    from ..solvers.assembly import assembler

    b, A, assemble = assembler(model.F, model.J, model.bcs)
    ksp = PETSc.KSP().create(model.comm)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    x = b.duplicate()

    def iteration():
        assemble()
        ksp.setOperators(A)  # a new tangent: factorised again, as in every Newton iteration
        ksp.solve(b, x)

    try:
        kw = {"budget": budget, "repeats": repeats}
        assembly, total = cpu_seconds(assemble, **kw), cpu_seconds(iteration, **kw)
        return {"assembly": assembly, "solve": max(total - assembly, 0.0)}
    finally:
        for obj in (ksp, A, b, x):
            obj.destroy()


def matrix_cost(elements=128, degree=2, rounds=3):
    """Per Newton iteration (:func:`iteration_seconds`), the coupled 6×6 section of the
    coupled cantilever against its diagonal (``type = "general"``): the same mesh, unknowns
    and load, measured alternately ``rounds`` times (the least of each kept) and the ratio."""
    from mpi4py import MPI

    from ..analyses.planar_condensed import build_model
    from .coupled_cantilever import _data

    C = np.array(_data()["beams"][0]["section"]["stiffness"], float)
    sections = {"matrix": {"type": "matrix", "stiffness": C.tolist()}, "general": _diagonal(C)}
    models = {
        k: build_model(_cost_scene(v, elements, degree).model, MPI.COMM_WORLD)
        for k, v in sections.items()
    }
    unknowns = {k: m.W.dofmap.index_map.size_global for k, m in models.items()}
    if len(set(unknowns.values())) != 1:
        raise RuntimeError(f"matrix_cost: unknowns differ {unknowns}")
    samples = {k: [iteration_seconds(m) for _ in range(rounds)] for k, m in models.items()}
    least = {k: {p: min(x[p] for x in v) for p in v[0]} for k, v in samples.items()}
    m, g = least["matrix"], least["general"]
    return {
        "elements": elements,
        "degree": degree,
        "unknowns": unknowns["matrix"],
        "rounds": rounds,
        "least_s": least,
        "ratio": (m["assembly"] + m["solve"]) / (g["assembly"] + g["solve"]),
        "ratio_assembly": m["assembly"] / g["assembly"],
        "ratio_solve": m["solve"] / g["solve"],
    }


def cost_lines(r):
    """Report lines of the 6×6 cost measurement (nothing for other cases)."""
    rows = [row for row in r["rows"] if "matrix_cost" in row]
    if not rows:
        return []
    c = rows[-1]["matrix_cost"]
    m, g = c["least_s"]["matrix"], c["least_s"]["general"]

    def ms(x):
        return (
            f"{1e3 * (x['assembly'] + x['solve']):.3f} (assembly {1e3 * x['assembly']:.3f}, "
            f"LU {1e3 * x['solve']:.3f})"
        )

    line = (
        f"6x6 section against its diagonal, per Newton iteration (the coupled cantilever's "
        f"section, {c['elements']} x P{c['degree']}, {c['unknowns']} unknowns each; residual "
        f"+ tangent assembly and MUMPS LU, CPU time, least of {c['rounds']} alternated "
        f"measurements, ms): matrix {ms(m)}, general {ms(g)}: ratio {c['ratio']:.2f} "
        f"(assembly {c['ratio_assembly']:.2f}, LU {c['ratio_solve']:.2f})."
    )
    return ["", line]
