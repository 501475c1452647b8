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
