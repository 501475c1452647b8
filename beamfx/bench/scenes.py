"""A bench setting as the scene a user would run, and its run through ``beamfx run``'s path."""

import time
from dataclasses import fields


def case_scene(case, elements, degree, analysis="static", **settings):
    """The scene of one setting of a case, as ``beamfx run`` takes it (built in code)."""
    from ..analyses.registry import analysis as lookup
    from ..scene.load import Scene

    spec, steps = case.build(elements, degree)
    entry = lookup(analysis)
    if "steps" in {f.name for f in fields(entry.settings)}:
        settings.setdefault("steps", steps)
    return Scene(
        f"bench:{case.id}", spec, analysis, dict(case.probes), settings=entry.settings(**settings)
    )


def run_in_process(scene, folder):
    """``beamfx run`` of ``scene`` in this process (output written to ``folder``), quiet;
    returns the :class:`~beamfx.runner.RunResult` and the whole run's wall time."""
    from ..runner import run_scene

    t0 = time.perf_counter()
    run = run_scene(scene.file, folder, log=lambda *a, **k: None, scene=scene)
    return run, time.perf_counter() - t0


def analysis_scene(case_id, spec, analysis, probes=None, **settings):
    """A scene of ``analysis`` on the model ``spec`` with ``[analysis]`` ``settings``, as a
    user's scene file of that model would give it."""
    from ..analyses.registry import analysis as lookup
    from ..scene.load import Scene

    entry = lookup(analysis)
    return Scene(
        f"bench:{case_id}", spec, analysis, dict(probes or {}), settings=entry.settings(**settings)
    )


def run_scenes(runs, folder):
    """The scenes of one setting (``[(scene, read)]``) run one after the other as ``beamfx run``
    runs them; returns (the runs, their total wall time, the values their ``read(result)``
    give, merged)."""
    done, total, values = [], 0.0, {}
    for scene, read in runs:
        run, seconds = run_in_process(scene, folder)
        done.append(run)
        total += seconds
        values.update(read(run.result))
    return done, total, values
