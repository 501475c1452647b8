"""The ``beamfx`` command: ``run``, ``check``, ``bench``, ``solid``, ``warm``. Each is one library
call."""

import argparse
import sys


def _parser():
    from . import __version__

    parser = argparse.ArgumentParser(
        prog="beamfx", description="Geometrically exact 3D beams on FEniCSx."
    )
    parser.add_argument("--version", action="version", version=f"beamfx {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser(
        "run",
        help="solve a scene (the built-in 45-degree bend if none is given); a scene with "
        "[[sweep]] tables runs as an ensemble across the MPI ranks",
    )
    p.add_argument(
        "scene",
        nargs="?",
        help="scene file (TOML, see docs/scenes.md); none: the built-in 45-degree bend",
    )
    p.add_argument("--out", help="output folder (default: the scene's [output] dir)")
    p.add_argument(
        "--restart",
        action="store_true",
        help="transient: go on from the last checkpoint in the output folder",
    )
    p.add_argument(
        "--png",
        action="store_true",
        help="also render pictures (PNG, pyvista) of the results into the output folder",
    )
    p.add_argument(
        "--animate",
        action="store_true",
        help="transient: also an animated GIF of the frames (implies --png)",
    )
    p = sub.add_parser("check", help="validate a scene file without solving")
    p.add_argument("scene", help="scene file (TOML)")
    p = sub.add_parser("bench", help="run the benchmark cases and write a report")
    p.add_argument("cases", nargs="*", help="case ids (default: all); see --list")
    p.add_argument(
        "--report", help="folder for bench.json and README.md (without it nothing is written)"
    )
    p.add_argument("--list", action="store_true", help="list the case ids")
    p = sub.add_parser("warm", help="compile the kernels of common scenes into the JIT cache")
    p.add_argument("scenes", nargs="*", help="also these: files, folders, .md with toml blocks")
    p.add_argument(
        "--only",
        action="store_true",
        help="only these scenes (not the built-in scene and the grid of common cases)",
    )
    p = sub.add_parser("solid", help="the 3D solid of a one-beam scene, compared with the beam")
    p.add_argument("scene", help="scene file (TOML) of one beam")
    p.add_argument("--out", help="output folder (default: <the scene's [output] dir>/solid)")
    p.add_argument("--material", help="linear, svk or neo-hookean (default: from the kinematics)")
    p.add_argument("--section-cells", type=int, default=2, help="cells across the section")
    p.add_argument(
        "--layers",
        type=int,
        help="cells along the centre line (default: cells at most 8 times longer than wide)",
    )
    p.add_argument(
        "--cell",
        default="hexahedron",
        choices=("hexahedron", "tetrahedron"),
        help="hexahedron (rectangular sections) or tetrahedron",
    )
    p.add_argument(
        "--solver",
        default="auto",
        choices=("auto", "direct", "iterative"),
        help="linear solver of the solid (auto: direct up to a size, then iterative)",
    )
    p.add_argument(
        "--png", action="store_true", help="also a picture of the solid and the beam (pyvista)"
    )
    return parser


def _run(args):
    import gc

    from .runner import run_scene

    # the objects of the imports (UFL, DOLFINx, NumPy) live as long as the process: out of the
    # collector's sight, a full collection during the run no longer walks them (40-50 ms each)
    gc.freeze()
    results = run_scene(
        args.scene, args.out, restart=args.restart, png=args.png, animate=args.animate
    )
    if "members" not in results:  # one scene: results.json says how it ended
        if results.converged:
            return 0
        from mpi4py import MPI

        from .interrupt import received

        if MPI.COMM_WORLD.rank == 0:
            more = "; go on with 'beamfx run --restart'" if received() else ""
            print(
                f"beamfx: {results.result.status}: {results.result.reason}{more}", file=sys.stderr
            )
        return 128 + received() if received() else 3
    failed = [m["member"] for m in results["members"] if m["status"] != "converged"]
    if failed:  # a sweep: the table is written, but say that it has holes
        print(f"beamfx: sweep members {failed} failed (see sweep.md)", file=sys.stderr)
        return 3
    return 0


def _check(args):
    from .runner import check_scene

    scene = check_scene(args.scene)
    if hasattr(scene, "members"):
        first, n, checked = scene.members[0].scene, len(scene.members), len(scene.validated)
        which = (
            "every member checked"
            if checked == n
            else f"{checked} members checked, each value once; 'beamfx run' checks every "
            "member before it solves any"
        )
        print(
            f"{args.scene}: OK (a sweep of {n} scenes over {', '.join(scene.keys)}; analysis "
            f"{first.analysis}; {which})"
        )
    else:
        n = len(scene.model.beams)
        print(f"{args.scene}: OK ({n} beam(s), analysis {scene.analysis})")
    return 0


def _solid(args):
    from .solid.run import SolidMesh, run_solid

    mesh = SolidMesh(args.section_cells, args.layers, args.cell)
    run_solid(args.scene, args.out, args.material, mesh, args.solver, png=args.png)
    return 0


def _bench(args):
    from .bench import all_cases
    from .bench.run import run_bench
    from .scene import SceneError

    if args.list:
        for cid, case in all_cases().items():
            print(f"{cid:28s} {case.title}")
        return 0
    unknown = [c for c in args.cases if c not in all_cases()]
    if unknown:
        raise SceneError(f"unknown bench case(s) {unknown}; allowed: {list(all_cases())}")
    results = run_bench(args.cases or None, args.report)
    failed = [r["id"] for r in results if not r["passed"]]
    print(
        f"{len(results) - len(failed)}/{len(results)} cases within tolerance"
        + (f"; outside: {failed}" if failed else "")
    )
    return 0


def _warm(args):
    from .warm import warm

    warm(args.scenes, common=not args.only)
    return 0


COMMANDS = {"run": _run, "check": _check, "solid": _solid, "bench": _bench, "warm": _warm}


def main(argv=None):
    """``beamfx <command>``: 0 on success, 2 on bad input, 3 on a failed solve, 130/143 when
    interrupted by SIGINT/SIGTERM. Under MPI a failure on any rank ends every rank
    (:func:`beamfx.interrupt.stop_everywhere`): never a hang."""
    from .startup import prepare

    prepare()  # before mpi4py and UFL are imported (beamfx.startup)
    from .interrupt import error_comm, handle_signals, stop_everywhere

    args = _parser().parse_args(argv)
    errors = error_comm()
    with handle_signals():
        code, message = _guarded(args, errors is not None)
    if message is not None:
        code = stop_everywhere(message, code, errors)
    if errors is not None:
        errors.Free()
    return code


def _guarded(args, parallel):
    """(exit status, message or None) of the command: errors become one line; a traceback
    only for a bug in a serial run (under MPI it is printed and every rank stops)."""
    from .interrupt import Interrupted, interruption
    from .scene import SceneError
    from .solvers import SolveFailed

    try:
        return COMMANDS[args.command](args), None
    except Interrupted as e:
        return e.exit_code, f"beamfx: {e}"
    except Exception as e:
        signal = interruption(e)  # a signal that surfaced as another error (in an import)
        if signal is not None:
            return signal.exit_code, f"beamfx: {signal}"
        if isinstance(e, (SceneError, ValueError, OSError)):
            return 2, f"beamfx: error: {e}"
        if isinstance(e, SolveFailed):
            return 3, f"beamfx: solve failed: {e}"
        if not parallel:
            raise
        import traceback

        return 1, "beamfx: internal error:\n" + traceback.format_exc()


if __name__ == "__main__":
    sys.exit(main())
