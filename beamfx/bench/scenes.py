"""A bench setting as the scene a user would run, and its run through ``beamfx run``'s path."""

import time
from dataclasses import dataclass, fields

from .registry import Case


def case_scene(case, elements, degree, analysis="static", **settings):
    """The scene of one setting of a case, as ``beamfx run`` takes it (built in code)."""
    from ..analyses.registry import analysis as lookup

    spec, steps = case.build(elements, degree)
    if "steps" in {f.name for f in fields(lookup(analysis).settings)}:
        settings.setdefault("steps", steps)
    return analysis_scene(
        case.id, spec, analysis, case.probes, choose=not case.own_model, **settings
    )


def chosen_model(scene):
    """``scene`` with the model the scene builder picks for it from a file ([model] plane and
    condense "auto": planar, statically condensed), by the same
    :func:`~beamfx.scene.load.choose_model` as ``beamfx run``."""
    from dataclasses import replace

    from ..analyses.registry import analysis as lookup
    from ..scene.load import choose_model

    model, trim, condense = choose_model(scene.model, lookup(scene.analysis), scene.settings)
    return replace(scene, model=model, trimming=trim, condense=condense)


def setting_scene(case, setting):
    """The scene of a setting of a case: a transient case's own (elements, degree, dt), else
    :func:`case_scene` of (elements, degree)."""
    if hasattr(case, "scene"):
        return case.scene(*setting)
    return case_scene(case, *setting[:2])


def run_in_process(scene, folder):
    """``beamfx run`` of ``scene`` in this process (output written to ``folder``), quiet;
    returns the :class:`~beamfx.runner.RunResult` and the whole run's wall time."""
    import gc

    from ..runner import run_scene

    gc.collect()  # outside the timing: the earlier runs' garbage; then, as `beamfx run` does,
    gc.freeze()  # the live objects out of the collector's sight
    t0 = time.perf_counter()
    run = run_scene(scene.file, folder, log=lambda *a, **k: None, scene=scene)
    return run, time.perf_counter() - t0


def analysis_scene(case_id, spec, analysis, probes=None, choose=True, **settings):
    """A scene of ``analysis`` on the model ``spec`` with ``[analysis]`` ``settings``, as a
    user's scene file of that model would give it: with the model the scene builder picks
    (:func:`chosen_model`) unless ``choose`` is False (a case's documented ``own_model``)."""
    from ..analyses.registry import analysis as lookup
    from ..scene.load import Scene

    entry = lookup(analysis)
    scene = Scene(
        f"bench:{case_id}", spec, analysis, dict(probes or {}), settings=entry.settings(**settings)
    )
    return chosen_model(scene) if choose else scene


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


def _solve_only(seconds):
    """The analysis's own assembly and solve time from its ``seconds`` split."""
    keys = ("assemble_F", "assemble_J", "solve", "assemble")
    return sum(float(seconds.get(k, 0.0)) for k in keys)


@dataclass(frozen=True)
class SceneCase(Case):
    """A case whose setting is one or more scenes: ``build(elements, degree)`` returns
    ``[(scene, read)]``, ``read(result)`` the named values of a run's result (eigen analyses,
    arc-length traces: values a probe cannot give). :meth:`run_setting` runs them through
    ``beamfx run``'s path (cold, then warm)."""

    def scenes(self, elements, degree):
        """The scenes of one setting, for a process of their own (:mod:`.process`)."""
        return [scene for scene, _ in self.build(elements, degree)]

    def run_setting(self, elements, degree):
        """Cold and warm whole runs of the setting's scenes; solve only = the analyses' own
        assembly and solves (Newton's, or the eigen solver's)."""
        import tempfile

        from ..solvers.forms import compile_seconds
        from .model_choice import formulation

        c0 = compile_seconds[0]
        with tempfile.TemporaryDirectory(prefix="beamfx-bench-") as folder:
            _, cold, _ = run_scenes(self.build(elements, degree), folder)
            jit = compile_seconds[0] - c0
            runs, warm, values = run_scenes(self.build(elements, degree), folder)
        solve = sum(
            r.result.seconds.get("assemble", 0.0) + r.result.seconds.get("solve", 0.0) for r in runs
        )
        return {
            "elements": elements,
            "degree": degree,
            "unknowns": runs[0].model["unknowns"],
            "formulation": " + ".join(dict.fromkeys(formulation(r.model) for r in runs)),
            "newton_iterations": sum(r.result.newton_iterations for r in runs),
            "load_steps": sum(len(r.result.load_steps) for r in runs),
            "wall_s_cold": cold,
            "wall_s_whole": warm,
            "wall_s_warm": solve,
            "jit_s": jit,
            "warm_split_s": {},
            "values": {k: float(v) for k, v in self.measure(values).items()},
        }
