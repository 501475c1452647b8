"""Arc-length continuation past limit points: the solver alone (Bratu) and a beam (Lee's frame).

Bratu's problem -u'' = λ eᵘ on (0, 1), u(0) = u(1) = 0, has the closed form
u(x) = 2 ln[cosh(θ/4) / cosh((x - ½)θ/2)] with θ² = 2λ cosh²(θ/4), so λ(θ) = θ² / (2 cosh²(θ/4))
has a fold at λ_c = max_θ λ(θ) = 3.513830719 (θ_c = 4.7987), and u(½) = 2 ln cosh(θ/4) on both
branches. Its load vector f = eᵘ depends on the state: the solver's "follower" mode.

Lee's frame (Lee, Manuel & Rossow 1968, J. Eng. Mech. Div. ASCE 94, 521–547): two members of
length L = 120 (E = 720, A = 6, I = 2) meeting at a rigid corner, pinned at both far ends, a
downward load P at 24 from the corner on the horizontal member. Its path has a limit point at
P L²/EI ≈ 18.5–18.6 (published; e.g. Schweizerhof & Wriggers 1986, CMAME 59, 261–279), that is
P_max ≈ 1.855 for these data, followed by a snap-back of the loaded point.
"""

import math
import time

import numpy as np
import pytest
from mpi4py import MPI

E, A, I, L = 720.0, 6.0, 2.0, 120.0
EI = E * I

#: converged limit load of the shear-rigid (GA = 100 EA) beamfx model: P3 elements, 20 and 40
#: per member agree to 7 digits (see test_lee_frame_convergence)
P_MAX = 1.855669
#: relative error of the limit load with 10 P3 elements per member: 1.2e-5 measured (ne = 5:
#: 3.7e-4, ne = 10: 1.2e-5, ne = 20: < 1e-7); the tolerance keeps a factor ~8
P3_NE10_RTOL = 1e-4


def lee_frame(elements, degree):
    from beamfx.geometry import Line
    from beamfx.physics.sections import Section
    from beamfx.spec import Beam, Model, PointLoad, Support

    # planar frame in x-y; the out-of-plane stiffness only has to be positive: square section,
    # shear about 100 times stiffer than stretching (shear rigid for this slenderness, L/h = 60)
    sec = Section(EA=E * A, GA_y=1e2 * E * A, GA_z=1e2 * E * A, GJ=EI, EI_y=EI, EI_z=EI)
    pin = ("ux", "uy", "uz", "rx", "ry")  # rz free: pinned in the plane
    return Model(
        beams=(
            Beam("column", Line((0, 0, 0), (0, L, 0)), sec, elements, degree),
            Beam("top", Line((0, L, 0), (L, L, 0)), sec, elements, degree),
        ),
        supports=(Support("column:start", pin), Support("top:end", pin)),
        point_loads=(PointLoad("top:0.2", force=(0.0, -1.0, 0.0)),),
    )


def trace_lee(elements, degree):
    from beamfx.analyses.continuation import limit_points, trace_path
    from beamfx.analyses.model import BeamModel

    model = BeamModel(lee_frame(elements, degree))
    t = time.perf_counter()
    result = trace_path(
        model,
        max_steps=400,
        first_load_increment=0.2,
        stop=lambda path: path[-1].load_factor < 0.5 * max(p.load_factor for p in path),
    )
    return result, limit_points(result.path), time.perf_counter() - t


def test_lee_frame_limit_point_and_snap_back():
    result, limits, seconds = trace_lee(10, 3)
    lam, u = result.load_factors, result.displacements
    assert result.reason == "stop"

    top = limits[0]
    assert top.kind == "maximum"
    assert abs(top.load_factor - P_MAX) <= P3_NE10_RTOL * P_MAX
    assert 18.5 <= top.load_factor * L**2 / EI <= 18.6  # the published range
    # the path goes on past the maximum, the load falling
    i_max = int(np.argmax(lam))
    assert 0 < i_max < len(lam) - 10
    assert np.all(np.diff(lam[i_max:]) < 0)
    assert lam[-1] < 0.5 * lam[i_max]
    # snap-back: the deflection under the load turns back while the load keeps falling
    i_back = int(np.argmin(u[:, 1]))
    assert i_max < i_back < len(lam) - 1
    assert lam[i_back + 1] < lam[i_back] < lam[i_back - 1]
    assert -62.0 < u[i_back, 1] < -60.0  # about 61 below its start, for P ≈ 1.19
    # planar: no out-of-plane motion
    assert np.abs(u[:, 2]).max() < 1e-8
    assert max(p.iterations for p in result.path) <= 12
    if MPI.COMM_WORLD.rank == 0:
        print(
            f"\nLee's frame, 10 P3 elements per member: P_max = {top.load_factor:.6f} "
            f"(P L²/EI = {top.load_factor * L**2 / EI:.4f}), {len(result.steps)} steps, "
            f"{sum(p.iterations for p in result.path)} iterations, {seconds:.2f} s"
        )


