"""``beamfx warm``: compile the forms of common scenes into the JIT cache.

A run's first minute on a fresh machine (or in every fresh container) is spent compiling C
kernels (FFCx, DOLFINx's JIT); a cached run loads them in milliseconds. The Docker image runs
``beamfx warm`` at build time with the cache in a fixed folder of the image (``XDG_CACHE_HOME``,
see the Dockerfile), so ``docker run ... beamfx run`` starts warm.

What is warmed: the built-in default scene, a grid of common cases (:func:`grid`: spatial and
planar cantilevers, static, linear static, modal and transient, degrees 1 to 4) and the scene
files given on the command line (files, folders of ``*.toml`` files, and Markdown documents
whose ```` ```toml ```` blocks are scenes, e.g. docs/scenes.md). Each scene goes through
:func:`beamfx.runner.run_scene` into a temporary folder, so exactly what ``beamfx run`` compiles
is compiled. Transients, arc-length traces and speed sweeps are cut short (:func:`shortened`):
their forms do not depend on how many steps are taken.

What a warm cache covers: the kernels depend on the structure of a scene (kinematics, plane,
degree, analysis, kinds of loads and supports), not on element counts, lengths or section and
material values, which enter as coefficient fields, nor on point-load vectors (constants of the
forms; only whether a force or a moment is zero shapes them). Spring stiffnesses and point
masses of the full model enter the forms as numbers, so a scene with other such values compiles
its residual and tangent again (about 1 to 10 s); the elements and output expressions stay
cached.
"""

import re
import shutil
import tempfile
import time
from dataclasses import fields, is_dataclass, replace
from pathlib import Path
from typing import NamedTuple

#: degrees of the grid of common cases
DEGREES = (1, 2, 3, 4)

_BASE = """[material]
E = 210e9
nu = 0.3
rho = 7850

[[beams]]
name = "b"
curve = {{ shape = "line", start = [0, 0, 0], end = [1, 0, 0] }}
section = {{ type = "rectangle", h = 0.02, w = 0.01 }}
elements = 4
degree = {degree}

[[supports]]
at = "b:start"
fix = "all"
{support}
[[probes]]
name = "tip"
at = "b:end"
"""

#: name -> (extra support keys, the rest of the scene)
_CASES = {
    # a tip force out of every coordinate plane: the condensed cantilever
    "static-3d": ("", '[[loads]]\nat = "b:end"\nforce = [0, 100, -100]\n'),
    # a tip force in the xz plane: the planar model
    "static-xz": ("", '[[loads]]\nat = "b:end"\nforce = [0, 0, -100]\n'),
    "linear-3d": (
        "",
        '[[loads]]\nat = "b:end"\nforce = [0, 100, -100]\n\n[analysis]\ntype = "linear_static"\n',
    ),
    "modal-3d": ("", '[analysis]\ntype = "modal"\nmodes = 4\n'),
    # a base shaken in the plane / out of it: transients with a support history, no loads
    "transient-xz": (
        'displacement = [0, 0, 0.002]\nhistory = "1 - cos(2*pi*5*t)"\n',
        '[analysis]\ntype = "transient"\nt_end = 0.01\ndt = 0.002\n',
    ),
    "transient-3d": (
        'displacement = [0, 0.002, 0.002]\nhistory = "1 - cos(2*pi*5*t)"\n',
        '[analysis]\ntype = "transient"\nt_end = 0.01\ndt = 0.002\n',
    ),
}


class Source(NamedTuple):
    """A scene file to warm the JIT cache with."""

    name: str  # what the log calls it
    path: Path  # a scene file


class Warmed(NamedTuple):
    """What warming one scene compiled, and how long it took."""

    name: str
    compiled: int  # new kernels written to the cache (rank 0's count)
    seconds: float
    error: str | None = None  # a failed solve (its kernels up to the failure are cached)


def grid(folder):
    """Write the common cases (:data:`_CASES` at every degree of :data:`DEGREES`) into
    ``folder``; return them as :class:`Source` s."""
    out = []
    for name, (support, rest) in _CASES.items():
        for degree in DEGREES:
            path = Path(folder) / f"{name}-p{degree}.toml"
            text = _BASE.format(degree=degree, support=support) + "\n" + rest
            path.write_text(text, encoding="utf-8")
            out.append(Source(path.stem, path))
    return out


_FENCE = re.compile(r"^```([\w-]*)\n(.*?)^```$", re.MULTILINE | re.DOTALL)


