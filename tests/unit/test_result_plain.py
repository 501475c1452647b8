"""results.json's values (:func:`beamfx.analyses.result.plain`): the exact containers take
the fast path, their subclasses (NamedTuples, ordered dicts) and NumPy values keep theirs."""

from collections import OrderedDict
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from beamfx.analyses.result import plain


class Step(NamedTuple):
    step: int
    load_factor: float


@dataclass(frozen=True)
class Point:
    at: str
    xyz: tuple


def test_plain_spells_every_kind_as_json_values():
    value = {
        "vector": (1.0, 2.0),
        "mixed": (1, 2.0, None),
        "steps": (Step(1, 0.5), [Step(2, 1.0)]),
        "numpy": [np.arange(2.0), np.float64(0.25), np.int64(3)],
        "ordered": OrderedDict(a=(0.5,)),
        "point": Point("tip", (1.0, np.float64(2.0))),
        "empty": ((), []),
    }
    assert plain(value) == {
        "vector": [1.0, 2.0],
        "mixed": [1, 2.0, None],
        "steps": [{"step": 1, "load_factor": 0.5}, [{"step": 2, "load_factor": 1.0}]],
        "numpy": [[0.0, 1.0], 0.25, 3],
        "ordered": {"a": [0.5]},
        "point": {"at": "tip", "xyz": [1.0, 2.0]},
        "empty": [[], []],
    }
    assert type(plain(value)["numpy"][1]) is float
    assert type(plain(value)["point"]["xyz"][1]) is float