@pytest.mark.slow
def test_lee_frame_convergence():
    """Limit load by mesh: P2 converges to the P3 value; P3 settles by 20 elements."""
    rows = []
    for degree, meshes in ((2, (8, 16, 32)), (3, (5, 10, 20, 40))):
        for ne in meshes:
            result, limits, seconds = trace_lee(ne, degree)
            rows.append((degree, ne, limits[0].load_factor, len(result.steps), seconds))
    if MPI.COMM_WORLD.rank == 0:
        print("\ndegree  elements/member  P_max      P L²/EI   steps  seconds")
        for degree, ne, p, steps, seconds in rows:
            print(
                f"  P{degree}    {ne:4d}            {p:.6f}  {p * L**2 / EI:.4f}  {steps:5d}  {seconds:.2f}"
            )
    p3 = {ne: p for d, ne, p, *_ in rows if d == 3}
    p2 = {ne: p for d, ne, p, *_ in rows if d == 2}
    assert abs(p3[40] - p3[20]) < 1e-6 and abs(p3[40] - P_MAX) < 1e-6
    assert abs(p3[10] - P_MAX) <= P3_NE10_RTOL * P_MAX
    errors = [abs(p2[ne] - P_MAX) for ne in (8, 16, 32)]
    assert errors[0] > errors[1] > errors[2] and errors[2] < 5e-4 * P_MAX


# --- the solver alone -------------------------------------------------------------------------

BRATU_LAMBDA_C = 3.513830719125161


def bratu_u_mid(lam, upper):
    """u(½) of the exact solution on the lower or upper branch at load factor lam."""
    from scipy.optimize import brentq

    theta_c = 4.798714560762704

    def g(t):
        return t * t / (2 * math.cosh(t / 4) ** 2) - lam

    theta = brentq(g, theta_c, 30.0) if upper else brentq(g, 1e-9, theta_c)
    return 2 * math.log(math.cosh(theta / 4))