def _markdown_scenes(doc, folder):
    """The ```toml blocks of ``doc`` as files in ``folder``, next to its ```geo blocks (each
    named on its first line, ``// name.geo``)."""
    text = doc.read_text(encoding="utf-8")
    out = []
    for m in _FENCE.finditer(text):
        info, body = m.group(1), m.group(2)
        line = text.count("\n", 0, m.start()) + 1
        if info == "geo" and (name := re.match(r"// *([\w.-]+\.geo)\b", body)):
            (folder / name.group(1)).write_text(body, encoding="utf-8")
        elif info == "toml":
            path = folder / f"{doc.stem}_line{line}.toml"
            path.write_text(body, encoding="utf-8")
            out.append(Source(f"{doc.name}:{line}", path))
    return out


def scene_sources(paths, folder):
    """:class:`Source` s of the given files, folders (their ``*.toml``) and Markdown
    documents (their ```toml blocks, written into ``folder``)."""
    out = []
    for p in map(Path, paths):
        if p.is_dir():
            out += [Source(str(f), f) for f in sorted(p.glob("*.toml"))]
        elif p.suffix == ".md":
            out += _markdown_scenes(p, Path(folder))
        else:
            out.append(Source(str(p), p))
    return out


def shortened(scene):
    """The scene with its time, arc-length or speed loop cut to its first steps (the same
    forms); static, eigen and adaptive scenes unchanged (adaptive: the solve picks the
    degree)."""
    settings = scene.settings
    if scene.accuracy or not is_dataclass(settings):
        return scene
    names = {f.name for f in fields(settings)}
    cut = {}
    if {"t_end", "dt"} <= names:
        cut["t_end"] = min(settings.t_end, 3 * settings.dt)
    if "max_steps" in names:
        cut["max_steps"] = min(settings.max_steps, 3)
    if getattr(settings, "speeds_rad_s", None):
        cut["speeds_rad_s"] = tuple(settings.speeds_rad_s[:2])
    return replace(scene, settings=replace(settings, **cut)) if cut else scene


def _cache_files(cache):
    return len(list(cache.glob("*.so"))) if cache.is_dir() else 0


def warm_one(source, out, cache, comm):
    """Run one scene (shortened; every member of a sweep) into ``out``; a :class:`Warmed`.

    A scene that cannot be read raises (SceneError, OSError); a failed solve is reported in
    ``error`` (the kernels compiled up to the failure stay cached)."""
    from .runner import run_scene
    from .scene import Sweep, load_scene_or_sweep

    before, t = _cache_files(cache), time.perf_counter()
    loaded = load_scene_or_sweep(source.path)
    members = [m.scene for m in loaded.members] if isinstance(loaded, Sweep) else [loaded]
    error = None
    try:
        for s in members:
            run_scene(source.path, out, log=lambda *a, **k: None, comm=comm, scene=shortened(s))
    except Exception as e:  # noqa: BLE001  a failed solve is a result here, not the end
        error = f"{type(e).__name__}: {e}"
    compiled = _cache_files(cache) - before
    return Warmed(source.name, compiled, time.perf_counter() - t, error)


def warm(paths=(), common=True, comm=None, log=None):
    """Compile the kernels of the default scene and the grid (``common``) and of ``paths``
    into the JIT cache; log one line per scene and return the :class:`Warmed` list."""
    from functools import partial

    import dolfinx.jit
    from mpi4py import MPI

    from .io import log as default_log
    from .runner import default_scene_path
    from .solvers.forms import JIT_PARAMS

    comm = comm or MPI.COMM_WORLD
    log = log or partial(default_log, comm=comm)
    cache = Path(dolfinx.jit.get_parameters(JIT_PARAMS)["cache_dir"])
    folder = comm.bcast(tempfile.mkdtemp(prefix="beamfx_warm_") if comm.rank == 0 else None)
    try:
        sources = [Source("default scene", default_scene_path())] if common else []
        sources += grid(folder) if common and comm.rank == 0 else []
        sources += scene_sources(paths, folder) if comm.rank == 0 else []
        sources = comm.bcast(sources)
        log(f"beamfx warm: {len(sources)} scenes into the JIT cache {cache}")
        results = []
        for i, source in enumerate(sources):
            r = warm_one(source, Path(folder) / f"out{i}", cache, comm)
            note = f"; {r.error}" if r.error else ""
            log(f"  {r.name}: {r.compiled} kernels compiled, {r.seconds:.1f} s{note}")
            results.append(r)
        total = sum(r.compiled for r in results)
        log(f"beamfx warm: {total} kernels compiled in {sum(r.seconds for r in results):.0f} s")
        return results
    finally:
        comm.barrier()
        if comm.rank == 0:
            shutil.rmtree(folder, ignore_errors=True)
