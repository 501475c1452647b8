"""The public API is annotated: every parameter and the return of the functions a user calls
(run_scene, check_scene, the scene readers, the analysis registry, each analysis's ``run`` and
``Result``), and the annotations name real types (``typing.get_type_hints`` resolves them)."""

import inspect
import typing

import pytest
from mpi4py import MPI

from beamfx import runner, scene
from beamfx.analyses import registry, result
from beamfx.analyses.static import StaticResult
from beamfx.analyses.transient import TransientSettings

#: names that the modules import only for type checkers (``if TYPE_CHECKING:``)
TYPE_CHECKING_NAMES = {
    "MPI": MPI,
    "Scene": scene.Scene,
    "Sweep": scene.Sweep,
    "Result": result.Result,
    "StaticResult": StaticResult,
    "TransientSettings": TransientSettings,
}

FUNCTIONS = [
    runner.default_scene_path,
    runner.run_scene,
    runner.check_scene,
    runner.RunResult.to_json,
    runner.RunResult.get,
    scene.load_scene,
    scene.parse_scene,
    scene.load_scene_or_sweep,
    scene.load_sweep,
    scene.parse_sweep,
    registry.analyses,
    registry.analysis,
    result.plain,
    result.entry,
    result.Result.to_json,
    result.Result.summary,
]


def _analyses():
    return list(registry.analyses().values())


def _missing(fn):
    """Parameters (and "return") of ``fn`` without an annotation."""
    sig = inspect.signature(fn)
    out = [
        name
        for name, p in sig.parameters.items()
        if name not in ("self", "cls") and p.annotation is inspect.Parameter.empty
    ]
    if sig.return_annotation is inspect.Signature.empty:
        out.append("return")
    return out


def _check(fn):
    assert not _missing(fn), f"{fn.__module__}.{fn.__qualname__}: not annotated: {_missing(fn)}"
    hints = typing.get_type_hints(fn, localns=TYPE_CHECKING_NAMES)
    assert "return" in hints


@pytest.mark.parametrize("fn", FUNCTIONS, ids=lambda f: f"{f.__module__}.{f.__qualname__}")
def test_public_function_is_annotated(fn):
    _check(fn)


@pytest.mark.parametrize("entry", _analyses(), ids=lambda a: a.name)
def test_analysis_run_and_result_are_annotated(entry):
    _check(entry.run)
    hints = typing.get_type_hints(entry.run, localns=TYPE_CHECKING_NAMES)
    assert hints["settings"] is entry.settings
    assert issubclass(hints["return"], result.Result)
    _check(hints["return"].summary)


def test_an_unannotated_function_is_reported():
    def bare(a, b: int = 1):
        return a

    assert _missing(bare) == ["a", "return"]