def test_bratu_fold_with_state_dependent_load():
    import dolfinx
    import dolfinx.fem.petsc
    import ufl
    from dolfinx import fem
    from petsc4py import PETSc

    from beamfx.solvers.arclength import ArcLengthSettings, ArcLengthSolver

    comm, n, p = MPI.COMM_WORLD, 16, 2
    cell = ufl.Cell("interval", geometric_dimension=1)
    domain = ufl.Mesh(ufl.VectorElement("Lagrange", cell, 1, variant="equispaced"))
    x = np.linspace(0, 1, n + 1)[:, None] if comm.rank == 0 else np.empty((0, 1))
    cells = np.c_[np.arange(n), np.arange(1, n + 1)] if comm.rank == 0 else np.empty((0, 2))
    mesh = dolfinx.mesh.create_mesh(comm, cells.astype(np.int64), x, domain)
    V = fem.FunctionSpace(mesh, ("Lagrange", p))
    u, v = fem.Function(V), ufl.TestFunction(V)
    lam = fem.Constant(mesh, PETSc.ScalarType(0.0))
    dx = ufl.dx(metadata={"quadrature_degree": 2 * p + 2})
    F = ufl.inner(ufl.grad(u), ufl.grad(v)) * dx - lam * ufl.exp(u) * v * dx
    ends = dolfinx.mesh.locate_entities_boundary(
        mesh, 0, lambda x: np.isclose(x[0], 0) | np.isclose(x[0], 1)
    )
    bc = fem.dirichletbc(PETSc.ScalarType(0), fem.locate_dofs_topological(V, 0, ends), V)
    mid = np.flatnonzero(np.isclose(V.tabulate_dof_coordinates()[:, 0], 0.5))

    def u_mid():
        return comm.allreduce(u.x.array[mid].max() if len(mid) else -np.inf, op=MPI.MAX)

    settings = ArcLengthSettings(follower=True, max_arc_length=1.0)
    solver = ArcLengthSolver(
        F, ufl.derivative(F, u), u, lam, [bc], "test_bratu_", settings=settings
    )

    # up the lower branch, landing on λ = 3 (P2, 16 cells: u(½) error 7e-7)
    result = solver.trace(first_load_increment=0.05, target_load_factor=3.0, max_steps=500)
    assert result.reason == "target" and float(lam.value) == 3.0
    assert abs(u_mid() - bratu_u_mid(3.0, upper=False)) < 1e-5

    # on from there, round the fold and back down to λ = 3 on the upper branch (error 1.1e-5)
    path = []
    result = solver.trace(
        first_load_increment=0.05,
        target_load_factor=3.0,
        max_steps=500,
        on_step=lambda step: path.append((step.load_factor, step.arc_length)),
    )
    solver.destroy()
    assert result.reason == "target" and float(lam.value) == 3.0
    assert abs(u_mid() - bratu_u_mid(3.0, upper=True)) < 5e-5
    lam_path, s = np.array(path).T
    s = np.cumsum(s)
    i = int(np.argmax(lam_path))
    c = np.polyfit(s[i - 1 : i + 2] - s[i], lam_path[i - 1 : i + 2], 2)
    lam_c = np.polyval(c, -c[1] / (2 * c[0]))
    # FE error of the fold at 16 P2 cells 8e-6 (32 cells: 3e-6, then the parabola's O(Δs³))
    assert abs(lam_c - BRATU_LAMBDA_C) < 5e-5


def test_lee_frame_from_its_scene_file(tmp_path):
    """The documented arc-length scene (planar model): limit load and the path file."""
    import json
    import re
    from pathlib import Path

    from beamfx.runner import run_scene

    doc = (Path(__file__).resolve().parents[2] / "docs" / "scenes.md").read_text()
    text = next(b for b in re.findall(r"```toml\n(.*?)```", doc, re.DOTALL) if "Lee's frame" in b)
    scene = tmp_path / "lee.toml"
    scene.write_text(text.replace('dir = "results/lee_frame"', f'dir = "{tmp_path / "out"}"'))
    results = run_scene(scene, log=lambda *a: None)
    assert results["model"]["plane"] == "xy" and results["model"]["unknowns"] == 183
    top = results["limit_points"][0]
    assert top["kind"] == "maximum"
    assert abs(top["load_factor"] - P_MAX) <= P3_NE10_RTOL * P_MAX
    assert results["stopped_by"] == "displacement_limit"
    assert abs(results["path"][-1]["displacement"][1]) >= 55
    rows = (tmp_path / "out" / "path.csv").read_text().splitlines()
    assert len(rows) == len(results["path"])  # header + one row per step after the start
    assert json.loads((tmp_path / "out" / "results.json").read_text())["converged"]


def test_a_trace_cut_short_by_max_steps_is_not_converged(tmp_path):
    """Lee's frame with max_steps = 3: the trace ends before its displacement limit, so
    results.json says converged false (status "stopped", the reason) and `beamfx run` exits
    3."""
    import json
    import re
    from pathlib import Path

    from beamfx.cli import main

    doc = (Path(__file__).resolve().parents[2] / "docs" / "scenes.md").read_text()
    text = next(b for b in re.findall(r"```toml\n(.*?)```", doc, re.DOTALL) if "Lee's frame" in b)
    text = text.replace('dir = "results/lee_frame"', f'dir = "{tmp_path / "out"}"')
    scene = tmp_path / "lee.toml"
    scene.write_text(
        text.replace(
            'displacement_limit = ["uy", 55]', 'displacement_limit = ["uy", 55]\nmax_steps = 3'
        )
    )
    assert main(["run", str(scene)]) == 3
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    assert results["converged"] is False and results["status"] == "stopped"
    assert results["stopped_by"] == "max_steps" and "max_steps" in results["reason"]
    assert len(results["path"]) == 4  # the start and three steps
